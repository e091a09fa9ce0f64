// The Retarget job: animate a target character with a clip of a skinned source character,
// without rigging the target (paper 002, docs/retarget.md; worker ops in worker/ops/retarget.js).
// A guided step list leads through
//   1 the clip: a library of the bundled skinned characters (lib/clip-library.js), browsed by
//     character and clip name (filter), with a small animated preview of the selected clip
//     (view/clip-preview.js); or the person's own skinned, animated GLB
//   2 the target: a bundled character (rigged KayKit, or a plain mesh with hand-placed joints)
//     or the person's own mesh (glTF/OBJ/OFF/PLY); its joints come from its skin or from a
//     joints file (the CLI's {"name": [x, y, z]}); shown as spheres and bones over the
//     see-through target. The joints choice (`#rt-joints-from`): its skin, a joints file, or
//     automatic (the source's skeleton fitted inside the target by the joints job, issue 14;
//     the default for an unrigged mesh without a bundled joints file). A joint dragged with the
//     mouse is pinned there (the fit keeps it; pins download as the CLI's --markers file); a
//     joint chosen in "Click to pin" is pinned where a click on the target lands (the middle of
//     the limb under the pointer), also when the fit was refused and there are no joints to drag.
//   3 retarget: method (harmonic / the LBS baseline) and the job's options (optionSchema {job:
//     'retarget'}); any change starts a new run at once and cancels the one going
//     (lib/retarget-runner.js): retargetPrepare, then frames in growing batches, each playable
//     as it arrives (lib/frame-store.js)
//   4 play: the timeline under the view (ui/timeline.js: play / pause, scrub, speed, the
//     computed frames drawn under the bar, the bone-length change per frame as a plot); source
//     and target side by side or in split panes, in sync (view/retarget-view.js)
//   5 export: the animated GLB (retargetExportGlb: the job's export layout — per frame, or compact
//     above 60 frames), the joints JSON;
//     an animated GLB opened here plays on the target side with the same timeline.
// State it owns (window.__meshmorph.state.retarget): {step, source ({id, name, family, clips,
// clip, clipName}), target ({id, name, skinned, vertices}), jointsFrom ('skin' | 'file' | 'auto'),
// pins ({joint name: [x, y, z]}: joints dragged by the person; the automatic fit keeps them),
// fit ({status: 'idle' | 'fitting' | 'done' | 'error', fits, ms, pins, warnings}),
// joints (count) , method, run ({status: 'idle' | 'preparing' | 'frames' | 'done' | 'error' |
// 'stopped', session, frames, received, contiguous, clip, warnings, prepareMs, framesMs}),
// playing, time, frame, speed, firstFrameMs (choosing the clip → its first frame shown),
// shownFrames, runs, exports, played ({name, duration, morphTargets} of an opened GLB)}.
// Test hooks (window.__meshmorph.hooks): retargetFrame(k) → frame k's positions (array) or null,
// retargetShown() → the target positions on screen, retargetJoints() → {names, positions},
// retargetSeek(t), retargetJointOnScreen(j) → {x, y}, retargetCamera() → the camera position,
// retargetPinnedDrawn() → the joints drawn as pins (red), retargetDropJoint(j, [x, y, z]) → drops
// joint j there as the drag would (without its inside constraint), retargetSourceGraph() → the source's graph
// nodes as drawn (following the clip), retargetPointOnScreen([x, y, z]) → the client pixel of a
// target point, retargetInsidePointAt(x, y) → where a click there would pin a joint (or null).
import * as THREE from 'three';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { clipOption, filterClips, jointsFileFor, familiesOf, librarySources, libraryTargets } from '../../lib/clip-library.js';
import { MeshMorphError, toMeshMorphError } from '../../lib/errors.js';
import { FrameStore, PlaybackClock } from '../../lib/frame-store.js';
import { JointFollower, boneLengthChange, boneLengths, bonesOf, jointsFile, parseJointsText } from '../../lib/retarget-joints.js';
import { RetargetRunner } from '../../lib/retarget-runner.js';
import { ClipPreview } from '../../view/clip-preview.js';
import { RetargetView } from '../../view/retarget-view.js';
import { download } from '../download.js';
import { finder, fromHtml } from '../dom.js';
import { OptionsForm } from '../options-form.js';
import { StepList } from '../step-list.js';
import { Timeline } from '../timeline.js';
import './retarget.css';

const targetSlot = 'retarget-target';
const meshTypes = '.glb,.gltf,.obj,.off,.ply';

const markup = `
<section class="retarget">
  <h2>Retarget</h2>
  <div id="rt-steps"></div>
  <h3>Clip</h3>
  <div class="row">
    <label for="rt-character">Character</label>
    <select id="rt-character"></select>
    <label class="button file" title="Your own skinned, animated character (.glb, or a .gltf with everything embedded)">Open…<input type="file" id="rt-source-file" accept=".glb,.gltf" /></label>
  </div>
  <div class="clip-browser">
    <div class="clip-list">
      <input id="rt-clip-filter" type="search" placeholder="Filter clips (e.g. walk)" aria-label="Filter clips" />
      <select id="rt-clip" size="8" aria-label="Clips"></select>
    </div>
    <div id="rt-preview" class="clip-preview-box" title="The selected clip on its own character"></div>
  </div>
  <p id="rt-source-info" class="hint"></p>

  <h3>Target</h3>
  <div class="row">
    <label for="rt-target">Target</label>
    <select id="rt-target" data-idle></select>
    <label class="button file" title="Your own mesh: glTF / GLB (rigged or not), OBJ, OFF or PLY">Open…<input type="file" id="rt-target-file" accept="${meshTypes}" data-idle /></label>
  </div>
  <div class="row">
    <label for="rt-joints-from" title="Where the target's joints come from">Joints</label>
    <select id="rt-joints-from">
      <option value="skin">from its skin</option>
      <option value="file">from a joints file</option>
      <option value="auto">automatic (fitted inside the mesh)</option>
    </select>
    <label class="button file" id="rt-joints-file-label" title="A joints file {&quot;joint name&quot;: [x, y, z]} in the target's coordinates, named like the source's joints (meshmorph retarget --target-joints)">Joints file…<input type="file" id="rt-joints-file" accept=".json,application/json" /></label>
  </div>
  <div class="row">
    <label class="button file" title="Only when the joints file's names differ from the source's: {&quot;source joint&quot;: &quot;target joint&quot;} (meshmorph retarget --joint-map)">Joint map…<input type="file" id="rt-map-file" accept=".json,application/json" /></label>
    <span id="rt-map-info" class="hint"></span>
  </div>
  <p id="rt-target-info" class="hint"></p>
  <div class="row" id="rt-pins-row" hidden>
    <label title="Pause and show the target in its rest pose; drag its joints there"><input type="checkbox" id="rt-edit-joints" /> Edit joints (rest pose)</label>
    <span id="rt-pins-info" class="hint"></span>
    <button id="rt-pins-clear" type="button" title="Forget every pinned joint and fit again">Clear pins</button>
    <button id="rt-pins-save" type="button" title="The pinned joints as the CLI's markers file (meshmorph retarget --target-joints auto --markers M.json)">Download pins JSON</button>
    <label class="button file" id="rt-pins-load" title="Pins from a file, the CLI's markers file {&quot;joint name&quot;: [x, y, z]}: the automatic fit keeps these joints there (also when it refused the fit without them)">Load pins…<input type="file" id="rt-pins-file" accept=".json,application/json" /></label>
    <span id="rt-pin-click-row">
      <label for="rt-pin-joint" title="Choose a joint of the clip's character, then click on the target where that joint is: the pin goes to the middle of the limb under the pointer (in depth), and the automatic fit keeps the joint there">Click to pin</label>
      <select id="rt-pin-joint"><option value="">(a joint)</option></select>
    </span>
  </div>
  <div class="row">
    <label title="Draw the target see-through with its joints (spheres) and bones (lines)"><input type="checkbox" id="rt-skeleton" checked /> Joints and bones</label>
  </div>

  <h3>Retarget</h3>
  <div class="row" role="radiogroup" aria-label="Method">
    <label title="Harmonic maps (paper 002): the target keeps its own shape"><input type="radio" name="rt-method" value="harmonic" checked /> harmonic</label>
    <label title="The naive baseline: the source's skin weights on the target (linear blend skinning)"><input type="radio" name="rt-method" value="lbs" /> LBS baseline</label>
    <button id="rt-run" type="button" title="Compute again (any change of clip, target or options does it by itself)">Retarget</button>
    <button id="rt-stop" type="button" title="Stop computing frames (those computed stay)">Stop</button>
  </div>
  <div id="rt-run-info" class="run-info">
    <progress id="rt-progress" max="1" value="0" hidden></progress>
    <span id="rt-run-text" class="hint"></span>
  </div>
  <details id="rt-warnings" class="run-warnings" hidden><summary></summary><ul></ul></details>
  <div id="rt-options"></div>

  <h3>View</h3>
  <div class="row" role="radiogroup" aria-label="View">
    <label title="Both characters in one view"><input type="radio" name="rt-view" value="side" checked /> Side by side</label>
    <label title="Two views, each with its own camera"><input type="radio" name="rt-view" value="split" /> Split</label>
    <label id="rt-link-row" hidden title="Orbiting one view moves the other the same way"><input type="checkbox" id="rt-link" checked /> Link the cameras</label>
  </div>
  <div class="row">
    <label title="The context graph of the run (paper 002 Sec. 6; option context_graph on): the source's graph nodes (coloured by body part) and edges following the clip, the target's graph nodes and edges and its volume graph following the frames"><input type="checkbox" id="rt-graph" disabled /> Context graph</label>
    <span id="rt-graph-info" class="hint"></span>
  </div>

  <h3>Export</h3>
  <div class="row">
    <button id="rt-export" type="button" title="The animated target (plays in three.js and Blender): one morph target per frame, or for clips over 60 frames the compact export (the clip's mean and principal components within the option export_tolerance; option export)">Download GLB</button>
    <button id="rt-joints-save" type="button" title="The target's joints as the CLI's joints file">Download joints JSON</button>
  </div>
  <div class="row">
    <label class="button file" title="Play an animated GLB (e.g. one downloaded here) on the target side">Play a GLB…<input type="file" id="rt-play-file" accept=".glb" data-idle /></label>
    <button id="rt-back" type="button" hidden title="Back to the retargeted frames">Back to the retargeting</button>
  </div>
  <p id="rt-export-info" class="hint"></p>
</section>`;

