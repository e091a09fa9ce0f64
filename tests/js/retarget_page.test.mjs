// The Retarget page's helper modules (web/src/lib): frames arriving in batches and playback
// (frame-store.js), the clip library (clip-library.js), target joints (retarget-joints.js) and
// the latest-only run of prepare + frame batches (retarget-runner.js, with a fake client).
// Run: node --test tests/js/
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { clipOption, filterClips, jointsFileFor, libraryFiles, librarySources, libraryTargets } from '../../web/src/lib/clip-library.js';
import { FrameStore, PlaybackClock } from '../../web/src/lib/frame-store.js';
import { JointFollower, boneLengthChange, boneLengths, bonesOf, jointsFile, readJointsFile } from '../../web/src/lib/retarget-joints.js';
import { RetargetRunner } from '../../web/src/lib/retarget-runner.js';

const repoDir = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');

function batch(first, count, nv) {
  const p = new Float32Array(count * nv * 3);
  for (let k = 0; k < count; ++k) p.fill(first + k, k * nv * 3, (k + 1) * nv * 3);
  return p;
}

test('FrameStore: batches in any order, ranges, playable prefix, interpolation', () => {
  const store = new FrameStore([0, 0.1, 0.2, 0.3, 0.4, 0.5], 2);
  const out = new Float32Array(6);
  assert.equal(store.positionsAt(0.1, out), null);
  store.add(3, 2, batch(3, 2, 2));
  assert.deepEqual(store.ranges(), [[3, 5]]);
  assert.equal(store.contiguous(), 0);
  // Before any received frame: the first one after.
  assert.deepEqual(store.positionsAt(0.05, out), { frame: 3, exact: false });
  assert.equal(out[0], 3);
  store.add(0, 2, batch(0, 2, 2));
  assert.deepEqual(store.ranges(), [[0, 2], [3, 5]]);
  assert.equal(store.contiguous(), 2);
  // Between two received frames: linear.
  assert.deepEqual(store.positionsAt(0.05, out), { frame: 0, exact: true });
  assert.ok(Math.abs(out[0] - 0.5) < 1e-6 && Math.abs(out[5] - 0.5) < 1e-6);
  // Frame 2 missing: hold frame 1 (at or before).
  assert.deepEqual(store.positionsAt(0.25, out), { frame: 1, exact: false });
  assert.equal(out[0], 1);
  // Frame 1 here, frame 2 not: frame 1 itself.
  assert.deepEqual(store.positionsAt(0.15, out), { frame: 1, exact: true });
  assert.equal(store.prefixPositions(3), null);
  store.add(2, 1, batch(2, 1, 2));
  store.add(5, 1, batch(5, 1, 2));
  assert.ok(store.complete);
  assert.deepEqual(store.ranges(), [[0, 6]]);
  const all = store.prefixPositions();
  assert.equal(all.length, 36);
  assert.equal(all[6 * 4], 4);
  assert.equal(store.frameAt(9), 5);
  assert.equal(store.frameAt(-1), 0);
  assert.throws(() => store.add(5, 2, batch(5, 2, 2)), /outside/);
  assert.throws(() => store.add(0, 1, new Float32Array(5)), /floats/);
});

test('PlaybackClock: speed, loop at the playable end, seek', () => {
  const clock = new PlaybackClock({ start: 0, end: 2 });
  assert.equal(clock.tick(0.5), 0); // paused
  clock.playing = true;
  assert.equal(clock.tick(0.5), 0.5);
  clock.speed = 2;
  assert.equal(clock.tick(0.25), 1);
  // Only [0, 1.2] playable: wraps there.
  assert.ok(Math.abs(clock.tick(0.2, 1.2) - 0.2) < 1e-12);
  clock.speed = -1;
  assert.ok(Math.abs(clock.tick(0.5, 1.2) - 0.9) < 1e-12);
  assert.equal(clock.seek(5), 2);
  assert.equal(clock.seek(-1), 0);
  clock.setRange(1, 3);
  assert.equal(clock.time, 1);
});

