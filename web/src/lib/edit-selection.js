// The selection of an edit on the welded mesh: numbered handles (a label per vertex: 0 none,
// h + 1 handle h), the fixed set and the region of interest (0/1 per vertex). A vertex is in at
// most one handle, and never both in a handle and fixed (it is moved or held). Painting, grow /
// shrink / clear (lib/vertex-sets.js) and the index lists of a spec go through here; the panel
// (ui/panels/edit.js) only says which set and which handle.
import { members, setFromIndices } from './vertex-sets.js';

export class EditSelection {
  constructor(count) {
    this.count = count;
    this.handle = new Uint8Array(count);
    this.fixed = new Uint8Array(count);
    this.roi = new Uint8Array(count);
    this.handleCount = 1; // handles offered (the last may still be empty)
  }

  // From a spec's index lists ({handles: [[...]], roi, fixed}, lib/edit-spec.js readSpec).
  static fromLists({ handles, roi = [], fixed = [] }, count) {
    if (handles.length > 255) throw new RangeError('the page edits at most 255 handles');
    const s = new EditSelection(count);
    handles.forEach((list, h) => {
      for (const w of members(setFromIndices(list, count))) s.handle[w] = h + 1;
    });
    s.roi = setFromIndices(roi, count);
    s.fixed = setFromIndices(fixed, count);
    for (let w = 0; w < count; ++w) if (s.handle[w]) s.fixed[w] = 0;
    s.handleCount = Math.max(1, handles.length);
    return s;
  }

  handleMembers(h) {
    const out = [];
    for (let w = 0; w < this.count; ++w) if (this.handle[w] === h + 1) out.push(w);
    return out;
  }

  // {handle (vertices in any handle), handles: [per handle], fixed, roi}
  counts() {
    const handles = new Array(this.handleCount).fill(0);
    let handle = 0;
    for (const label of this.handle) {
      if (!label) continue;
      handle += 1;
      if (label <= this.handleCount) handles[label - 1] += 1;
    }
    return { handle, handles, fixed: members(this.fixed).length, roi: members(this.roi).length };
  }

  // Paints (or with erase, unpaints) welded vertices into set `target` ('handle' | 'fixed' |
  // 'roi'; handles: handle `active`). Returns whether anything changed.
  paint(vertices, target, active, erase) {
    const set = this[target];
    const on = target === 'handle' ? active + 1 : 1;
    let changed = false;
    for (const w of vertices) {
      if (erase) {
        if (set[w] === on) {
          set[w] = 0;
          changed = true;
        }
        continue;
      }
      changed ||= set[w] !== on;
      set[w] = on;
      if (target === 'handle') this.fixed[w] = 0;
      if (target === 'fixed') this.handle[w] = 0;
    }
    return changed;
  }

  // Applies fn (a Uint8Array 0/1 mask → changes it in place: grow, shrink, clear) to set
  // `target`; for handles to handle `active`, which does not take vertices of other handles.
  change(target, active, fn) {
    if (target !== 'handle') {
      fn(this[target]);
      if (target === 'fixed') for (let w = 0; w < this.count; ++w) if (this.fixed[w]) this.handle[w] = 0;
      return;
    }
    const label = active + 1;
    const mask = this.handle.map((l) => (l === label ? 1 : 0));
    fn(mask);
    for (let w = 0; w < this.count; ++w) {
      if (mask[w] && (this.handle[w] === 0 || this.handle[w] === label)) {
        this.handle[w] = label;
        this.fixed[w] = 0;
      } else if (!mask[w] && this.handle[w] === label) {
        this.handle[w] = 0;
      }
    }
  }

  // A new (empty) handle, or the last one when it is still empty; returns its index.
  addHandle() {
    if (this.handleMembers(this.handleCount - 1).length) this.handleCount += 1;
    return this.handleCount - 1;
  }

  // Renumbers the non-empty handles 1..H in order (a spec lists non-empty handles only);
  // returns the new index of handle `active` (0 when it was empty).
  compact(active) {
    const used = [];
    for (let h = 0; h < this.handleCount; ++h) if (this.handleMembers(h).length) used.push(h + 1);
    const relabel = new Uint8Array(256);
    used.forEach((label, i) => { relabel[label] = i + 1; });
    for (let w = 0; w < this.count; ++w) this.handle[w] = relabel[this.handle[w]];
    this.handleCount = Math.max(1, used.length);
    return Math.max(0, used.indexOf(active + 1));
  }

  // The index lists of a spec: {handles (non-empty ones), roi, fixed}.
  lists() {
    const handles = [];
    for (let h = 0; h < this.handleCount; ++h) {
      const list = this.handleMembers(h);
      if (list.length) handles.push(list);
    }
    return { handles, roi: members(this.roi), fixed: members(this.fixed) };
  }
}
