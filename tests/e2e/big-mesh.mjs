// A huge mesh for the out-of-memory checks (issue 13): a bundled binary PLY subdivided in JS
// (every triangle into n² triangles, edge points shared, so the result stays a closed manifold
// surface) and written as a binary little-endian PLY. Armadillo with n = 9: 1 181 387 vertices,
// 2 362 770 faces, 45 MB.
import fs from 'node:fs';

// Vertices and triangles of a binary little-endian PLY whose elements are "vertex" (float
// x y z first) and "face" (list uchar int). Enough for the repository's data/edit/*.ply.
export function readBinaryPly(bytes) {
  const headerEnd = bytes.indexOf('end_header') + 'end_header\n'.length;
  const header = Buffer.from(bytes.subarray(0, headerEnd)).toString('latin1');
  if (!/format binary_little_endian/.test(header)) throw new Error('readBinaryPly: not binary little endian');
  const vertexCount = Number(/element vertex (\d+)/.exec(header)[1]);
  const faceCount = Number(/element face (\d+)/.exec(header)[1]);
  const vertexProps = header.slice(header.indexOf('element vertex'), header.indexOf('element face')).match(/property float \w+/g).length;
  if (!/property list uchar int/.test(header) || /property (?!float|list)/.test(header)) throw new Error('readBinaryPly: unexpected property types');
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const positions = new Float32Array(vertexCount * 3);
  let o = headerEnd;
  for (let v = 0; v < vertexCount; ++v, o += 4 * vertexProps) {
    for (let k = 0; k < 3; ++k) positions[3 * v + k] = view.getFloat32(o + 4 * k, true);
  }
  const triangles = new Uint32Array(faceCount * 3);
  for (let f = 0; f < faceCount; ++f) {
    if (view.getUint8(o) !== 3) throw new Error(`readBinaryPly: face ${f} is not a triangle`);
    for (let k = 0; k < 3; ++k) triangles[3 * f + k] = view.getInt32(o + 1 + 4 * k, true);
    o += 13;
  }
  return { positions, triangles };
}

// Every triangle into n² triangles (points a + i/n (b - a) + j/n (c - a)).
export function subdivide({ positions, triangles }, n) {
  const vertexCount = positions.length / 3;
  const edges = new Map(); // min * V + max → index of its first interior point (from min to max)
  const out = [];
  for (let i = 0; i < positions.length; ++i) out.push(positions[i]);
  let next = vertexCount;
  const push = (a, b, c, i, j) => {
    for (let k = 0; k < 3; ++k) out.push(positions[3 * a + k] + (i / n) * (positions[3 * b + k] - positions[3 * a + k]) + (j / n) * (positions[3 * c + k] - positions[3 * a + k]));
    return next++;
  };
  // The k-th interior point (1..n-1) of edge p → q, counted from p.
  const edgePoint = (p, q, k) => {
    const lo = Math.min(p, q);
    const hi = Math.max(p, q);
    const key = lo * vertexCount + hi;
    let first = edges.get(key);
    if (first === undefined) {
      first = next;
      for (let s = 1; s < n; ++s) push(lo, hi, hi, s, 0);
      edges.set(key, first);
    }
    return first + (p === lo ? k - 1 : n - k - 1);
  };
  const faces = new Uint32Array((triangles.length / 3) * n * n * 3);
  let f = 0;
  const id = new Int32Array((n + 1) * (n + 1));
  for (let t = 0; t < triangles.length; t += 3) {
    const [a, b, c] = [triangles[t], triangles[t + 1], triangles[t + 2]];
    for (let i = 0; i <= n; ++i) {
      for (let j = 0; i + j <= n; ++j) {
        let v;
        if (i === 0 && j === 0) v = a;
        else if (i === n) v = b;
        else if (j === n) v = c;
        else if (j === 0) v = edgePoint(a, b, i);
        else if (i === 0) v = edgePoint(a, c, j);
        else if (i + j === n) v = edgePoint(b, c, j);
        else v = push(a, b, c, i, j);
        id[i * (n + 1) + j] = v;
      }
    }
    const P = (i, j) => id[i * (n + 1) + j];
    for (let i = 0; i < n; ++i) {
      for (let j = 0; i + j < n; ++j) {
        faces[f++] = P(i, j); faces[f++] = P(i + 1, j); faces[f++] = P(i, j + 1);
        if (i + j < n - 1) { faces[f++] = P(i + 1, j); faces[f++] = P(i + 1, j + 1); faces[f++] = P(i, j + 1); }
      }
    }
  }
  return { positions: Float32Array.from(out), triangles: faces };
}

export function binaryPly({ positions, triangles }) {
  const v = positions.length / 3;
  const t = triangles.length / 3;
  const header = Buffer.from(`ply\nformat binary_little_endian 1.0\ncomment subdivided by tests/e2e/big-mesh.mjs\nelement vertex ${v}\n`
    + `property float x\nproperty float y\nproperty float z\nelement face ${t}\nproperty list uchar int vertex_indices\nend_header\n`, 'latin1');
  const body = Buffer.alloc(v * 12 + t * 13);
  for (let i = 0; i < positions.length; ++i) body.writeFloatLE(positions[i], 4 * i);
  let o = v * 12;
  for (let f = 0; f < t; ++f, o += 13) {
    body.writeUInt8(3, o);
    for (let k = 0; k < 3; ++k) body.writeInt32LE(triangles[3 * f + k], o + 1 + 4 * k);
  }
  return Buffer.concat([header, body]);
}

// Writes (once; reused while it is newer than the input) the subdivided mesh to `file`.
export function writeBigMesh(input, file, n = 9) {
  if (fs.existsSync(file) && fs.statSync(file).mtimeMs > fs.statSync(input).mtimeMs) return file;
  fs.writeFileSync(file, binaryPly(subdivide(readBinaryPly(fs.readFileSync(input)), n)));
  return file;
}
