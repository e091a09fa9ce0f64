// Landmark pairs of the Transfer job on the welded meshes (what the core works on): the pairs
// [[referenceVertex, sourceVertex], ...], the half pair waiting for its other side, and the
// CLI's landmark file {"reference", "source", "comment", "pairs": [[r, s], ...]} (docs/transfer.md;
// `meshmorph transfer --landmarks FILE`).
import { MeshMorphError } from './errors.js';

export const minLandmarks = 6; // the core's LandmarkOptions.min_landmarks

export class LandmarkPairs {
  constructor() {
    this.pairs = [];      // [[r, s], ...] welded indices
    this.pending = null;  // {side: 'reference'|'source', vertex: welded} clicked, other side next
  }

  // A click on welded vertex `vertex` of `side`. The first click of a pair waits (a second click
  // on the same side moves it); a click on the other side completes the pair. Returns
  // 'pending' or 'paired'.
  click(side, vertex) {
    if (!this.pending || this.pending.side === side) {
      this.pending = { side, vertex };
      return 'pending';
    }
    const pair = side === 'source' ? [this.pending.vertex, vertex] : [vertex, this.pending.vertex];
    this.pairs.push(pair);
    this.pending = null;
    return 'paired';
  }

  // Moves the `side` end of pair `index` to welded vertex `vertex` (a selected pair's end is
  // re-clicked where it belongs); the other end stays.
  move(index, side, vertex) {
    if (index < 0 || index >= this.pairs.length) return;
    this.pairs[index][side === 'reference' ? 0 : 1] = vertex;
  }

  remove(index) {
    this.pairs.splice(index, 1);
  }

  clear() {
    this.pairs = [];
    this.pending = null;
  }
}

// The landmark file of `pairs` (names: the meshes' file names).
export function landmarkFile(pairs, { reference, source }) {
  return {
    reference,
    source,
    comment: 'landmark pairs picked on the MeshMorph page: welded vertex indices (reference, source)',
    pairs: pairs.map(([r, s]) => [r, s]),
  };
}

// The pairs of a landmark file's parsed JSON, checked against the meshes' welded vertex counts.
export function readLandmarkFile(json, { referenceVertices, sourceVertices }) {
  const pairs = json?.pairs;
  if (!Array.isArray(pairs)) throw new MeshMorphError('ParseError', 'a landmark file is {"pairs": [[reference_vertex, source_vertex], ...]}');
  return pairs.map((p, i) => {
    if (!Array.isArray(p) || p.length !== 2 || !p.every(Number.isInteger)) {
      throw new MeshMorphError('ParseError', `landmark pair ${i} is not [reference_vertex, source_vertex]: ${JSON.stringify(p)}`);
    }
    const [r, s] = p;
    if (r < 0 || r >= referenceVertices || s < 0 || s >= sourceVertices) {
      throw new MeshMorphError('InvalidArgument', `landmark pair ${i} [${r}, ${s}] is out of range (reference ${referenceVertices}, source ${sourceVertices} vertices)`);
    }
    return [r, s];
  });
}
