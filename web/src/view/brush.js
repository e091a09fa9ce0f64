// The selection brush: a circle cursor over the view (a DOM ring that follows the pointer) and
// the vertices under it — displayed vertices whose projection falls inside the circle and that
// the camera sees (view/screen-space.js), so painting the front of an arm does not select its
// back. Projections are cached per camera pose and geometry version, so a stroke projects the
// mesh once, not per pointer event.
import { projectVertices, vertexVisible } from './screen-space.js';

export class Brush {
  constructor(viewer, { radius = 24 } = {}) {
    this.viewer = viewer;
    this.radius = radius; // CSS pixels
    this.cursor = document.createElement('div');
    this.cursor.className = 'brush-cursor';
    this.cursor.hidden = true;
    viewer.renderer.domElement.after(this.cursor);
    this.cache = null; // {key, projected}
  }

  setRadius(radius) {
    this.radius = radius;
    this.cursor.style.width = this.cursor.style.height = `${2 * radius}px`;
  }

  // Shows the ring centred on a client position (null hides it).
  showCursor(clientX, clientY, { erase = false } = {}) {
    if (clientX === null) {
      this.cursor.hidden = true;
      return;
    }
    const rect = this.cursor.parentElement.getBoundingClientRect();
    this.setRadius(this.radius);
    this.cursor.style.left = `${clientX - rect.left - this.radius}px`;
    this.cursor.style.top = `${clientY - rect.top - this.radius}px`;
    this.cursor.classList.toggle('erase', erase);
    this.cursor.hidden = false;
  }

  projection() {
    const { camera, geometry } = this.viewer;
    camera.updateMatrixWorld();
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    const key = [...camera.matrixWorld.elements, rect.left, rect.top, rect.width, rect.height,
      geometry.id, geometry.getAttribute('position')?.version].join(',');
    if (this.cache?.key !== key) this.cache = { key, projected: projectVertices(this.viewer) };
    return this.cache.projected;
  }

  // Raw vertices the circle covers moving from client position `from` to `to` (samples every
  // half radius up to `to`, so a fast stroke leaves no gaps), each once.
  verticesAlong(from, to) {
    const steps = Math.max(1, Math.ceil(Math.hypot(to.x - from.x, to.y - from.y) / (0.5 * this.radius)));
    const out = new Set();
    for (let i = 1; i <= steps; ++i) { // `from` itself was painted by the previous call
      const t = i / steps;
      for (const v of this.verticesAt(from.x + t * (to.x - from.x), from.y + t * (to.y - from.y))) out.add(v);
    }
    return [...out];
  }

  // Raw vertices under the circle at a client position that the camera sees.
  verticesAt(clientX, clientY) {
    if (!this.viewer.geometry.getAttribute('position')) return [];
    const projected = this.projection();
    const r2 = this.radius * this.radius;
    const out = [];
    for (let i = 0, v = 0; i < projected.length; i += 3, ++v) {
      const dx = projected[i] - clientX;
      const dy = projected[i + 1] - clientY;
      if (dx * dx + dy * dy <= r2 && Math.abs(projected[i + 2]) < 1 && vertexVisible(this.viewer, v)) out.push(v);
    }
    return out;
  }
}
