// Vertex colours of the edit selection: each set in its own colour on the plain surface colour,
// spread from the welded mesh (where the sets live) to the displayed (raw) layout. Handles are
// numbered (a label per vertex) and each gets a colour of its own; where sets overlap, a handle
// wins over the fixed set, which wins over the region of interest.
export const handleColors = [
  [0.96, 0.42, 0.22],  // orange-red
  [0.93, 0.30, 0.70],  // magenta
  [0.98, 0.78, 0.20],  // yellow
  [0.62, 0.40, 0.95],  // violet
  [0.25, 0.85, 0.90],  // cyan
  [0.70, 0.50, 0.30],  // brown
];
export const fixedColor = [0.36, 0.55, 0.98];  // blue
export const roiColor = [0.45, 0.82, 0.52];    // green
const surface = [0.79, 0.81, 0.85];

export const handleColor = (h) => handleColors[h % handleColors.length];

// sets: {handle: Uint8Array of labels per welded vertex (0 = none, h + 1 = handle h), roi,
// fixed: Uint8Array 0/1}; toWelded: raw → welded map. Returns Float32Array #R·3 in 0..1, or
// null when every set is empty.
export function selectionColors({ handle, roi, fixed }, toWelded) {
  if (!handle.some(Boolean) && !roi.some(Boolean) && !fixed.some(Boolean)) return null;
  const colors = new Float32Array(toWelded.length * 3);
  for (let r = 0; r < toWelded.length; ++r) {
    const w = toWelded[r];
    const c = handle[w] ? handleColor(handle[w] - 1) : fixed[w] ? fixedColor : roi[w] ? roiColor : surface;
    colors[3 * r] = c[0];
    colors[3 * r + 1] = c[1];
    colors[3 * r + 2] = c[2];
  }
  return colors;
}
