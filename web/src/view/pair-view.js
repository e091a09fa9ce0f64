// Two meshes side by side in the viewer's scene (the Transfer job: the reference on the left,
// the source — or the transfer result — on the right). Each side is a THREE.Mesh with its own
// VertexPicker (view/picking.js); both are scaled to the same display size (their bounding
// radius → 1) and placed next to each other, so meshes in different units are comparable.
// Three ways to show them (setMode):
//   'side'    side by side in one pane, one camera; a pick tries both and keeps the nearer hit
//   'split'   two panes (Viewer.setSplit), the reference left and the source right, each centred
//             with its own camera; the cameras are linked (orbiting one moves both) or not
//   'overlay' both at the same place in one pane, both see-through
// Points given to and returned by this module are world space unless named `local` (a side's
// own coordinates, where its markers live as children of its mesh).
import * as THREE from 'three';
import { applyArrays } from '../lib/arrays.js';
import { disposeDocumentMaterials } from './document-materials.js';
import { VertexPicker, ndcFromClient } from './picking.js';

export const sides = ['reference', 'source'];
export const modes = ['side', 'split', 'overlay'];
const sideColors = { reference: 0xb9c7e0, source: 0xd8cdbf };
const gap = 0.2; // between the two meshes' bounding spheres, in display radii

