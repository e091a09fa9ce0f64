// Joins the rows of meshmorph_bench --json runs into one Markdown table:
//   node scripts/bench-table.mjs NATIVE.json WASM.json [--native-threads F.json] [--wasm-threads F.json]
// Each file may be a comma-separated list of repeated runs (scripts/bench --repeat N, native and
// wasm alternating): each row then shows its fastest run, which keeps a machine's drift between
// the native and the wasm runs out of the ratios.
// NATIVE and WASM are one-thread runs (the single-threaded wasm build); the optional files are the
// native run with --threads N and the threaded wasm build's run with --threads N (scripts/bench
// --threads N). wasm/native compares one thread with one thread; wasm N/native 1 is the figure the
// browser gets against the single-threaded native build.
import { readFileSync } from 'node:fs';

// The peer's time in ms from its figure ("igl 8 ms", "Spectra+LDLT 1.56 s", "paper 001: 0.062 +
// 0.328 + 0.032 s" → the sum), or null when the figure has no time.
export function peerMs(text) {
  const m = /((?:\d+(?:\.\d+)?\s*\+\s*)*\d+(?:\.\d+)?)\s*(ms|s)\b/.exec(text || '');
  if (!m) return null;
  const total = m[1].split('+').reduce((a, x) => a + Number(x), 0);
  return m[2] === 's' ? total * 1000 : total;
}

// Rows of one or more runs ("a.json,b.json"): per row (suite, mesh, stage) the fastest run's.
export function fastestRows(runs) {
  const key = (r) => `${r.suite}|${r.mesh}|${r.stage}`;
  const best = new Map();
  const order = [];
  for (const rows of runs)
    for (const r of rows) {
      const k = key(r);
      const b = best.get(k);
      if (!b) order.push(k);
      if (!b || r.ms < b.ms) best.set(k, r);
    }
  return order.map((k) => best.get(k));
}

function main(argv) {
  const positional = [];
  const named = {};
  for (let i = 0; i < argv.length; ++i) {
    if (argv[i].startsWith('--')) named[argv[i].slice(2)] = argv[++i];
    else positional.push(argv[i]);
  }
  const read = (f) => (f ? fastestRows(f.split(',').map((one) => JSON.parse(readFileSync(one, 'utf8')))) : null);
  const [native, wasm] = positional.map(read);
  const nativeN = read(named['native-threads']);
  const wasmN = read(named['wasm-threads']);
  const key = (r) => `${r.suite}|${r.mesh}|${r.stage}`;
  const index = (rows) => new Map((rows || []).map((r) => [key(r), r]));
  const [wasmBy, nativeNBy, wasmNBy] = [index(wasm), index(nativeN), index(wasmN)];
  const n = nativeN?.[0]?.threads ?? wasmN?.[0]?.threads ?? 0;
  const fmt = (ms) => (ms >= 1000 ? `${(ms / 1000).toFixed(2)} s` : `${ms.toFixed(ms < 10 ? 2 : 1)} ms`);
  const cell = (r) => (r ? fmt(r.ms) : '—');
  const ratio = (a, b) => (a && b && b.ms > 0 ? (a.ms / b.ms).toFixed(2) : '—');

  const head = ['suite', 'mesh', '#V', 'stage', 'native (1 thread)'];
  if (nativeN) head.push(`native (${n} threads)`);
  head.push('wasm (1 thread)');
  if (wasmN) head.push(`wasm (${n} threads)`);
  head.push('wasm/native');
  if (wasmN) head.push(`wasm ${n}/native 1`);
  head.push('peer (PEERS.md / paper)', 'native/peer', 'note');
  console.log(`| ${head.join(' | ')} |`);
  console.log(`|${head.map(() => '---').join('|')}|`);
  for (const r of native) {
    const w = wasmBy.get(key(r));
    const t = nativeNBy.get(key(r));
    const wt = wasmNBy.get(key(r));
    const p = peerMs(r.peer);
    const best = t && t.ms < r.ms ? t.ms : r.ms;  // native/peer: the faster native run
    const row = [r.suite, r.mesh, r.vertices, r.stage, fmt(r.ms)];
    if (nativeN) row.push(cell(t));
    row.push(cell(w));
    if (wasmN) row.push(cell(wt));
    row.push(ratio(w, r));
    if (wasmN) row.push(ratio(wt, r));
    row.push(r.peer, p && best > 0 ? (best / p).toFixed(2) : '', r.note);
    console.log(`| ${row.join(' | ')} |`);
  }
}

if (import.meta.url === `file://${process.argv[1]}`) main(process.argv.slice(2));
