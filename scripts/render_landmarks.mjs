#!/usr/bin/env node
// Renders two meshes side by side with numbered landmark dots, to check a landmark file
// (data/landmarks/*.json: {"reference","source","pairs":[[ref_vertex, src_vertex],...]}) by eye.
// Pure Node (software z-buffer, PNG via zlib): no browser, no GPU, no npm packages.
//
//   node scripts/render_landmarks.mjs --ref R.off --src S.ply [--landmarks L.json] \
//       [--ref-frame x,z,-y] [--src-frame x,y,z] [--views front,side,otherside,back,top] [--size 700] \
//       [--highlight 3,7] [--zoom 7 --radius 0.15] --out /tmp/lm.png
//
// Output: one PNG per view (<out>-front.png, ...) with the reference on the left and the source on
// the right, each scaled to its bounding box. Pair i is drawn on both meshes with the same colour
// and the number i; a filled dot is visible, a hollow ring is hidden behind the surface.
// --ref-frame / --src-frame map mesh axes to the view frame (Y up, viewer on +Z looking at -Z):
// "x,z,-y" means view = (mesh.x, mesh.z, -mesh.y), i.e. a Z-up mesh facing -y seen from the front.
// Views: front (from +Z), side (from +X: the character's left), otherside (from -X), back, top
// (from +Y, front at the bottom). Either mesh alone: omit --src (or --ref). PLY (binary, float32), OFF and OBJ are read.
// --highlight draws only the listed pairs; --zoom i keeps only the faces within --radius (fraction
// of the bounding-box diagonal, default 0.15) of pair i's vertex, to inspect a head or a hand.
// Also useful for transfer results: --ref reference --src result.ply (both in the reference frame).
// Example (data/landmarks/michael3-armadillo.json was checked this way):
//   node scripts/render_landmarks.mjs --ref ../shared/data/pose/tosca/michael3.off --ref-frame x,z,-y \
//       --src data/edit/armadillo.ply --landmarks data/landmarks/michael3-armadillo.json \
//       --views front,side,otherside,back --out /tmp/michael-armadillo.png
import fs from 'fs';
import zlib from 'zlib';