test('clip library: files exist, filter, clip option, joints per family', () => {
  for (const f of libraryFiles()) assert.ok(fs.existsSync(path.join(repoDir, 'data', f)), f);
  assert.ok(librarySources.length >= 5 && libraryTargets.length >= 3);
  const clips = [{ name: 'Walking_A', duration: 1 }, { name: 'Running_A', duration: 0.8 }, { name: 'Walking_B', duration: 1.1 }];
  assert.deepEqual(filterClips(clips, 'walk').map((c) => c.index), [0, 2]);
  assert.deepEqual(filterClips(clips, 'WALK b').map((c) => c.name), ['Walking_B']);
  assert.equal(filterClips(clips, '').length, 3);
  assert.equal(clipOption(clips, 1), 'Running_A');
  assert.equal(clipOption([{ name: '' }], 0), '');
  assert.equal(clipOption([{ name: 'a' }, { name: '' }], 1), null);
  assert.deepEqual(filterClips([{ name: '', duration: 2 }]).map((c) => c.label), ['(unnamed clip 1)']);
  const woman = libraryTargets.find((t) => t.id === 'woman');
  assert.equal(jointsFileFor(woman, 'kaykit'), 'joints/human_woman_kaykit_joints.json');
  assert.equal(jointsFileFor(woman, 'robot'), null);
  assert.equal(jointsFileFor(libraryTargets.find((t) => t.id === 'barbarian'), 'kaykit'), null);
});

test('joints: file round trip, errors, bones through missing ancestors, following the surface', () => {
  const json = JSON.parse(fs.readFileSync(path.join(repoDir, 'data/joints/human_woman_kaykit_joints.json'), 'utf8'));
  const joints = readJointsFile(json);
  assert.equal(joints.length, 18);
  assert.deepEqual(jointsFile(joints), json);
  assert.throws(() => readJointsFile([1, 2]), /expected an object/);
  assert.throws(() => readJointsFile({ a: [0, 0] }, 'j.json'), /j.json: joint "a" must be/);
  assert.throws(() => readJointsFile({ a: [0, 0, 0] }), /at least 2/);
  // Pins (the CLI's markers file): one joint is enough, none is not.
  assert.deepEqual(readJointsFile({ a: [0, 1, 2] }, 'pins.json', { min: 1 }), [{ name: 'a', position: [0, 1, 2] }]);
  assert.throws(() => readJointsFile({}, 'pins.json', { min: 1 }), /pins.json: needs at least 1 joint \(found 0\)/);
  // root → hips → spine → chest; "spine" is not a joint here: chest's bone goes to hips.
  const parents = { hips: 'root', spine: 'hips', chest: 'spine', head: 'chest', root: null };
  assert.deepEqual(bonesOf(['hips', 'chest', 'head'], (n) => parents[n] ?? null), [[1, 0], [2, 1]]);

  // A bar of 2 × 4 vertices along x; joints at its ends; stretch the right half by 1.
  const rest = Float32Array.from([0, 0, 0, 1, 0, 0, 2, 0, 0, 3, 0, 0, 0, 1, 0, 1, 1, 0, 2, 1, 0, 3, 1, 0]);
  const follower = new JointFollower(rest, [[0, 0.5, 0], [3, 0.5, 0]], 2);
  const moved = rest.slice();
  for (const v of [3, 7]) moved[3 * v] += 1;
  const at = follower.at(moved);
  assert.deepEqual(Array.from(at), [0, 0.5, 0, 4, 0.5, 0]);
  const bones = [[1, 0]];
  const restLengths = boneLengths(follower.at(rest), bones);
  assert.deepEqual(Array.from(restLengths), [3]);
  const change = boneLengthChange(at, bones, restLengths);
  // Nearest vertices against a full sort (random cloud).
  let seed = 7;
  const random = () => { seed = (seed * 16807) % 2147483647; return seed / 2147483647; };
  const cloud = Float32Array.from({ length: 3000 }, random);
  const far = new JointFollower(cloud, [[0.5, 0.5, 0.5], [0, 1, 0]], 16);
  for (const [j, p] of [[0.5, 0.5, 0.5], [0, 1, 0]].entries()) {
    const d = (v) => (cloud[3 * v] - p[0]) ** 2 + (cloud[3 * v + 1] - p[1]) ** 2 + (cloud[3 * v + 2] - p[2]) ** 2;
    const sorted = Array.from({ length: 1000 }, (_, v) => v).sort((a, b) => d(a) - d(b) || a - b).slice(0, 16);
    assert.deepEqual(far.near[j], sorted);
  }
  assert.ok(Math.abs(change.mean - 1 / 3) < 1e-6 && Math.abs(change.max - 1 / 3) < 1e-6);
});

// A fake client: each request resolves when the test says so; cancel rejects it.
function fakeClient() {
  const requests = [];
  let nextId = 1;
  return {
    requests,
    run(op, options, buffers, { onProgress } = {}) {
      const id = nextId++;
      let settle;
      const promise = new Promise((resolve, reject) => { settle = { resolve, reject }; });
      requests.push({ id, op, options, buffers, onProgress, ...settle, cancelled: false });
      return { id, promise };
    },
    cancel(id) {
      const r = requests.find((q) => q.id === id);
      r.cancelled = true;
      r.reject(Object.assign(new Error('cancelled'), { code: 'Cancelled' }));
    },
  };
}
const tick = () => new Promise((resolve) => setTimeout(resolve, 0));

