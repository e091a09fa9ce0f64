// Joins the native and wasm rows of meshmorph_bench --json into one Markdown table. With a third
// file (the native run with --threads N, scripts/bench --threads N), the native column is the
// one-thread run and a column for N threads follows.
import { readFileSync } from 'node:fs';

const [nativePath, wasmPath, threadedPath] = process.argv.slice(2);
const native = JSON.parse(readFileSync(nativePath, 'utf8'));
const wasm = JSON.parse(readFileSync(wasmPath, 'utf8'));
const threaded = threadedPath ? JSON.parse(readFileSync(threadedPath, 'utf8')) : null;
const key = (r) => `${r.suite}|${r.mesh}|${r.stage}`;
const wasmByKey = new Map(wasm.map((r) => [key(r), r]));
const threadedByKey = new Map((threaded || []).map((r) => [key(r), r]));
const n = threaded?.[0]?.threads ?? 0;
const fmt = (ms) => (ms >= 1000 ? `${(ms / 1000).toFixed(2)} s` : `${ms.toFixed(ms < 10 ? 2 : 1)} ms`);
// The peer's time in ms from its figure ("igl 8 ms", "Spectra+LDLT 1.56 s", "paper 001: 0.062 +
// 0.328 + 0.032 s" → the sum), or null when the figure has no time.
export function peerMs(text) {
  const m = /((?:\d+(?:\.\d+)?\s*\+\s*)*\d+(?:\.\d+)?)\s*(ms|s)\b/.exec(text || '');
  if (!m) return null;
  const total = m[1].split('+').reduce((a, x) => a + Number(x), 0);
  return m[2] === 's' ? total * 1000 : total;
}

const nativeHead = threaded ? `native (1 thread) | native (${n} threads)` : 'native';
console.log(`| suite | mesh | #V | stage | ${nativeHead} | wasm | wasm/native | peer (PEERS.md / paper) | native/peer | note |`);
console.log(`|---|---|---|---|---|${threaded ? '---|' : ''}---|---|---|---|---|`);
for (const r of native) {
  const w = wasmByKey.get(key(r));
  const t = threadedByKey.get(key(r));
  const ratio = w && r.ms > 0 ? (w.ms / r.ms).toFixed(2) : '—';
  const p = peerMs(r.peer);
  const best = t && t.ms < r.ms ? t.ms : r.ms;  // native/peer: the faster native run
  const vsPeer = p && best > 0 ? (best / p).toFixed(2) : '';
  const threadedCell = threaded ? ` ${t ? fmt(t.ms) : '—'} |` : '';
  console.log(`| ${r.suite} | ${r.mesh} | ${r.vertices} | ${r.stage} | ${fmt(r.ms)} |${threadedCell} ${w ? fmt(w.ms) : '—'} | ${ratio} | ${r.peer} | ${vsPeer} | ${r.note} |`);
}
