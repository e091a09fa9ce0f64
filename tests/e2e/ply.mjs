// Vertex positions of a PLY file (ascii or binary little/big endian), for the end-to-end tests
// that compare the page's edit with the CLI's output. Reads the first element named "vertex"
// (x, y, z; any scalar property types); faces and other elements are not needed here.
const sizes = { char: 1, uchar: 1, int8: 1, uint8: 1, short: 2, ushort: 2, int16: 2, uint16: 2, int: 4, uint: 4, int32: 4, uint32: 4, float: 4, float32: 4, double: 8, float64: 8 };

function reader(view, type, little) {
  switch (type) {
    case 'char': case 'int8': return (o) => view.getInt8(o);
    case 'uchar': case 'uint8': return (o) => view.getUint8(o);
    case 'short': case 'int16': return (o) => view.getInt16(o, little);
    case 'ushort': case 'uint16': return (o) => view.getUint16(o, little);
    case 'int': case 'int32': return (o) => view.getInt32(o, little);
    case 'uint': case 'uint32': return (o) => view.getUint32(o, little);
    case 'float': case 'float32': return (o) => view.getFloat32(o, little);
    case 'double': case 'float64': return (o) => view.getFloat64(o, little);
    default: throw new Error(`PLY: unknown property type ${type}`);
  }
}

// bytes: Buffer/Uint8Array → Float64Array #V·3
export function readPlyVertices(bytes) {
  const headerEnd = bytes.indexOf('end_header');
  if (headerEnd < 0) throw new Error('PLY: no end_header');
  const header = Buffer.from(bytes.subarray(0, headerEnd)).toString('latin1').split(/\r?\n/);
  let bodyStart = headerEnd + 'end_header'.length;
  if (bytes[bodyStart] === 13) bodyStart += 1;
  bodyStart += 1; // the newline
  const format = header.find((l) => l.startsWith('format')).split(/\s+/)[1];
  const elements = [];
  for (const line of header) {
    const w = line.trim().split(/\s+/);
    if (w[0] === 'element') elements.push({ name: w[1], count: Number(w[2]), props: [] });
    else if (w[0] === 'property') elements.at(-1).props.push(w[1] === 'list' ? { list: true } : { type: w[1], name: w[2] });
  }
  if (elements[0]?.name !== 'vertex') throw new Error('PLY: the first element is not "vertex"');
  const { count, props } = elements[0];
  if (props.some((p) => p.list)) throw new Error('PLY: list properties on vertices are not supported');
  const axis = ['x', 'y', 'z'].map((n) => props.findIndex((p) => p.name === n));
  const out = new Float64Array(count * 3);
  if (format === 'ascii') {
    const lines = Buffer.from(bytes.subarray(bodyStart)).toString('latin1').split(/\r?\n/);
    for (let v = 0; v < count; ++v) {
      const w = lines[v].trim().split(/\s+/).map(Number);
      for (let k = 0; k < 3; ++k) out[3 * v + k] = w[axis[k]];
    }
    return out;
  }
  const little = format === 'binary_little_endian';
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const offsets = [];
  let stride = 0;
  for (const p of props) {
    offsets.push(stride);
    stride += sizes[p.type];
  }
  const read = axis.map((i) => reader(view, props[i].type, little));
  for (let v = 0; v < count; ++v) {
    const base = bodyStart + v * stride;
    for (let k = 0; k < 3; ++k) out[3 * v + k] = read[k](base + offsets[axis[k]]);
  }
  return out;
}
