// Joins the native and wasm rows of meshmorph_bench --json into one Markdown table.
import { readFileSync } from 'node:fs';

const [nativePath, wasmPath] = process.argv.slice(2);
const native = JSON.parse(readFileSync(nativePath, 'utf8'));
const wasm = JSON.parse(readFileSync(wasmPath, 'utf8'));
const key = (r) => `${r.suite}|${r.mesh}|${r.stage}`;
const wasmByKey = new Map(wasm.map((r) => [key(r), r]));
const fmt = (ms) => (ms >= 1000 ? `${(ms / 1000).toFixed(2)} s` : `${ms.toFixed(ms < 10 ? 2 : 1)} ms`);

console.log('| suite | mesh | #V | stage | native | wasm | wasm/native | peer (PEERS.md / paper) | note |');
console.log('|---|---|---|---|---|---|---|---|---|');
for (const r of native) {
  const w = wasmByKey.get(key(r));
  const ratio = w && r.ms > 0 ? (w.ms / r.ms).toFixed(2) : '—';
  console.log(`| ${r.suite} | ${r.mesh} | ${r.vertices} | ${r.stage} | ${fmt(r.ms)} | ${w ? fmt(w.ms) : '—'} | ${ratio} | ${r.peer} | ${r.note} |`);
}