function createSide(name) {
  const material = new THREE.MeshStandardMaterial({
    color: sideColors[name], roughness: 0.62, metalness: 0.0, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const mesh = new THREE.Mesh(new THREE.BufferGeometry(), material);
  mesh.name = `pair-${name}`;
  mesh.visible = false;
  return { name, mesh, analysis: material, document: null, picker: new VertexPicker(), toWelded: null, loaded: false };
}

export class PairView {
  constructor(viewer) {
    this.viewer = viewer;
    this.group = new THREE.Group();
    this.group.visible = false;
    viewer.scene.add(this.group);
    this.sides = Object.fromEntries(sides.map((name) => [name, createSide(name)]));
    for (const side of Object.values(this.sides)) this.group.add(side.mesh);
    this.raycaster = new THREE.Raycaster();
    this.mode = 'side';
    this.linked = true;
    this.materialMode = 'document'; // a glTF side shows its own materials (not in overlay)
  }

  // A side's glTF materials (view/document-materials.js result for its current geometry).
  setDocumentMaterials(name, display) {
    const side = this.sides[name];
    disposeDocumentMaterials(side.document);
    side.document = display;
    const geometry = side.mesh.geometry;
    if (display.uv) geometry.setAttribute('uv', new THREE.BufferAttribute(display.uv, 2));
    if (display.uv1) geometry.setAttribute('uv1', new THREE.BufferAttribute(display.uv1, 2));
    geometry.clearGroups();
    for (const g of display.groups) geometry.addGroup(g.start, g.count, g.materialIndex);
    this.applyMaterials();
  }

  setMaterialMode(mode) {
    this.materialMode = mode;
    this.applyMaterials();
  }

  // Overlay needs the see-through analysis material; otherwise the toggle decides.
  applyMaterials() {
    for (const side of Object.values(this.sides)) {
      const useDocument = side.document && this.materialMode === 'document' && this.mode !== 'overlay' && !side.analysis.vertexColors;
      side.mesh.material = useDocument ? side.document.materials : side.analysis;
    }
    this.viewer.requestRender();
  }

  // What each side is drawn with: {reference, source} → 'document' | 'analysis'.
  shownMaterials() {
    return Object.fromEntries(Object.values(this.sides).map((s) => [s.name, s.mesh.material === s.analysis ? 'analysis' : 'document']));
  }

  get active() { return this.group.visible; }

  // Shows the pair instead of the viewer's own mesh (or gives the view back).
  setActive(on) {
    if (this.group.visible === on) return;
    this.group.visible = on;
    this.viewer.setMainVisible(!on);
    this.applySplit();
    if (on) this.frame();
    this.viewer.requestRender();
  }

  // 'side' | 'split' | 'overlay' (see above); linked: the split panes' cameras move together.
  setMode(mode, { linked = this.linked } = {}) {
    if (!modes.includes(mode)) throw new Error(`unknown pair view mode ${mode}`);
    const changed = mode !== this.mode;
    this.mode = mode;
    this.linked = linked;
    // Overlay: both see-through (either can be inside the other), the source drawn last.
    for (const side of Object.values(this.sides)) {
      const material = side.analysis;
      material.transparent = mode === 'overlay';
      material.opacity = mode === 'overlay' ? (side.name === 'source' ? 0.55 : 0.4) : 1;
      material.depthWrite = mode !== 'overlay';
      material.needsUpdate = true;
      side.mesh.renderOrder = mode === 'overlay' && side.name === 'source' ? 1 : 0;
    }
    this.applyMaterials();
    this.layout();
    this.applySplit();
    if (changed) this.frame();
    this.viewer.requestRender();
  }

  applySplit() {
    const { viewer } = this;
    const split = this.active && this.mode === 'split';
    if (!split) {
      if (viewer.split) viewer.setSplit(null);
      return;
    }
    const meshes = sides.map((name) => this.sides[name]);
    viewer.setSplit({
      linked: this.linked,
      beforePass: (i) => meshes.forEach((side, k) => { side.mesh.visible = side.loaded && k === i; }),
      afterPasses: () => meshes.forEach((side) => { side.mesh.visible = side.loaded; }),
    });
  }

  // Which pane shows a side (0 unless split) and its camera and client rectangle.
  view(name) {
    const pane = this.mode === 'split' && this.active && name === 'source' ? 1 : 0;
    return { pane, camera: this.viewer.paneCamera(pane), rect: this.viewer.paneRect(pane) };
  }

  // A mesh for one side: positions/normals/indices (+ toWelded) from a load result; `open` as
  // in Viewer.setMesh (draw back faces of surfaces with boundaries).
  setMesh(name, { positions, normals, indices, toWelded = null }, { open = true } = {}) {
    const side = this.sides[name];
    const geometry = new THREE.BufferGeometry();
    applyArrays(geometry, { positions: positions.slice(), normals, indices });
    if (!normals) geometry.computeVertexNormals();
    side.mesh.geometry.dispose();
    side.mesh.geometry = geometry;
    disposeDocumentMaterials(side.document);
    side.document = null;
    side.mesh.material = side.analysis;
    side.analysis.vertexColors = false; // a new mesh has no part colours (setColors)
    side.analysis.color.set(sideColors[name]);
    side.analysis.side = open ? THREE.DoubleSide : THREE.FrontSide;
    side.analysis.needsUpdate = true;
    side.mesh.userData.pickSide = side.analysis.side;
    side.mesh.visible = true;
    side.toWelded = toWelded;
    side.loaded = true;
    side.picker.setTarget(side.mesh, { toWelded });
    this.layout();
    this.frame();
    const schedule = window.requestIdleCallback || ((fn) => setTimeout(fn, 0));
    schedule(() => {
      if (side.mesh.geometry === geometry) side.picker.ensureBvh();
    });
  }

  // New positions for a side (raw layout, same triangles): the transfer result over the source
  // or the source back. The side is placed again (the result sits elsewhere than the source),
  // the camera stays.
  setPositions(name, positions) {
    const side = this.sides[name];
    applyArrays(side.mesh.geometry, { positions });
    side.mesh.geometry.computeVertexNormals();
    side.picker.refitLater();
    this.layout();
    this.viewer.requestRender();
  }

  // Per-vertex colours on a side's analysis material (raw layout, 3 floats a vertex; the Transfer
  // job's part regions), or null to go back to the plain side colour. While colours are on, the
  // side is drawn with the analysis material (the glTF's own would hide them).
  setColors(name, colors) {
    const side = this.sides[name];
    const geometry = side.mesh.geometry;
    if (colors) geometry.setAttribute('color', new THREE.BufferAttribute(colors, 3));
    else geometry.deleteAttribute('color');
    side.analysis.color.set(colors ? 0xffffff : sideColors[name]);
    side.analysis.vertexColors = Boolean(colors);
    side.analysis.needsUpdate = true;
    this.applyMaterials();
  }

  // Display size: both sides scaled to bounding radius 1 and centred on their bounding boxes,
  // the reference at x = -(1 + gap / 2), the source at x = +(1 + gap / 2): fixed places, so
  // switching the source for the result (another extent) does not move the other side.
  // In split and overlay modes both are centred on the origin.
  layout() {
    for (const side of Object.values(this.sides)) {
      const geometry = side.mesh.geometry;
      if (!side.loaded || !geometry.boundingBox) continue;
      const scale = 1 / (geometry.boundingSphere.radius || 1);
      const center = geometry.boundingBox.getCenter(new THREE.Vector3());
      side.mesh.scale.setScalar(scale);
      side.mesh.position.copy(center).multiplyScalar(-scale);
      if (this.mode === 'side') side.mesh.position.x += (side.name === 'reference' ? -1 : 1) * (1 + gap / 2);
    }
    this.group.updateMatrixWorld(true);
  }

  frame() {
    const meshes = Object.values(this.sides).filter((s) => s.loaded).map((s) => s.mesh);
    // Straight from the front (slightly above): both sides at the same distance, the same size.
    // Split panes frame both meshes (they share the place), so linked cameras agree.
    if (!meshes.length || !this.active) return;
    this.viewer.frameMeshes(meshes, { direction: [0, 0.3, 1] });
    if (this.mode === 'split') this.viewer.frameMeshes(meshes, { direction: [0, 0.3, 1], pane: 1 });
  }

  // The vertex under a pointer position on either side: the picking.js result plus `side`, or
  // null. Both sides are ray cast; the nearer hit wins.
  pickAt(clientX, clientY) {
    if (!this.active) return null;
    let candidates = Object.values(this.sides);
    let pane = 0;
    if (this.mode === 'split') {
      pane = clientX >= this.viewer.paneRect(1).left ? 1 : 0;
      candidates = [candidates[pane]];
    }
    const camera = this.viewer.paneCamera(pane);
    const [x, y] = ndcFromClient(clientX, clientY, this.viewer.paneRect(pane));
    camera.updateMatrixWorld();
    this.raycaster.setFromCamera(new THREE.Vector2(x, y), camera);
    let best = null;
    for (const side of candidates) {
      if (!side.loaded) continue;
      const pick = side.picker.pickRay(this.raycaster.ray);
      if (pick && (!best || pick.distance < best.distance)) best = { ...pick, side: side.name };
    }
    return best;
  }

  // A displayed (raw) vertex of a side: its local position ([x, y, z]).
  localPoint(name, vertex) {
    const p = this.sides[name].mesh.geometry.getAttribute('position');
    return [p.getX(vertex), p.getY(vertex), p.getZ(vertex)];
  }

  // The display radius of a side's mesh in its local units (markers are sized from it).
  localRadius(name) {
    return this.sides[name].mesh.geometry.boundingSphere?.radius || 1;
  }
}