test('RetargetRunner: prepare, growing batches, events; a new start cancels and disposes the old run', async () => {
  const client = fakeClient();
  const events = [];
  const runner = new RetargetRunner({ run: client.run, cancel: client.cancel, onEvent: (t, d) => events.push([t, d]), batchSizes: [2, 3] });
  let buffersMade = 0;
  const request = { options: { clip: 'Walk' }, buffers: () => { buffersMade += 1; return { source: new Uint8Array(1), target: new Uint8Array(1) }; } };
  const first = runner.start(request);
  await tick();
  assert.equal(client.requests[0].op, 'retargetPrepare');
  client.requests[0].onProgress('svd', 0.5);
  client.requests[0].resolve({ info: { session: 7, frames: 6 }, buffers: {} });
  await tick();
  assert.equal(client.requests[1].op, 'retargetFrames');
  assert.deepEqual(client.requests[1].options, { session: 7, first: 0, count: 2 });
  client.requests[1].onProgress('frames', 0.5);
  client.requests[1].resolve({ info: { count: 2 }, buffers: { positions: new Float32Array(6) } });
  await tick();
  assert.deepEqual(client.requests[2].options, { session: 7, first: 2, count: 3 });
  // A new start while frames compute: the request is cancelled and the session disposed.
  const second = runner.start(request);
  await first;
  assert.ok(client.requests[2].cancelled);
  const disposes = client.requests.filter((r) => r.op === 'retargetDispose');
  assert.deepEqual(disposes.map((r) => r.options.session), [7]);
  await tick();
  const prepare2 = client.requests.filter((r) => r.op === 'retargetPrepare')[1];
  prepare2.resolve({ info: { session: 8, frames: 3 }, buffers: {} });
  await tick();
  const frames2 = client.requests.filter((r) => r.op === 'retargetFrames' && r.options.session === 8);
  assert.deepEqual(frames2[0].options, { session: 8, first: 0, count: 2 });
  frames2[0].resolve({ info: { count: 2 }, buffers: { positions: new Float32Array(6) } });
  await tick();
  const last = client.requests.at(-1);
  assert.deepEqual(last.options, { session: 8, first: 2, count: 1 });
  last.resolve({ info: { count: 1 }, buffers: { positions: new Float32Array(3) } });
  await second;
  assert.equal(buffersMade, 2);
  const types = events.map(([t]) => t);
  assert.deepEqual(types.filter((t) => t !== 'progress'), ['prepared', 'frames', 'prepared', 'frames', 'frames', 'done']);
  const progress = events.filter(([t]) => t === 'progress').map(([, d]) => d);
  assert.deepEqual(progress[0], { phase: 'prepare', stage: 'svd', fraction: 0.5 });
  assert.deepEqual(progress[1], { phase: 'frames', stage: 'frames', fraction: 1 / 6 });
  assert.equal(runner.running, false);
  assert.equal(runner.session, 8);
});

test('RetargetRunner: errors end the run; stop() cancels; a superseded prepare is disposed', async () => {
  const client = fakeClient();
  const events = [];
  const runner = new RetargetRunner({ run: client.run, cancel: client.cancel, onEvent: (t, d) => events.push([t, d]) });
  const request = { options: {}, buffers: () => ({}) };
  const a = runner.start(request);
  await tick();
  client.requests[0].reject(Object.assign(new Error('bad joints'), { code: 'InvalidArgument' }));
  await a;
  assert.equal(events.at(-1)[0], 'error');
  assert.equal(events.at(-1)[1].error.code, 'InvalidArgument');

  const b = runner.start(request);
  await tick();
  assert.equal(runner.stop(), true);
  await b;
  assert.equal(events.at(-1)[0], 'stopped');
  assert.equal(runner.stop(), false);

  // The worker finished a prepare before the cancel reached it: its session is disposed.
  const noCancel = { ...client, cancel() {} };
  const runner2 = new RetargetRunner({ run: client.run, cancel: noCancel.cancel });
  const c = runner2.start(request);
  await tick();
  const prepare = client.requests.at(-1);
  const d = runner2.start(request);
  prepare.resolve({ info: { session: 11, frames: 1 }, buffers: {} });
  await c;
  assert.ok(client.requests.some((r) => r.op === 'retargetDispose' && r.options.session === 11));
  await tick();
  runner2.stop();
  client.requests.filter((r) => r.op === 'retargetPrepare').at(-1).resolve({ info: { session: 12, frames: 1 }, buffers: {} });
  await d;
  assert.ok(client.requests.some((r) => r.op === 'retargetDispose' && r.options.session === 12));
});