function loadMesh(path) {
  const buf = fs.readFileSync(path);
  if (path.endsWith('.ply')) {
    const end = buf.indexOf('end_header\n') + 11;
    const hdr = buf.slice(0, end).toString();
    if (!hdr.includes('binary_little_endian')) throw new Error('only binary little-endian PLY');
    const nv = +hdr.match(/element vertex (\d+)/)[1], nf = +hdr.match(/element face (\d+)/)[1];
    const vpart = hdr.split('element vertex')[1].split('element face')[0];
    const vprops = [...vpart.matchAll(/property (\w+) (\w+)/g)].map(m => m[1]);
    const sz = { float: 4, float32: 4, double: 8, float64: 8, uchar: 1, uint8: 1, int: 4, int32: 4, uint: 4, uint32: 4 };
    const stride = vprops.reduce((a, t) => a + sz[t], 0);
    const fl = hdr.match(/property list (\w+) (\w+) vertex_ind/);
    const cs = sz[fl[1]], is = sz[fl[2]];
    let o = end; const V = new Float64Array(nv * 3), F = [];
    const dbl = vprops[0] === 'double' || vprops[0] === 'float64';
    for (let i = 0; i < nv; i++, o += stride)
      for (let k = 0; k < 3; k++) V[3 * i + k] = dbl ? buf.readDoubleLE(o + 8 * k) : buf.readFloatLE(o + 4 * k);
    for (let f = 0; f < nf; f++) {
      const n = cs === 1 ? buf.readUInt8(o) : buf.readInt32LE(o); o += cs; const idx = [];
      for (let k = 0; k < n; k++, o += is) idx.push(is === 4 ? buf.readInt32LE(o) : is === 2 ? buf.readUInt16LE(o) : buf.readUInt8(o));
      for (let k = 1; k + 1 < n; k++) F.push(idx[0], idx[k], idx[k + 1]);
    }
    return { V, F };
  }
  const txt = buf.toString();
  if (path.endsWith('.obj')) {
    const V = [], F = [];
    for (const line of txt.split('\n')) {
      if (line.startsWith('v ')) { const p = line.trim().split(/\s+/); V.push(+p[1], +p[2], +p[3]); }
      else if (line.startsWith('f ')) {
        const p = line.trim().split(/\s+/).slice(1).map(s => parseInt(s.split('/')[0]) - 1);
        for (let k = 1; k + 1 < p.length; k++) F.push(p[0], p[k], p[k + 1]);
      }
    }
    return { V: Float64Array.from(V), F };
  }
  const tok = txt.replace(/#.*$/mg, '').split(/\s+/).filter(s => s.length);
  let t = tok[0].startsWith('OFF') ? 1 : 0;
  const nv = +tok[t++], nf = +tok[t++]; t++;
  const V = new Float64Array(nv * 3); for (let i = 0; i < 3 * nv; i++) V[i] = +tok[t++];
  const F = [];
  for (let f = 0; f < nf; f++) {
    const n = +tok[t++]; const idx = []; for (let k = 0; k < n; k++) idx.push(+tok[t++]);
    for (let k = 1; k + 1 < n; k++) F.push(idx[0], idx[k], idx[k + 1]);
  }
  return { V, F };
}

function applyFrame(V, frame) {
  const spec = frame.split(',').map(s => ({ sign: s.trim().startsWith('-') ? -1 : 1, axis: 'xyz'.indexOf(s.trim().replace('-', '')) }));
  const W = new Float64Array(V.length);
  for (let i = 0; i < V.length; i += 3) for (let k = 0; k < 3; k++) W[i + k] = spec[k].sign * V[i + spec[k].axis];
  return W;
}

// 5x7 digit glyphs (rows top to bottom, 5 bits each).
const GLYPH = {
  0: [14, 17, 19, 21, 25, 17, 14], 1: [4, 12, 4, 4, 4, 4, 14], 2: [14, 17, 1, 2, 4, 8, 31], 3: [31, 2, 4, 2, 1, 17, 14],
  4: [2, 6, 10, 18, 31, 2, 2], 5: [31, 16, 30, 1, 1, 17, 14], 6: [6, 8, 16, 30, 17, 17, 14], 7: [31, 1, 2, 4, 8, 8, 8],
  8: [14, 17, 17, 14, 17, 17, 14], 9: [14, 17, 17, 15, 1, 2, 12],
};
const PALETTE = [[230, 25, 75], [60, 180, 75], [0, 130, 200], [245, 130, 48], [145, 30, 180], [70, 240, 240], [240, 50, 230],
  [210, 245, 60], [250, 190, 212], [0, 128, 128], [170, 110, 40], [128, 0, 0], [0, 0, 128], [128, 128, 0], [255, 225, 25]];

class Image {
  constructor(w, h) { this.w = w; this.h = h; this.px = new Uint8Array(w * h * 3).fill(255); this.z = new Float64Array(w * h).fill(-Infinity); }
  set(x, y, c) { x |= 0; y |= 0; if (x < 0 || y < 0 || x >= this.w || y >= this.h) return; const o = 3 * (y * this.w + x); this.px[o] = c[0]; this.px[o + 1] = c[1]; this.px[o + 2] = c[2]; }
  text(x, y, s, c, scale = 2) {
    let cx = x;
    for (const ch of String(s)) {
      const g = GLYPH[ch]; if (!g) { cx += 6 * scale; continue; }
      for (let r = 0; r < 7; r++) for (let b = 0; b < 5; b++) if (g[r] >> (4 - b) & 1)
        for (let dy = -1; dy <= scale; dy++) for (let dx = -1; dx <= scale; dx++) {
          const inner = dy >= 0 && dx >= 0 && dy < scale && dx < scale;
          if (!inner) { const px = cx + b * scale + dx, py = y + r * scale + dy; const o = 3 * ((py | 0) * this.w + (px | 0));
            if (px >= 0 && py >= 0 && px < this.w && py < this.h && !(this.px[o] === c[0] && this.px[o + 1] === c[1] && this.px[o + 2] === c[2])) this.set(px, py, [255, 255, 255]); }
        }
      for (let r = 0; r < 7; r++) for (let b = 0; b < 5; b++) if (g[r] >> (4 - b) & 1)
        for (let dy = 0; dy < scale; dy++) for (let dx = 0; dx < scale; dx++) this.set(cx + b * scale + dx, y + r * scale + dy, c);
      cx += 6 * scale;
    }
  }
  disc(x, y, r, c, filled) {
    for (let dy = -r - 1; dy <= r + 1; dy++) for (let dx = -r - 1; dx <= r + 1; dx++) {
      const d = Math.hypot(dx, dy);
      if (filled ? d <= r : Math.abs(d - r) < 1.2) this.set(x + dx, y + dy, c);
      else if (filled && d <= r + 1.2) this.set(x + dx, y + dy, [0, 0, 0]);
    }
  }
  png() {
    const crcT = new Int32Array(256).map((_, n) => { let c = n; for (let k = 0; k < 8; k++) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1; return c; });
    const crc = b => { let c = -1; for (const x of b) c = crcT[(c ^ x) & 255] ^ (c >>> 8); return (c ^ -1) >>> 0; };
    const chunk = (type, data) => { const l = Buffer.alloc(4); l.writeUInt32BE(data.length); const td = Buffer.concat([Buffer.from(type), data]);
      const cb = Buffer.alloc(4); cb.writeUInt32BE(crc(td)); return Buffer.concat([l, td, cb]); };
    const raw = Buffer.alloc((this.w * 3 + 1) * this.h);
    for (let y = 0; y < this.h; y++) { raw[y * (this.w * 3 + 1)] = 0; Buffer.from(this.px.buffer, y * this.w * 3, this.w * 3).copy(raw, y * (this.w * 3 + 1) + 1); }
    const ihdr = Buffer.alloc(13); ihdr.writeUInt32BE(this.w, 0); ihdr.writeUInt32BE(this.h, 4); ihdr[8] = 8; ihdr[9] = 2;
    return Buffer.concat([Buffer.from([137, 80, 78, 71, 13, 10, 26, 10]), chunk('IHDR', ihdr), chunk('IDAT', zlib.deflateSync(raw)), chunk('IEND', Buffer.alloc(0))]);
  }
}

// view rotation: front = identity; side = viewer on +X (mesh's left side turned to camera); back; top.
const VIEWS = {
  front: p => [p[0], p[1], p[2]], side: p => [-p[2], p[1], p[0]], back: p => [-p[0], p[1], -p[2]],
  top: p => [p[0], -p[2], p[1]], otherside: p => [p[2], p[1], -p[0]],
};

function drawMesh(img, mesh, view, x0, w, h, marks, tint) {
  const { V, F } = mesh; const n = V.length / 3; const P = new Float64Array(V.length);
  for (let i = 0; i < n; i++) { const q = VIEWS[view]([V[3 * i], V[3 * i + 1], V[3 * i + 2]]); P[3 * i] = q[0]; P[3 * i + 1] = q[1]; P[3 * i + 2] = q[2]; }
  const used = new Uint8Array(n); for (const v of F) used[v] = 1;
  const mn = [Infinity, Infinity, Infinity], mx = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; i++) if (used[i]) for (let k = 0; k < 3; k++) { mn[k] = Math.min(mn[k], P[3 * i + k]); mx[k] = Math.max(mx[k], P[3 * i + k]); }
  const s = 0.9 * Math.min(w / (mx[0] - mn[0]), h / (mx[1] - mn[1]));
  const cx = (mn[0] + mx[0]) / 2, cy = (mn[1] + mx[1]) / 2;
  const S = new Float64Array(V.length);
  for (let i = 0; i < n; i++) { S[3 * i] = x0 + w / 2 + s * (P[3 * i] - cx); S[3 * i + 1] = h / 2 - s * (P[3 * i + 1] - cy); S[3 * i + 2] = s * P[3 * i + 2]; }
  const L = [0.35, 0.45, 0.82]; const ln = Math.hypot(...L); L[0] /= ln; L[1] /= ln; L[2] /= ln;
  for (let f = 0; f < F.length; f += 3) {
    const a = F[f], b = F[f + 1], c = F[f + 2];
    const ax = S[3 * a], ay = S[3 * a + 1], az = S[3 * a + 2], bx = S[3 * b], by = S[3 * b + 1], bz = S[3 * b + 2], qx = S[3 * c], qy = S[3 * c + 1], qz = S[3 * c + 2];
    // normal in view space (y flipped on screen)
    const ux = P[3 * b] - P[3 * a], uy = P[3 * b + 1] - P[3 * a + 1], uz = P[3 * b + 2] - P[3 * a + 2];
    const vx = P[3 * c] - P[3 * a], vy = P[3 * c + 1] - P[3 * a + 1], vz = P[3 * c + 2] - P[3 * a + 2];
    let nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx; const nl = Math.hypot(nx, ny, nz) || 1;
    nx /= nl; ny /= nl; nz /= nl; if (nz < 0) { nx = -nx; ny = -ny; nz = -nz; }  // two-sided
    const shade = 0.25 + 0.75 * Math.max(0, nx * L[0] + ny * L[1] + nz * L[2]);
    const col = tint.map(t => Math.min(255, t * shade) | 0);
    const minx = Math.max(x0, Math.floor(Math.min(ax, bx, qx))), maxx = Math.min(x0 + w - 1, Math.ceil(Math.max(ax, bx, qx)));
    const miny = Math.max(0, Math.floor(Math.min(ay, by, qy))), maxy = Math.min(h - 1, Math.ceil(Math.max(ay, by, qy)));
    const area = (bx - ax) * (qy - ay) - (by - ay) * (qx - ax); if (Math.abs(area) < 1e-12) continue;
    for (let y = miny; y <= maxy; y++) for (let x = minx; x <= maxx; x++) {
      const px = x + 0.5, py = y + 0.5;
      const w0 = ((bx - px) * (qy - py) - (by - py) * (qx - px)) / area, w1 = ((qx - px) * (ay - py) - (qy - py) * (ax - px)) / area, w2 = 1 - w0 - w1;
      if (w0 < 0 || w1 < 0 || w2 < 0) continue;
      const z = w0 * az + w1 * bz + w2 * qz; const o = y * img.w + x;
      if (z > img.z[o]) { img.z[o] = z; img.set(x, y, col); }
    }
  }
  const tol = 0.012 * s * Math.max(mx[0] - mn[0], mx[1] - mn[1]);
  const pts = [];
  for (const [label, v, color] of marks) {
    if (!used[v]) continue;
    const x = S[3 * v], y = S[3 * v + 1], z = S[3 * v + 2];
    let zmax = -Infinity; for (let dy = -1; dy <= 1; dy++) for (let dx = -1; dx <= 1; dx++) { const xx = (x | 0) + dx, yy = (y | 0) + dy; if (xx >= 0 && yy >= 0 && xx < img.w && yy < img.h) zmax = Math.max(zmax, img.z[yy * img.w + xx]); }
    pts.push([label, x, y, color, z >= zmax - tol]);
  }
  pts.sort((p, q) => p[4] - q[4]);  // visible ones on top
  for (const [label, x, y, color, vis] of pts) { img.disc(x | 0, y | 0, 5, color, vis); img.text((x | 0) + 7, (y | 0) - 7, label, color, 2); }
}