const loader = new GLTFLoader();
function parseGltf(bytes) {
  const ab = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  return new Promise((resolve, reject) => loader.parse(ab, '', resolve, (e) => reject(new MeshMorphError('ParseError', `three.js could not read the file: ${e?.message || e}`))));
}

async function fetchData(rel) {
  const url = new URL(`samples/${rel}`, document.baseURI);
  const response = await fetch(url);
  if (!response.ok) throw new MeshMorphError('IoError', `could not fetch ${url}: HTTP ${response.status}`);
  return new Uint8Array(await response.arrayBuffer());
}

const fileName = (path) => path.slice(path.lastIndexOf('/') + 1);
const stem = (name) => name.replace(/^.*[\\/]/, '').replace(/\.[^.]*$/, '');

// three.js sanitizes node names ("upperarm.l" → "upperarml"); the core and the joints file use
// the file's own names: the name of an object's glTF node.
function nodeName(gltf, object) {
  const index = gltf.parser.associations.get(object)?.nodes;
  return index == null ? object.name : (gltf.parser.json.nodes[index].name ?? object.name);
}

// Joints of a skinned glTF in its scene's coordinates at the bind pose: every bone that moves
// some skin (a weight > 0), at the translation of its inverse bind matrix's inverse.
function skinJoints(gltf) {
  const joints = new Map(); // name → position
  gltf.scene.updateMatrixWorld(true);
  gltf.scene.traverse((o) => {
    if (!o.isSkinnedMesh) return;
    const { skeleton, geometry } = o;
    const index = geometry.getAttribute('skinIndex');
    const weight = geometry.getAttribute('skinWeight');
    const used = new Set();
    if (index && weight) {
      for (let v = 0; v < index.count; ++v) {
        for (let c = 0; c < 4; ++c) if (weight.getComponent(v, c) > 0) used.add(index.getComponent(v, c));
      }
    }
    skeleton.bones.forEach((bone, i) => {
      const name = nodeName(gltf, bone);
      if (!used.has(i) || joints.has(name)) return;
      const m = skeleton.boneInverses[i].clone().invert();
      joints.set(name, new THREE.Vector3().setFromMatrixPosition(m).toArray());
    });
  });
  return [...joints].map(([name, position]) => ({ name, position }));
}

// Every joint of a glTF's skins (the file's node names, skin order): the joints the automatic
// fit places and a pin may name.
function skeletonJointNames(gltf) {
  const json = gltf.parser.json;
  const names = (json.skins || []).flatMap((skin) => (skin.joints || []).map((n) => json.nodes?.[n]?.name).filter((n) => n != null));
  return [...new Set(names)];
}

// parentOf(name) over a glTF's node hierarchy (the file's node names).
function parentsOf(gltf) {
  const parents = new Map();
  const nodes = gltf.parser.json.nodes || [];
  nodes.forEach((node) => {
    for (const c of node.children || []) if (nodes[c]?.name) parents.set(nodes[c].name, node.name ?? null);
  });
  return (name) => parents.get(name) ?? null;
}

