// The edit spec the page builds, sends to editCreate and saves: the same JSON grammar as
// `meshmorph edit --spec` (app/edit_spec.h), restricted to what the page edits — handles given
// by welded vertex indices, each with a column-major 4x4 "matrix", optional "roi" and "fixed"
// index lists, "features" and "options". Reading accepts index lists (plain arrays or
// {"indices": [...]}) and matrices only: selectors (spheres, boxes, slabs…) and
// translate/rotate transforms are evaluated by the core, and the page has to show its
// selection and gizmo before it starts a session.
import { MeshMorphError } from './errors.js';

export const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

// handles: [sorted welded index array per handle]; matrices: [16 numbers per handle] or null
// (no transform keys: the core's identity); roi / fixed: sorted welded index arrays (left out
// when empty); features; options.
export function buildSpec({ handles, roi = [], fixed = [], matrices = null, features = 'keep', options = {} }) {
  const spec = { handles: handles.map((select, h) => (matrices ? { select: [...select], matrix: Array.from(matrices[h]) } : { select: [...select] })) };
  if (roi.length) spec.roi = [...roi];
  if (fixed.length) spec.fixed = [...fixed];
  spec.features = features;
  if (Object.keys(options).length) spec.options = { ...options };
  return spec;
}

function indexList(selection, what) {
  if (selection === undefined) return [];
  const list = Array.isArray(selection) ? selection : selection?.indices;
  const others = Array.isArray(selection) ? [] : Object.keys(selection || {}).filter((k) => k !== 'indices');
  if (!Array.isArray(list) || others.length) {
    throw new MeshMorphError('Unsupported', `the ${what} of this spec uses ${others.join(', ') || 'a selector'}; `
      + 'the page reads vertex index lists only (specs it saved itself); run selector specs with `meshmorph edit --spec`');
  }
  return list;
}

// A spec document (parsed JSON) → {handles, roi, fixed, matrices (identity where a handle has
// none), features, options}; throws MeshMorphError for what the page cannot show.
export function readSpec(spec) {
  if (!spec || typeof spec !== 'object' || Array.isArray(spec)) throw new MeshMorphError('ParseError', 'an edit spec is a JSON object');
  const handles = spec.handles;
  if (!Array.isArray(handles) || handles.length === 0) throw new MeshMorphError('ParseError', 'the spec has no "handles"');
  const matrices = handles.map((h, i) => {
    const transformKeys = Object.keys(h || {}).filter((k) => !['select', 'matrix'].includes(k));
    if (transformKeys.length) {
      throw new MeshMorphError('Unsupported', `handle ${i + 1}'s transform uses ${transformKeys.join(', ')}; the page reads "matrix" transforms (as it saves them)`);
    }
    const matrix = h.matrix ?? identity;
    if (!Array.isArray(matrix) || matrix.length !== 16 || !matrix.every(Number.isFinite)) {
      throw new MeshMorphError('ParseError', `handle ${i + 1}'s "matrix" must be 16 numbers (column-major)`);
    }
    return matrix;
  });
  const features = spec.features ?? 'keep';
  if (!['keep', 'scale'].includes(features)) throw new MeshMorphError('ParseError', `"features" must be "keep" or "scale", not ${JSON.stringify(features)}`);
  return {
    handles: handles.map((h, i) => indexList(h.select, `handle ${i + 1}`)),
    roi: indexList(spec.roi, 'roi'),
    fixed: indexList(spec.fixed, 'fixed set'),
    matrices,
    features,
    options: spec.options ?? {},
  };
}