const args = {}; for (let i = 2; i < process.argv.length; i += 2) args[process.argv[i].replace(/^--/, '')] = process.argv[i + 1];
const size = +(args.size || 700);
const lm = args.landmarks ? JSON.parse(fs.readFileSync(args.landmarks, 'utf8')) : { pairs: [] };
const only = args.highlight ? new Set(args.highlight.split(',').map(Number)) : null;
const meshes = [];
if (args.ref) meshes.push({ mesh: loadMesh(args.ref), frame: args['ref-frame'] || 'x,y,z', col: 0, tint: [200, 200, 205] });
if (args.src) meshes.push({ mesh: loadMesh(args.src), frame: args['src-frame'] || 'x,y,z', col: 1, tint: [215, 205, 185] });
for (const m of meshes) m.mesh.V = applyFrame(m.mesh.V, m.frame);
if (args.zoom !== undefined) {  // keep the faces near landmark pair `zoom`
  for (const m of meshes) {
    const { V, F } = m.mesh; const c = lm.pairs[+args.zoom][m.col];
    const mn = [Infinity, Infinity, Infinity], mx = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < V.length; i += 3) for (let k = 0; k < 3; k++) { mn[k] = Math.min(mn[k], V[i + k]); mx[k] = Math.max(mx[k], V[i + k]); }
    const r = +(args.radius || 0.15) * Math.hypot(mx[0] - mn[0], mx[1] - mn[1], mx[2] - mn[2]);
    const near = v => Math.hypot(V[3 * v] - V[3 * c], V[3 * v + 1] - V[3 * c + 1], V[3 * v + 2] - V[3 * c + 2]) < r;
    const G = []; for (let f = 0; f < F.length; f += 3) if (near(F[f]) && near(F[f + 1]) && near(F[f + 2])) G.push(F[f], F[f + 1], F[f + 2]);
    m.mesh.F = G;
  }
}
const views = (args.views || 'front,side').split(',');
const out = args.out || '/tmp/landmarks.png';
for (const view of views) {
  const img = new Image(size * meshes.length, size);
  meshes.forEach((m, j) => {
    const marks = lm.pairs.map((p, i) => [i, p[m.col], PALETTE[i % PALETTE.length]]).filter(([i]) => !only || only.has(i));
    drawMesh(img, m.mesh, view, j * size, size, size, marks, m.tint);
  });
  const file = views.length > 1 || !out.endsWith('.png') ? out.replace(/\.png$/, '') + `-${view}.png` : out;
  fs.writeFileSync(file, img.png()); console.log(file);
}
