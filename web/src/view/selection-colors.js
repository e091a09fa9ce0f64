// Vertex colours of the edit selection: each set in its own colour on the plain surface colour,
// spread from the welded mesh (where the sets live) to the displayed (raw) layout. Where sets
// overlap, the handle wins over the fixed set, which wins over the region of interest.
export const setColors = {
  handle: [0.96, 0.42, 0.22],  // orange-red
  fixed: [0.36, 0.55, 0.98],   // blue
  roi: [0.45, 0.82, 0.52],     // green
};
const surface = [0.79, 0.81, 0.85];

// sets: {handle, roi, fixed} (Uint8Array per welded vertex); toWelded: raw → welded map.
// Returns Float32Array #R·3 in 0..1, or null when every set is empty.
export function selectionColors({ handle, roi, fixed }, toWelded) {
  if (!handle.some(Boolean) && !roi.some(Boolean) && !fixed.some(Boolean)) return null;
  const colors = new Float32Array(toWelded.length * 3);
  for (let r = 0; r < toWelded.length; ++r) {
    const w = toWelded[r];
    const c = handle[w] ? setColors.handle : fixed[w] ? setColors.fixed : roi[w] ? setColors.roi : surface;
    colors[3 * r] = c[0];
    colors[3 * r + 1] = c[1];
    colors[3 * r + 2] = c[2];
  }
  return colors;
}
