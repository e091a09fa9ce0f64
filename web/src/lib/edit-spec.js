// The edit spec the page builds, sends to editCreate and saves: the same JSON grammar as
// `meshmorph edit --spec` (app/edit_spec.h), restricted to what the page edits — one handle
// given by welded vertex indices and a column-major 4x4 "matrix", optional "roi" and "fixed"
// index lists, "features" and "options". Reading accepts index lists (plain arrays or
// {"indices": [...]}) only: selectors (spheres, boxes, slabs…) are evaluated by the core, and the
// page has to show its selection before it starts a session.
import { MeshMorphError } from './errors.js';

const identity = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1];

// {handle, roi, fixed}: sorted welded index arrays (roi/fixed may be empty: then left out);
// matrix: 16 numbers or null (no transform key: the core's identity); features; options.
export function buildSpec({ handle, roi = [], fixed = [], matrix = null, features = 'keep', options = {} }) {
  const spec = { handles: [{ select: [...handle] }] };
  if (matrix) spec.handles[0].matrix = Array.from(matrix);
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

// A spec document (parsed JSON) → {handle, roi, fixed, matrix, features, options}; throws
// MeshMorphError for what the page cannot show.
export function readSpec(spec) {
  if (!spec || typeof spec !== 'object' || Array.isArray(spec)) throw new MeshMorphError('ParseError', 'an edit spec is a JSON object');
  const handles = spec.handles;
  if (!Array.isArray(handles) || handles.length === 0) throw new MeshMorphError('ParseError', 'the spec has no "handles"');
  if (handles.length > 1) throw new MeshMorphError('Unsupported', `the spec has ${handles.length} handles; the page edits one handle at a time`);
  const h = handles[0];
  const transformKeys = Object.keys(h).filter((k) => !['select', 'matrix'].includes(k));
  if (transformKeys.length) {
    throw new MeshMorphError('Unsupported', `the handle's transform uses ${transformKeys.join(', ')}; the page reads "matrix" transforms (as it saves them)`);
  }
  const matrix = h.matrix ?? null;
  if (matrix !== null && (!Array.isArray(matrix) || matrix.length !== 16 || !matrix.every(Number.isFinite))) {
    throw new MeshMorphError('ParseError', 'the handle\'s "matrix" must be 16 numbers (column-major)');
  }
  const features = spec.features ?? 'keep';
  if (!['keep', 'scale'].includes(features)) throw new MeshMorphError('ParseError', `"features" must be "keep" or "scale", not ${JSON.stringify(features)}`);
  return {
    handle: indexList(h.select, 'handle'),
    roi: indexList(spec.roi, 'roi'),
    fixed: indexList(spec.fixed, 'fixed set'),
    matrix: matrix && !matrix.every((v, i) => v === identity[i]) ? matrix : null,
    features,
    options: spec.options ?? {},
  };
}