export const panel = {
  id: 'retarget',
  title: 'Retarget',
  create(app) {
    const { state, viewer, client } = app;
    const root = fromHtml(markup);
    const $ = finder(root);
    const retarget = {
      step: 0, source: null, target: null, jointsFrom: 'skin', joints: 0, method: 'harmonic',
      run: { status: 'idle' }, playing: false, time: 0, frame: -1, speed: 1, firstFrameMs: null,
      shownFrames: 0, runs: 0, exports: 0, played: null, view: 'side',
      pins: {}, fit: { status: 'idle', fits: 0 }, editingJoints: false, graph: { sets: 0, nodes: 0, edges: 0 },
    };
    state.retarget = retarget;

    const steps = new StepList([
      { title: 'Choose a clip' },
      { title: 'Choose the target and its joints' },
      { title: 'Retarget' },
      { title: 'Play and compare' },
      { title: 'Export' },
    ]);
    $('rt-steps').append(steps.element);

    const view = new RetargetView(viewer);
    const preview = new ClipPreview();
    $('rt-preview').append(preview.element);
    const timeline = new Timeline({
      onPlay: (on) => setPlaying(on),
      onSeek: (t) => { setPlaying(false); clock.seek(t); applyTime(); },
      onSpeed: (s) => { clock.speed = s; retarget.speed = s; },
    });
    viewer.renderer.domElement.after(timeline.element);
    const paneLabels = fromHtml('<div class="pane-labels" hidden><span>Source</span><span>Target</span></div>');
    viewer.renderer.domElement.after(paneLabels);

    // Everything loaded or computed.
    const cache = new Map(); // library id → {bytes, gltf}
    let source = null;   // {id, name, bytes, gltf, family, parentOf}
    let target = null;   // {id, name, bytes, skinned, gltf|null, load (load op result)}
    let joints = null;   // {names, positions: [[x,y,z]], bones, from} in target coordinates
    let jointsText = ''; // the joints file sent (joints from file), '' = the skin
    let mapText = '';    // the joint map sent, '' = none
    let store = null;    // FrameStore of the current run
    let surface = null;  // {positions (rest, core layout), indices} of the current run
    let follower = null; // JointFollower on the run's rest surface
    let restLengths = null;
    let plot = null;     // Float64Array per frame: mean bone-length change (NaN = not yet)
    let crossings = null; // Float64Array per frame: self-intersecting triangle pairs (NaN = not yet)
    let graph = null;    // {sets: [{positions, follower}]} of the run's context graph (target side)
    let shownBuffer = null;
    let form = null;
    let visible = false;
    let clipChosenAt = null; // performance.now() when the clip was chosen (first frame timing)
    let timedStore = null;   // the first run's frames after that choice (older frames do not count)
    let timingPending = false;
    let userPaused = false;
    const clock = new PlaybackClock();

    // ---- the state shown

    function refresh() {
      const run = retarget.run;
      let step;
      let next;
      if (!source || retarget.source?.clip == null) {
        step = 0;
        next = 'Pick a character and one of its clips (the preview plays it), or open your own skinned GLB.';
      } else if (!target) {
        step = 1;
        next = 'Pick a target: a bundled character, or Open… your own mesh.';
      } else if (!joints) {
        step = 1;
        if (retarget.jointsFrom === 'auto') {
          next = retarget.fit.status === 'fitting'
            ? `Fitting the ${source.name} skeleton inside ${target.name}…`
            : `The automatic joints failed: choose "from a joints file", or pick a clip of another character.`;
        } else {
          next = retarget.jointsFrom === 'file'
            ? `Load a joints file for ${target.name} (names of the ${source.name} skeleton), choose "automatic", or pick a bundled target.`
            : `${target.name} has no skin: choose "automatic" or "from a joints file".`;
        }
      } else if (run.status === 'preparing' || (run.status === 'frames' && !retarget.shownFrames)) {
        step = 2;
        next = 'Computing: the first frames play as soon as they arrive.';
      } else if (run.status === 'error' || run.status === 'idle' || run.status === 'stopped') {
        step = 2;
        next = run.status === 'error' ? 'Fix the problem above (or change an option), then press Retarget.' : 'Press Retarget.';
      } else if (retarget.exportedRun !== retarget.runs) {
        step = 3;
        next = 'Play, scrub, change the speed; toggle harmonic / LBS to compare. Then Download GLB.';
      } else {
        step = 4;
        next = 'Downloaded. Play a GLB… opens it again here; any change recomputes.';
      }
      retarget.step = step;
      steps.set(step, next);
      $('rt-stop').disabled = !(run.status === 'preparing' || run.status === 'frames');
      $('rt-run').disabled = !(source && target && joints);
      $('rt-export').disabled = !(store && store.complete);
      $('rt-joints-save').disabled = !joints;
      $('rt-joints-file-label').classList.toggle('disabled', retarget.jointsFrom !== 'file');
      $('rt-joints-file').disabled = retarget.jointsFrom !== 'file';
    }

    function runText(text, fraction = null) {
      $('rt-run-text').textContent = text;
      $('rt-progress').hidden = fraction == null;
      if (fraction != null) $('rt-progress').value = fraction;
    }

    // ---- step 1: the clip library

    for (const s of librarySources) $('rt-character').add(new Option(s.label, s.id));
    $('rt-character').add(new Option('Your own file…', 'file'));
    $('rt-character').value = '';

    async function loadLibrarySource(id) {
      const entry = librarySources.find((s) => s.id === id);
      let cached = cache.get(id);
      if (!cached) {
        app.setStatus(`loading ${entry.label}…`);
        const bytes = await fetchData(entry.path);
        cached = { bytes, gltf: await parseGltf(bytes) };
        cache.set(id, cached);
      }
      // The view takes the scene: a fresh parse keeps the cached one for the preview.
      setSource({ id, name: fileName(entry.path), label: entry.label, family: entry.family, bytes: cached.bytes, gltf: cached.gltf });
    }

    function setSource(s) {
      const skinned = [];
      s.gltf.scene.traverse((o) => { if (o.isSkinnedMesh) skinned.push(o); });
      if (!skinned.length) throw new MeshMorphError('InvalidArgument', `${s.name} has no skin (no skinned mesh): the source must be a rigged, animated character`);
      if (!s.gltf.animations.length) throw new MeshMorphError('InvalidArgument', `${s.name} has no animation clips`);
      // The file's own clip names ("" when unnamed; three.js would say "animation_0").
      const names = (s.gltf.parser.json.animations || []).map((a) => a.name ?? '');
      const clips = s.gltf.animations.map((c, i) => ({ name: names[i] ?? c.name, duration: c.duration }));
      source = { ...s, clips, parentOf: parentsOf(s.gltf), jointNames: skeletonJointNames(s.gltf) };
      retarget.source = { id: s.id, name: s.name, family: s.family, clips: clips.map((c) => c.name), clip: null, clipName: null };
      $('rt-clip-filter').value = '';
      showClips();
      // The new character in its rest pose until a clip is picked (the last one's stayed on screen).
      view.setSource(s.gltf, -1);
      $('rt-source-info').textContent = `${s.label || s.name}: ${s.gltf.animations.length} clip${s.gltf.animations.length === 1 ? '' : 's'}. Pick one.`;
      app.setStatus(`${s.label || s.name}: ${s.gltf.animations.length} clips`);
      // A source of another skeleton: a bundled target's joints file depends on it.
      if (target && !target.skinned && (target.libraryId || retarget.jointsFrom === 'auto')) {
        if (retarget.jointsFrom === 'auto') retarget.pins = {}; // pins name the old skeleton's joints
        chooseJoints();
      }
      refresh();
      // One clip: nothing to pick, so it is chosen (its preview plays, and the run starts once
      // a target is there).
      if (clips.length === 1 && clipOption(clips, 0) != null) {
        chooseClip(0);
        $('rt-clip').value = '0';
      }
    }

    function showClips() {
      const select = $('rt-clip');
      select.replaceChildren();
      if (!source) return;
      const list = filterClips(source.clips, $('rt-clip-filter').value);
      for (const c of list) {
        const o = new Option(`${c.label}  (${c.duration.toFixed(1)} s)`, String(c.index));
        select.add(o);
      }
      if (retarget.source?.clip != null) select.value = String(retarget.source.clip);
    }

    $('rt-clip-filter').addEventListener('input', showClips);

    $('rt-character').addEventListener('change', async () => {
      const id = $('rt-character').value;
      if (id === 'file') {
        $('rt-source-file').click();
        return;
      }
      try {
        await loadLibrarySource(id);
      } catch (e) {
        app.showError(e);
      }
    });

    $('rt-source-file').addEventListener('change', async () => {
      const file = $('rt-source-file').files[0];
      $('rt-source-file').value = '';
      if (!file) return;
      try {
        const bytes = new Uint8Array(await file.arrayBuffer());
        setSource({ id: 'file', name: file.name, label: file.name, family: 'own', bytes, gltf: await parseGltf(bytes) });
        $('rt-character').value = 'file';
      } catch (e) {
        app.showError(e);
      }
    });

    $('rt-clip').addEventListener('change', () => chooseClip(Number($('rt-clip').value)));

    function chooseClip(index) {
      if (!source) return;
      const option = clipOption(source.clips, index);
      if (option == null) {
        app.showError({ code: 'InvalidArgument', message: 'this clip has no name, and only the first clip of a file can be chosen without one' });
        return;
      }
      clipChosenAt = performance.now();
      retarget.firstFrameMs = null;
      timingPending = true;
      timedStore = null;
      retarget.source.clip = index;
      retarget.source.clipName = option;
      const clip = source.gltf.animations[index];
      preview.paused = false;
      preview.show(source.gltf, index);
      $('rt-source-info').textContent = `${source.label || source.name} · ${source.clips[index].name || '(unnamed)'} · ${clip.duration.toFixed(2)} s`;
      // The main view shows the source in the clip's first pose until frames arrive.
      view.setSource(source.gltf, index);
      view.setSourceTime(0);
      startRun();
    }

    // ---- step 2: the target and its joints

    for (const t of libraryTargets) $('rt-target').add(new Option(t.label, t.id));
    $('rt-target').add(new Option('Your own file…', 'file'));
    $('rt-target').value = '';

    async function setTarget(t) {
      retarget.loadingTarget = true;
      const loaded = await app.runOp(`Loading ${t.name}`, 'load', { name: t.name, slot: targetSlot }, { [t.name]: t.bytes.slice() });
      retarget.loadingTarget = false;
      if (!loaded) return false;
      let gltf = null;
      if (/\.(glb|gltf)$/i.test(t.name)) {
        try {
          gltf = await parseGltf(t.bytes);
        } catch {
          gltf = null; // the core read it; without three.js's reading there is no skin to show
        }
      }
      let skinned = false;
      gltf?.scene.traverse((o) => { if (o.isSkinnedMesh) skinned = true; });
      target = { ...t, gltf, skinned, load: loaded };
      retarget.target = { id: t.libraryId ?? 'file', name: t.name, skinned, vertices: loaded.info.weldedVertices };
      stopRun('a new target');
      view.setTargetUp(1);
      if (retarget.editingJoints) setEditingJoints(false);
      view.setTargetMesh({ positions: loaded.buffers.positions, indices: loaded.buffers.indices });
      clearRunDisplay();
      $('rt-joints-from').value = skinned ? 'skin' : (t.libraryId && hasJointsFile(t.libraryId) ? 'file' : 'auto');
      retarget.pins = {};
      retarget.jointsFrom = $('rt-joints-from').value;
      jointsText = '';
      mapText = '';
      $('rt-map-info').textContent = '';
      await chooseJoints();
      return true;
    }

    // The joints for the target, from the choice: its skin, or a file (a bundled target's file
    // for the source's skeleton; otherwise the person's). Then a new run.
    // keepShown: the joints on screen stay until the new ones are there (a refit after a drag).
    async function chooseJoints(userFile = null, keepShown = false) {
      if (retarget.jointsFrom !== 'auto' && fitRequest) {
        client.cancel(fitRequest.id); // a fit going is no longer wanted
        fitRequest = null;
        retarget.fit = { ...retarget.fit, status: 'idle' };
      }
      if (!keepShown) {
        joints = null;
        view.clearJoints();
        retarget.joints = 0;
      }
      if (!target) return refresh();
      try {
        if (retarget.jointsFrom === 'skin') {
          if (!target.skinned) {
            $('rt-target-info').textContent = `${target.name}: ${target.load.info.weldedVertices} vertices, no skin — choose "from a joints file".`;
            return refresh();
          }
          const list = skinJoints(target.gltf);
          const parentOf = parentsOf(target.gltf);
          setJoints(list, bonesOf(list.map((j) => j.name), parentOf), 'skin');
          jointsText = '';
        } else if (retarget.jointsFrom === 'auto') {
          if (!source) {
            $('rt-target-info').textContent = `${target.name}: ${target.load.info.weldedVertices} vertices. Pick a clip: its character's skeleton is what is fitted inside ${target.name}.`;
            return refresh();
          }
          stopRun('new joints');
          const fitted = await fitJoints({ quiet: keepShown });
          if (!fitted) return refresh(); // superseded, cancelled or failed (the error is shown)
          const { names, parents, warnings, json } = fitted.info;
          const p = fitted.buffers.positions;
          const list = names.map((name, j) => ({ name, position: [p[3 * j], p[3 * j + 1], p[3 * j + 2]] }));
          const bones = parents.map((q, j) => (q >= 0 ? [j, q] : null)).filter(Boolean);
          const pinned = Object.keys(retarget.pins).length;
          setJoints(list, bones, pinned ? `the automatic fit with ${pinned} pinned` : 'the automatic fit');
          view.setTargetUp(fitted.info.targetUp); // the fit found which way is up: stand it upright
          // The core's warnings are clauses without a full stop: one sentence each.
          if (warnings.length) $('rt-target-info').textContent += ` ${warnings.filter(Boolean).map((w) => `${w[0].toUpperCase()}${w.slice(1).replace(/\.?$/, '.')}`).join(' ')}`;
          jointsText = json;
        } else {
          let text = null;
          let name = null;
          if (userFile) {
            text = await userFile.text();
            name = userFile.name;
          } else if (target.libraryId) {
            const entry = libraryTargets.find((t) => t.id === target.libraryId);
            const rel = source ? jointsFileFor(entry, source.family) : null;
            if (rel) {
              text = new TextDecoder().decode(await fetchData(rel));
              name = fileName(rel);
            } else if (entry.joints) {
              const fits = librarySources.filter((x) => familiesOf(entry).includes(x.family)).map((x) => x.label).join(', ');
              $('rt-target-info').textContent = `${target.name} has joints placed for the skeletons of ${fits}${source ? `, not for ${source.label || source.name}` : ''}: pick a clip of one of those, or load a joints file with this skeleton's names.`;
              return refresh();
            }
          } else if (retarget.userJoints) {
            ({ text, name } = retarget.userJoints);
          }
          if (text == null) {
            $('rt-target-info').textContent = `${target.name}: ${target.load.info.weldedVertices} vertices. Load its joints file (Joints file…).`;
            return refresh();
          }
          const list = parseJointsText(text, name);
          const parentOf = source ? source.parentOf : () => null;
          // Bones follow the source skeleton (the file uses its names, or a map to them).
          const map = mapText ? JSON.parse(mapText) : {};
          const back = new Map(Object.entries(map).map(([s, t]) => [t, s]));
          const sourceName = (n) => back.get(n) ?? n;
          const forward = new Map(Object.entries(map));
          const targetParent = (n) => {
            const p = parentOf(sourceName(n));
            return p == null ? null : (forward.get(p) ?? p);
          };
          setJoints(list, bonesOf(list.map((j) => j.name), targetParent), name);
          jointsText = text;
        }
      } catch (e) {
        app.showError(e);
        return refresh();
      }
      startRun();
      return undefined;
    }

    function setJoints(list, bones, from) {
      joints = { names: list.map((j) => j.name), positions: list.map((j) => j.position), bones, from };
      retarget.joints = list.length;
      view.setJoints(list.map((j) => j.position), bones);
      view.setJointsVisible($('rt-skeleton').checked);
      view.setSeeThrough($('rt-skeleton').checked);
      $('rt-target-info').textContent = `${target.name}: ${target.load.info.weldedVertices} vertices · ${list.length} joints and ${bones.length} bones from ${from === 'skin' ? 'its skin' : from}.`;
      showPins();
    }

    // ---- automatic joints (issue 14): the source's skeleton fitted inside the target, pins
    // (dragged joints) hold named joints where the person put them. Latest fit only.

    let fitRequest = null;
    // quiet: no error banner (a pin's refit: the drop handler takes the pin back and says why).
    async function fitJoints({ quiet = false } = {}) {
      if (fitRequest) client.cancel(fitRequest.id);
      const pins = retarget.pins;
      const markersJson = Object.keys(pins).length ? JSON.stringify(pins) : '';
      const req = client.run('retargetJoints', { sourceName: source.name, targetName: target.name, markersJson },
        { source: source.bytes.slice(), target: target.bytes.slice() },
        { onProgress: (stage, fraction) => runText(`Fitting the ${source.label || source.name} skeleton inside ${target.name}: ${stage}…`, fraction) });
      fitRequest = req;
      const startedAt = performance.now();
      retarget.fit = { ...retarget.fit, status: 'fitting' };
      runText(`Fitting the ${source.label || source.name} skeleton inside ${target.name}…`, 0);
      try {
        const r = await req.promise;
        if (fitRequest !== req) return null;
        retarget.fit = { status: 'done', fits: retarget.fit.fits + 1, ms: Math.round(performance.now() - startedAt), pins: Object.keys(pins).length, warnings: r.info.warnings };
        runText(`Joints fitted in ${(retarget.fit.ms / 1000).toFixed(1)} s.`);
        return r;
      } catch (e) {
        if (fitRequest !== req || e.code === 'Cancelled') return null;
        if (e.code === 'Aborted') {
          // Lost with a replaced worker (another request's cancel timed out): fitted again
          // when the new worker is up ('restarted').
          retarget.fit = { ...retarget.fit, status: 'aborted' };
          return null;
        }
        retarget.fit = { ...retarget.fit, status: 'error', error: e.message };
        runText('');
        if (!quiet) app.showError(e);
        $('rt-target-info').textContent = `${target.name}: the automatic joints failed (${e.message}). Pin the joints it names (Click to pin: choose one, click where it is; or Load pins…), choose "from a joints file", or pick a clip of another character.`;
        if (!quiet) showPins();
        return null;
      } finally {
        if (fitRequest === req) fitRequest = null;
      }
    }

    function hasJointsFile(libraryId) {
      const entry = libraryTargets.find((t) => t.id === libraryId);
      return Boolean(entry && source && jointsFileFor(entry, source.family));
    }

    function showPins() {
      const names = Object.keys(retarget.pins);
      const draggable = joints && retarget.jointsFrom !== 'skin';
      // A refused automatic fit has no joints to drag: pins are placed by clicking the surface or
      // come from a file then (the core's refusal names the joints to pin).
      const refused = !joints && retarget.jointsFrom === 'auto' && retarget.fit.status === 'error';
      $('rt-pins-row').hidden = !draggable && !refused;
      $('rt-pins-load').hidden = retarget.jointsFrom !== 'auto';
      $('rt-pin-click-row').hidden = retarget.jointsFrom !== 'auto';
      fillPinJoints();
      $('rt-edit-joints').disabled = !draggable;
      if (!draggable && retarget.editingJoints) setEditingJoints(false);
      const placing = retarget.jointsFrom === 'auto' ? $('rt-pin-joint').value : '';
      $('rt-pins-info').textContent = placing
        ? `Click on ${target?.name ?? 'the target'} where ${placing} is (the pin goes to the middle of the limb under the pointer).`
        : refused
        ? `No joints to drag: pin the joints the message names (Click to pin, or Load pins… with the CLI's markers file)${names.length ? `. Pinned: ${names.join(', ')}` : ''}.`
        : !retarget.editingJoints
        ? 'A joint in the wrong place? Edit joints, then drag it.'
        : retarget.jointsFrom === 'auto'
          ? (names.length ? `Pinned: ${names.join(', ')}. Drag a joint to pin it too.` : 'Drag a joint: it stays where you drop it and the others fit around it.')
          : 'Drag a joint to move it (the joints file changes).';
      $('rt-pins-clear').disabled = names.length === 0;
      $('rt-pins-save').disabled = names.length === 0;
      if (joints) {
        view.setPinned(joints.names.map((n, j) => (n in retarget.pins ? j : -1)).filter((j) => j >= 0));
      } else if (retarget.jointsFrom === 'auto') {
        // No fitted joints (refused, or fitting): the pins alone, drawn as pins.
        const pinned = Object.values(retarget.pins);
        view.setJoints(pinned, []);
        view.setPinned(pinned.map((_, j) => j));
        view.setJointsVisible(pinned.length > 0 || $('rt-skeleton').checked);
      }
    }

    // The joints a click can pin: the clip character's skinned joints, those the fit's refusal
    // names first. Kept as they are while the source and the message stay the same.
    let pinJointsKey = '';
    function fillPinJoints() {
      const select = $('rt-pin-joint');
      const all = source?.jointNames ?? [];
      const message = retarget.fit.status === 'error' ? retarget.fit.error ?? '' : '';
      const key = `${source?.name}|${message}`;
      if (key === pinJointsKey) return;
      pinJointsKey = key;
      const words = new Set(message.split(/[\s,;:()"]+/).flatMap((w) => [w, w.replace(/\.$/, '')]));
      const named = all.filter((n) => words.has(n));
      const chosen = select.value;
      select.replaceChildren(new Option('(a joint)', ''), ...named.map((n) => new Option(`${n} (named in the message)`, n)),
        ...all.filter((n) => !named.includes(n)).map((n) => new Option(n, n)));
      select.value = all.includes(chosen) ? chosen : '';
    }

    // Joints are edited in the rest pose (pins are rest-pose positions): playback pauses and the
    // target shows its rest surface until editing ends.
    function showRest() {
      if (surface) view.setTargetPositions(surface.positions);
      if (joints) view.moveJoints(joints.positions.flat());
      if (graph) graph.sets.forEach((set, i) => view.moveGraph(i, set.positions));
    }
    function setEditingJoints(on) {
      retarget.editingJoints = on;
      $('rt-edit-joints').checked = on;
      if (on) {
        setPlaying(false);
        showRest();
      } else {
        applyTime();
      }
      showPins();
    }
    $('rt-edit-joints').addEventListener('change', () => setEditingJoints($('rt-edit-joints').checked));

    // A joint dropped at `position` (target coordinates) by the drag below (or by the test hook
    // retargetDropJoint, which skips the drag's inside constraint to reach the core's refusal).
    // Pins joint `name` at `position` and fits again (automatic joints). With fitted joints shown,
    // a pin the fit refuses (outside the mesh) is taken back: the joints return to where they were
    // and the core's message says why (`how`: what the person did, for that message). Without
    // (the fit was refused), the pin stays: the refusal may need more than one.
    function pinJoint(name, position, how) {
      if (!joints) {
        retarget.pins = { ...retarget.pins, [name]: position };
        app.clearError(); // the refusal the pin answers; a new one is shown if it still holds
        chooseJoints();
        return;
      }
      const before = retarget.pins;
      const shown = joints.positions.flat();
      retarget.pins = { ...retarget.pins, [name]: position };
      showPins();
      chooseJoints(null, true).then(() => {
        if (retarget.fit.status !== 'error') return;
        retarget.pins = before;
        retarget.fit = { ...retarget.fit, status: 'done' };
        view.moveJoints(shown);
        showPins();
        $('rt-target-info').textContent = `${name} was not pinned: ${retarget.fit.error.replace(/\.?$/, '.')} ${how} inside ${target.name}.`;
        if (retarget.run.status !== 'done') startRun();
        refresh();
      });
    }

    const dropJoint = (j, position) => {
      const name = joints.names[j];
      if (retarget.jointsFrom === 'auto') {
        pinJoint(name, position, 'Drop it');
        return;
      }
      // Joints from a file: the moved joint is the new file (download it with Download joints JSON).
      joints.positions[j] = position;
      jointsText = JSON.stringify(Object.fromEntries(joints.names.map((n, k) => [n, joints.positions[k]])));
      retarget.pins = { ...retarget.pins, [name]: position };
      showPins();
      startRun();
    };
    view.attachJointDrag({
      canDrag: () => retarget.editingJoints && Boolean(joints) && retarget.jointsFrom !== 'skin' && retarget.fit.status !== 'fitting',
      onDrop: dropJoint,
    });
    // Click to pin: a joint chosen in #rt-pin-joint is pinned where the next click on the target
    // lands (view.insidePointAt), in the rest pose; then the choice clears.
    $('rt-pin-joint').addEventListener('change', () => {
      if ($('rt-pin-joint').value) {
        if (joints) setEditingJoints(true);
        else {
          setPlaying(false);
          showRest();
        }
      }
      showPins();
    });
    view.attachTargetClick({
      canClick: () => retarget.jointsFrom === 'auto' && Boolean(target) && Boolean($('rt-pin-joint').value) && retarget.fit.status !== 'fitting',
      onClick: (x, y) => {
        const name = $('rt-pin-joint').value;
        const position = view.insidePointAt(x, y);
        if (!position) {
          $('rt-pins-info').textContent = `That click missed ${target.name}: click on it where ${name} is.`;
          return;
        }
        $('rt-pin-joint').value = '';
        pinJoint(name, position, 'Click');
      },
    });
    $('rt-pins-clear').addEventListener('click', () => {
      retarget.pins = {};
      if (retarget.jointsFrom === 'auto') chooseJoints();
      else showPins();
    });
    $('rt-pins-file').addEventListener('change', async () => {
      const file = $('rt-pins-file').files[0];
      $('rt-pins-file').value = '';
      if (!file || retarget.jointsFrom !== 'auto') return;
      try {
        retarget.pins = Object.fromEntries(parseJointsText(await file.text(), file.name, { min: 1 }).map((j) => [j.name, j.position]));
      } catch (e) {
        app.showError(e);
        return;
      }
      app.clearError(); // the refusal the pins answer
      showPins();
      chooseJoints();
    });
    $('rt-pins-save').addEventListener('click', () => {
      download(new TextEncoder().encode(`${JSON.stringify(retarget.pins, null, 1)}\n`), `${stem(target.name)}_pins.json`, 'application/json');
    });

    $('rt-target').addEventListener('change', async () => {
      const id = $('rt-target').value;
      if (id === 'file') {
        $('rt-target-file').click();
        return;
      }
      const entry = libraryTargets.find((t) => t.id === id);
      try {
        retarget.userJoints = null;
        await setTarget({ libraryId: id, name: fileName(entry.path), bytes: await fetchData(entry.path) });
      } catch (e) {
        app.showError(e);
      }
    });
    $('rt-target-file').addEventListener('change', async () => {
      const file = $('rt-target-file').files[0];
      $('rt-target-file').value = '';
      if (!file) return;
      try {
        retarget.userJoints = null;
        if (await setTarget({ libraryId: null, name: file.name, bytes: new Uint8Array(await file.arrayBuffer()) })) $('rt-target').value = 'file';
      } catch (e) {
        app.showError(e);
      }
    });
    $('rt-joints-from').addEventListener('change', () => {
      retarget.jointsFrom = $('rt-joints-from').value;
      retarget.pins = {};
      chooseJoints();
    });
    $('rt-joints-file').addEventListener('change', async () => {
      const file = $('rt-joints-file').files[0];
      $('rt-joints-file').value = '';
      if (!file) return;
      retarget.userJoints = { text: await file.text(), name: file.name };
      chooseJoints(file);
    });
    $('rt-map-file').addEventListener('change', async () => {
      const file = $('rt-map-file').files[0];
      $('rt-map-file').value = '';
      if (!file) return;
      const text = await file.text();
      try {
        const parsed = JSON.parse(text);
        if (!parsed || typeof parsed !== 'object' || Array.isArray(parsed) || !Object.values(parsed).every((v) => typeof v === 'string')) {
          throw new MeshMorphError('ParseError', `${file.name}: expected {"source joint": "target joint", ...}`);
        }
        mapText = text;
        $('rt-map-info').textContent = `${file.name}: ${Object.keys(parsed).length} names`;
      } catch (e) {
        app.showError(e instanceof SyntaxError ? { code: 'ParseError', message: `${file.name}: ${e.message}` } : e);
        return;
      }
      chooseJoints();
    });
    $('rt-skeleton').addEventListener('change', () => {
      view.setJointsVisible($('rt-skeleton').checked);
      view.setSeeThrough($('rt-skeleton').checked);
    });

    // ---- step 3: runs (latest only)

    const runner = new RetargetRunner({
      run: (op, options, buffers, handlers) => client.run(op, options, buffers, handlers),
      cancel: (id) => client.cancel(id),
      onEvent: (type, detail) => onRunEvent(type, detail),
    });

    function runOptions() {
      return {
        sourceName: source.name, targetName: target.name, targetJointsJson: jointsText, jointMapJson: mapText,
        ...(form ? form.values() : {}), clip: retarget.source.clipName, method: retarget.method,
      };
    }

    function startRun() {
      refresh();
      if (!source || retarget.source?.clip == null || !target || !joints) return;
      const options = runOptions();
      retarget.runs += 1;
      retarget.run = { status: 'preparing', options: { ...options, targetJointsJson: options.targetJointsJson ? '(file)' : '', jointMapJson: options.jointMapJson ? '(file)' : '' }, startedAt: performance.now() };
      runText('Preparing (harmonic maps of both characters)…', 0);
      const s = source;
      const t = target;
      runner.start({ options, buffers: () => ({ source: s.bytes.slice(), target: t.bytes.slice() }) });
      refresh();
    }

    function stopRun(why) {
      if (runner.stop()) runText(`Stopped (${why}).`);
    }

    // The core's notes on the inputs (parts left out, joints not used), folded.
    function showWarnings(list) {
      const box = $('rt-warnings');
      box.hidden = list.length === 0;
      box.querySelector('summary').textContent = `${list.length} note${list.length === 1 ? '' : 's'} on the inputs`;
      const ul = box.querySelector('ul');
      ul.replaceChildren(...list.map((w) => Object.assign(document.createElement('li'), { textContent: w })));
    }

    // Under the timeline: bone-length error per frame (%) and self-intersecting triangle pairs.
    function showPlot() {
      if (!plot) {
        timeline.setPlot(null);
        return;
      }
      const label = retarget.method === 'harmonic'
        ? 'bone-length error per frame (the map\'s joints) · self-intersecting triangle pairs beyond the rest pose\'s'
        : 'bone-length change per frame (joints followed on the surface) · self-intersecting triangle pairs beyond the rest pose\'s';
      timeline.setPlot(plot, label, { values: crossings, color: '#ff6b8a', legend: (m) => `intersections max ${Math.round(m)}` });
    }

    // The context graph of a finished run (harmonic with context_graph on), over both sides: the
    // target's nodes follow the frames by their nearest rest vertices, the source's the playing
    // clip by their nearest skinned vertices (RetargetView.sourceFollower).
    async function loadGraph(session) {
      graph = null;
      view.clearGraph();
      retarget.graph = { sets: 0, nodes: 0 };
      $('rt-graph').disabled = true;
      $('rt-graph-info').textContent = '';
      const opts = form ? form.values() : {};
      if (retarget.method !== 'harmonic' || !(opts.context_graph === true || opts.context_graph === 'on') || session == null) {
        $('rt-graph-info').textContent = 'on with the option context_graph (harmonic)';
        return;
      }
      try {
        const r = await client.run('retargetGraph', { session }).promise;
        if (!surface || session !== runner.session) return;
        const sets = [];
        let sourceGap = 0;
        r.info.sets.forEach((set, i) => {
          // The source's nodes are drawn by part (coloured points) and its edges; its plain node
          // set would only repeat the parts.
          if (set.source && set.name === 'source graph nodes') return;
          const positions = r.buffers[`set${i}Positions`];
          const points = [];
          for (let k = 0; k < positions.length; k += 3) points.push([positions[k], positions[k + 1], positions[k + 2]]);
          const follower = set.source ? view.sourceFollower(points) : new JointFollower(surface.positions, points, 8);
          if (!follower) return;
          if (set.source) sourceGap = Math.max(sourceGap, follower.gap);
          sets.push({ positions, lines: r.buffers[`set${i}Lines`], color: set.color, name: set.name, source: set.source, follower });
        });
        graph = { sets };
        view.setGraph(sets);
        view.setGraphVisible($('rt-graph').checked);
        const count = (side, what) => sets.filter((x) => !!x.source === side && (what === 'edges') === (x.lines.length > 0))
          .reduce((n, x) => n + (what === 'edges' ? x.lines.length / 2 : x.positions.length / 3), 0);
        retarget.graph = { sets: sets.length, nodes: count(false, 'nodes'), edges: count(false, 'edges'),
          sourceSets: sets.filter((x) => x.source).length, sourceNodes: count(true, 'nodes'), sourceEdges: count(true, 'edges'), sourceGap };
        $('rt-graph').disabled = false;
        const parts = sets.filter((x) => x.source && !x.lines.length).length;
        $('rt-graph-info').textContent = `source: ${retarget.graph.sourceNodes} nodes in ${parts} parts, ${retarget.graph.sourceEdges} edges · ` +
          sets.filter((x) => !x.source).map((x) => `${x.name}: ${x.lines.length ? `${x.lines.length / 2} edges` : `${x.positions.length / 3} nodes`}`).join(' · ');
        applyTime();
      } catch (e) {
        if (e.code !== 'Cancelled') app.showError(e);
      }
    }
    $('rt-graph').addEventListener('change', () => {
      view.setGraphVisible($('rt-graph').checked);
      applyTime();
    });

    function clearRunDisplay() {
      store = null;
      surface = null;
      follower = null;
      plot = null;
      crossings = null;
      graph = null;
      view.clearGraph();
      retarget.frame = -1;
      retarget.shownFrames = 0;
      timeline.setBuffered([], 0);
      timeline.setPlot(null);
      timeline.show(false);
      updateTimelineVisibility();
    }

    function onRunEvent(type, detail) {
      const run = retarget.run;
      if (type === 'progress') {
        if (detail.phase === 'prepare') runText(`Preparing: ${detail.stage}…`, detail.fraction);
        else runText(`Computing frames: ${store ? store.received : 0} of ${store?.count ?? '?'}`, detail.fraction);
        return;
      }
      if (type === 'prepared') {
        const { info, buffers } = detail;
        run.status = 'frames';
        run.session = info.session;
        run.frames = info.frames;
        run.clip = info.clip;
        run.warnings = info.warnings;
        run.received = 0;
        run.prepareMs = Math.round(performance.now() - run.startedAt);
        run.preparedAt = performance.now();
        // The run's surface replaces what was shown (the old run played until now).
        clearPlayedGlb();
        surface = { positions: buffers.targetPositions, indices: buffers.targetIndices };
        store = new FrameStore(buffers.times, buffers.targetPositions.length / 3);
        if (timingPending) {
          timedStore = store;
          timingPending = false;
        }
        view.setTargetMesh(surface);
        shownBuffer = new Float32Array(buffers.targetPositions.length);
        follower = joints ? new JointFollower(surface.positions, joints.positions) : null;
        restLengths = follower ? boneLengths(follower.at(surface.positions), joints.bones) : null;
        if (follower) view.setJoints(joints.positions, joints.bones);
        plot = follower && joints.bones.length ? new Float64Array(info.frames).fill(NaN) : null;
        crossings = new Float64Array(info.frames).fill(NaN);
        const times = buffers.times;
        clock.setRange(times[0], times[times.length - 1]);
        clock.seek(times[0]);
        timeline.setRange(times[0], times[times.length - 1]);
        timeline.setBuffered([], info.frames);
        showPlot();
        retarget.frame = -1;
        retarget.shownFrames = 0;
        updateTimelineVisibility();
        showWarnings(info.warnings || []);
        runText(`Prepared in ${(run.prepareMs / 1000).toFixed(2)} s (${info.frames} frames of ${info.clip || 'the clip'})`, 0);
        refresh();
        return;
      }
      if (type === 'frames') {
        store.add(detail.first, detail.count, detail.positions);
        run.received = store.received;
        run.contiguous = store.contiguous();
        for (let k = detail.first; k < detail.first + detail.count; ++k) {
          // The core's bone-length error of the map's joints f_t(J_t) (harmonic); for LBS, the
          // joints followed on the surface.
          const core = detail.boneLengthError?.[k - detail.first];
          if (plot) plot[k] = Number.isFinite(core) ? core : boneLengthChange(follower.at(store.frames[k]), joints.bones, restLengths).mean;
          crossings[k] = detail.selfIntersections?.[k - detail.first] ?? NaN;
        }
        showPlot();
        timeline.setBuffered(store.ranges(), store.count);
        if (!userPaused && !retarget.playing) setPlaying(true);
        applyTime();
        refresh();
        return;
      }
      if (type === 'done') {
        run.status = 'done';
        loadGraph(detail.session);
        run.framesMs = Math.round(performance.now() - run.preparedAt);
        runText(`${store.count} frames: prepared in ${(run.prepareMs / 1000).toFixed(2)} s, frames in ${(run.framesMs / 1000).toFixed(2)} s (${(run.framesMs / store.count).toFixed(1)} ms each, with transfers)`);
        refresh();
        return;
      }
      if (type === 'error') {
        const error = toMeshMorphError(detail.error);
        if (error.code === 'Aborted') {
          // Lost with a replaced worker, not failed: run again when the new one is up.
          run.status = 'aborted';
          runText('The geometry worker was replaced; the run starts again…');
          refresh();
          return;
        }
        run.status = 'error';
        run.error = { code: error.code, message: error.message };
        runText(`Failed: ${error.message}`);
        app.showError(error);
        refresh();
        return;
      }
      if (type === 'stopped') {
        run.status = 'stopped';
        refresh();
      }
    }

    for (const radio of root.querySelectorAll('input[name="rt-method"]')) {
      radio.addEventListener('change', () => {
        retarget.method = radio.value;
        startRun();
      });
    }
    $('rt-run').addEventListener('click', () => startRun());
    $('rt-stop').addEventListener('click', () => stopRun('Stop pressed'));

    // ---- step 4: playback

    function updateTimelineVisibility() {
      const on = visible && Boolean(store || view.played);
      timeline.show(on);
      viewer.renderer.domElement.parentElement.classList.toggle('with-timeline', on);
    }

    function setPlaying(on) {
      const playable = (store && store.received > 0) || view.played;
      retarget.playing = Boolean(on && playable);
      clock.playing = retarget.playing;
      timeline.setPlaying(retarget.playing);
      if (!on) userPaused = true;
      else userPaused = false;
      if (retarget.playing) startLoop();
    }

    // The clip time → source pose, target positions (interpolated), joints, timeline.
    function applyTime() {
      const t = clock.time;
      retarget.time = t;
      view.setSourceTime(t);
      if (graph && $('rt-graph').checked) graph.sets.forEach((set, i) => { if (set.source) view.moveGraph(i, set.follower.at()); });
      if (view.played) {
        view.setPlayedTime(t - clock.start);
        timeline.setTime(t);
        return;
      }
      if (!store || !shownBuffer) return;
      if (retarget.editingJoints) { // the target stays at rest while its joints are edited
        timeline.setTime(t);
        return;
      }
      const at = store.positionsAt(t, shownBuffer);
      if (!at) return;
      view.setTargetPositions(shownBuffer);
      if (follower && joints) view.moveJoints(follower.at(shownBuffer));
      if (graph) graph.sets.forEach((set, i) => { if (!set.source) view.moveGraph(i, set.follower.at(shownBuffer)); });
      retarget.frame = at.frame;
      retarget.shownFrames += 1;
      preview.paused = retarget.playing;
      if (retarget.firstFrameMs == null && clipChosenAt != null && store === timedStore) {
        retarget.firstFrameMs = Math.round(performance.now() - clipChosenAt);
        app.setStatus(`first retargeted frame shown ${(retarget.firstFrameMs / 1000).toFixed(2)} s after choosing the clip`);
      }
      timeline.setTime(t, at.frame);
      if (plot) timeline.markPlot(at.frame, store.count);
      viewer.requestRender();
    }

    let looping = false;
    let last = 0;
    function startLoop() {
      if (looping) return;
      looping = true;
      last = performance.now();
      const step = (now) => {
        if (!retarget.playing || !visible) {
          looping = false;
          return;
        }
        const dt = Math.min(0.1, (now - last) / 1000);
        last = now;
        // While frames arrive, play the computed prefix only.
        let loopEnd = clock.end;
        if (store && !store.complete) {
          const n = store.contiguous();
          loopEnd = n > 0 ? store.times[n - 1] : clock.start;
        }
        clock.tick(dt, loopEnd);
        applyTime();
        requestAnimationFrame(step);
      };
      requestAnimationFrame(step);
    }

    root.ownerDocument.addEventListener('keydown', (e) => {
      if (!visible || e.code !== 'Space' || e.target.closest?.('input, select, textarea, button')) return;
      e.preventDefault();
      setPlaying(!retarget.playing);
    });

    // ---- view

    function setView(mode) {
      retarget.view = mode;
      $('rt-link-row').hidden = mode !== 'split';
      view.setMode(mode, { linked: $('rt-link').checked });
      paneLabels.hidden = !visible || mode !== 'split';
      paneLabels.classList.toggle('split', mode === 'split');
    }
    for (const radio of root.querySelectorAll('input[name="rt-view"]')) radio.addEventListener('change', () => setView(radio.value));
    $('rt-link').addEventListener('change', () => setView(retarget.view));

    // ---- step 5: export, and an animated GLB played here

    $('rt-export').addEventListener('click', async () => {
      if (!store?.complete) return;
      const positions = store.prefixPositions();
      const exported = await app.runOp('Writing the animated GLB', 'retargetExportGlb', { session: retarget.run.session }, { positions });
      if (!exported) return;
      const name = `${stem(target.name)}-${stem(retarget.source.clipName || 'clip')}${retarget.method === 'lbs' ? '-lbs' : ''}.glb`;
      download(exported.buffers.bytes, name, 'model/gltf-binary');
      retarget.exports += 1;
      retarget.exportedRun = retarget.runs;
      $('rt-export-info').textContent = `${name}: ${(exported.buffers.bytes.length / 1e6).toFixed(2)} MB, ${store.count} morph targets.`;
      refresh();
    });

    $('rt-joints-save').addEventListener('click', () => {
      if (!joints) return;
      const file = jointsFile(joints.names.map((name, i) => ({ name, position: joints.positions[i] })));
      retarget.savedJoints = file;
      download(new TextEncoder().encode(`${JSON.stringify(file, null, 1)}\n`), `${stem(target.name)}_joints.json`, 'application/json');
    });

    $('rt-play-file').addEventListener('change', async () => {
      const file = $('rt-play-file').files[0];
      $('rt-play-file').value = '';
      if (!file) return;
      try {
        const gltf = await parseGltf(new Uint8Array(await file.arrayBuffer()));
        if (!gltf.animations.length) throw new MeshMorphError('InvalidArgument', `${file.name} has no animation to play`);
        let morphTargets = 0;
        gltf.scene.traverse((o) => { if (o.isMesh && o.morphTargetInfluences) morphTargets = Math.max(morphTargets, o.morphTargetInfluences.length); });
        view.setPlayed(gltf);
        const duration = gltf.animations[0].duration;
        retarget.played = { name: file.name, duration, morphTargets, clips: gltf.animations.length };
        // The played file's own time: from the source clip's start when a run is shown
        // (in sync with the source), else from 0.
        const start = store ? store.times[0] : 0;
        clock.setRange(start, start + duration);
        clock.seek(start);
        timeline.setRange(start, start + duration);
        $('rt-back').hidden = !store;
        $('rt-export-info').textContent = `Playing ${file.name}: ${duration.toFixed(2)} s, ${morphTargets} morph targets.`;
        updateTimelineVisibility();
        setPlaying(true);
      } catch (e) {
        app.showError(e);
      }
    });

    function clearPlayedGlb() {
      if (!view.played) return;
      view.clearPlayed();
      retarget.played = null;
      $('rt-back').hidden = true;
    }
    $('rt-back').addEventListener('click', () => {
      clearPlayedGlb();
      if (surface) {
        view.setTargetMesh(surface);
        if (joints) view.setJoints(joints.positions, joints.bones);
        clock.setRange(store.times[0], store.times[store.count - 1]);
        timeline.setRange(clock.start, clock.end);
      }
      applyTime();
    });

    // ---- wiring

    app.on('ready', async () => {
      try {
        const schema = (await client.run('optionSchema', { job: 'retarget' }).promise).info;
        const method = schema.options.find((o) => o.name === 'method');
        if (method) root.querySelector('[aria-label="Method"]').title = method.help;
        form = new OptionsForm(schema.options.filter((o) => o.name !== 'method' && o.name !== 'clip'), { title: 'Retarget options' });
        form.gui.onFinishChange(() => startRun());
        $('rt-options').append(form.element);
      } catch (e) {
        app.showError(e);
      }
      refresh();
    });
    app.on('restarted', () => {
      // The sessions lived in the old worker; a fit or a run lost with it starts again.
      if (retarget.fit.status === 'aborted') {
        retarget.fit = { ...retarget.fit, status: 'idle' };
        if (retarget.jointsFrom === 'auto') {
          runner.session = null;
          chooseJoints();
          return;
        }
      }
      // A run still preparing was made after the cancel that replaced the worker (one made before
      // it was Aborted): it waits for the new worker and needs nothing.
      if (['frames', 'done', 'aborted'].includes(retarget.run.status)) {
        runner.session = null;
        startRun();
      }
    });
    app.on('job', (job) => {
      const was = visible;
      visible = job === 'retarget';
      if (visible === was) return;
      view.setActive(visible);
      paneLabels.hidden = !visible || retarget.view !== 'split';
      updateTimelineVisibility();
      if (visible && retarget.playing) startLoop();
      if (visible) preview.start();
      else {
        preview.stop();
        viewer.frame();
      }
    });

    app.hooks.retargetFrame = (k) => (store?.has(k) ? Array.from(store.frames[k]) : null);
    app.hooks.retargetTimes = () => (store ? Array.from(store.times) : null);
    app.hooks.retargetShown = () => Array.from(view.targetPositions() ?? []);
    // Where joint j's sphere is drawn now (it follows the frames unless joints are being edited).
    app.hooks.retargetPinnedDrawn = () => view.joints.spheres.flatMap((sp, j) => (sp.material === view.pinnedMaterial ? [j] : []));
    app.hooks.retargetJointOnScreen = (j) => (view.joints.spheres[j] ? view.toScreen('target', view.joints.spheres[j].position.toArray()) : null);
    app.hooks.retargetJointAt = (x, y) => view.jointAt(x, y);
    app.hooks.retargetPointOnScreen = (p) => view.toScreen('target', p);
    app.hooks.retargetInsidePointAt = (x, y) => view.insidePointAt(x, y);
    app.hooks.retargetDropJoint = (j, position) => dropJoint(j, position);
    app.hooks.retargetCamera = () => viewer.camera.position.toArray();
    app.hooks.retargetJoints = () => (joints ? { names: [...joints.names], positions: joints.positions.map((p) => [...p]), bones: joints.bones.map((b) => [...b]) } : null);
    app.hooks.retargetSeek = (t) => { setPlaying(false); clock.seek(t); applyTime(); return retarget.frame; };
    app.hooks.retargetPlot = () => (plot ? Array.from(plot) : null);
    // The source's graph nodes as drawn (the edges set, in the glTF scene's space), or null.
    app.hooks.retargetSourceGraph = () => {
      const i = graph ? graph.sets.findIndex((x) => x.source && x.lines.length) : -1;
      return i >= 0 ? Array.from(view.graph[i].geometry.getAttribute('position').array) : null;
    };
    app.hooks.retargetIntersections = () => (crossings ? Array.from(crossings) : null);
    app.hooks.retargetPreviewFrames = () => preview.frames;
    app.hooks.retargetScrubRect = () => {
      const r = timeline.scrub.getBoundingClientRect();
      return { left: r.left, top: r.top, width: r.width, height: r.height, min: Number(timeline.scrub.min), max: Number(timeline.scrub.max) };
    };
    refresh();
    return root;
  },
};
