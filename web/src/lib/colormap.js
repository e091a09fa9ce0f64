// Colours for scalar fields on the mesh (eigenfunctions): a diverging blue–white–red ramp,
// symmetric around zero so that the sign pattern (nodal lines) of a basis function is what
// the eye sees, independent of its scale. Same map as core/common/colormap.cpp
// (diverging_colors, used by `meshmorph eigs --out`), so the page and the CLI's coloured
// GLBs agree; it runs here because re-colouring on every slider move must not round-trip
// through the worker.
import { unweldValues } from './arrays.js';

// (t in -1..1, r, g, b): Moreland's cool–warm endpoints, white in the middle, linear between.
const stops = [
  [-1.0, 0.23, 0.30, 0.75],
  [0.0, 0.97, 0.97, 0.97],
  [1.0, 0.71, 0.02, 0.15],
];

export function divergingColor(t, out = [0, 0, 0], offset = 0) {
  const x = Math.max(-1, Math.min(1, Number.isFinite(t) ? t : 0));
  let i = 0;
  while (i < stops.length - 2 && x > stops[i + 1][0]) ++i;
  const [t0, r0, g0, b0] = stops[i];
  const [t1, r1, g1, b1] = stops[i + 1];
  const s = (x - t0) / (t1 - t0);
  out[offset] = r0 + s * (r1 - r0);
  out[offset + 1] = g0 + s * (g1 - g0);
  out[offset + 2] = b0 + s * (b1 - b0);
  return out;
}

// three.js treats vertex colours as linear and converts the frame to sRGB on output, so
// colours defined in sRGB (as the map above is) must be linearised first or they come out
// washed-out. A 1025-entry table keeps the per-vertex cost to one lookup.
const lutSize = 1024;
const lut = (() => {
  const table = new Float32Array((lutSize + 1) * 3);
  const rgb = [0, 0, 0];
  for (let j = 0; j <= lutSize; ++j) {
    divergingColor((2 * j) / lutSize - 1, rgb);
    for (let c = 0; c < 3; ++c) table[3 * j + c] = srgbToLinear(rgb[c]);
  }
  return table;
})();

function srgbToLinear(c) {
  return c <= 0.04045 ? c / 12.92 : ((c + 0.055) / 1.055) ** 2.4;
}

// Linear-RGB colours (#R·3, raw layout) for one function given per welded vertex (#W values).
// Scaled by max |value|, so a constant function is uniformly one colour.
export function fieldColors(values, toWelded) {
  let scale = 0;
  for (const v of values) if (Number.isFinite(v)) scale = Math.max(scale, Math.abs(v));
  const inv = scale > 0 ? 1 / scale : 0;
  const welded = new Float32Array(values.length * 3);
  for (let w = 0; w < values.length; ++w) {
    const t = Number.isFinite(values[w]) ? values[w] * inv : 0;
    const j = Math.round(((Math.max(-1, Math.min(1, t)) + 1) / 2) * lutSize);
    welded[3 * w] = lut[3 * j];
    welded[3 * w + 1] = lut[3 * j + 1];
    welded[3 * w + 2] = lut[3 * j + 2];
  }
  return unweldValues(welded, toWelded, 3);
}
