// The Merge job's scene (ui/panels/merge.js): the target and the source mesh, their boundary
// loops as thick lines (the chosen loop of each mesh bright), numbered key markers, the cut
// preview (a plane with a gizmo, or a disk), the placement gizmo of the source and the merged
// result with its seam.
//
// Arrangements (setArrangement):
//   'apart'     the two meshes side by side, each scaled to bounding radius 1 (the target left):
//               before both boundary loops are known
//   'exploded'  the source turned and scaled as it will attach (setExploded: a 4x4 from source
//               to target coordinates), pulled out of the target's opening: the
//               configuration-independent mode, where the source's own placement does not matter
//   'placed'    the source where `placement` (a 4x4 from source to target coordinates) puts it,
//               in the target's frame: the configuration-dependent mode, moved with the gizmo
// and the result (showResult) in the target's frame. The target's frame is the target scaled to
// radius 1 about its bounding-box centre. Vertices given to and returned from this module are
// displayed (raw) indices unless named `welded`; points named `local` are a mesh's own
// coordinates (where the core works), others world space.
import * as THREE from 'three';
import { TransformControls } from 'three/addons/controls/TransformControls.js';
import { LineMaterial } from 'three/addons/lines/LineMaterial.js';
import { LineSegments2 } from 'three/addons/lines/LineSegments2.js';
import { LineSegmentsGeometry } from 'three/addons/lines/LineSegmentsGeometry.js';
import { applyArrays } from '../lib/arrays.js';
import { VertexPicker, ndcFromClient } from './picking.js';
import { vertexVisible } from './screen-space.js';

export const mergeSides = ['target', 'source'];
export const sideColors = { target: [0.66, 0.74, 0.9], source: [0.92, 0.8, 0.62] };
const loopColors = { chosen: 0xffd23f, other: 0x4fc3d9 };
const seamColor = 0xff7a2f;
const gap = 0.25;
const pendingColor = [1, 1, 1];
const labelPx = 64;

// Colour of key pair i ([r, g, b] in 0..1): hues a golden angle apart (as the Transfer job's).
export function keyColor(i) {
  const c = new THREE.Color().setHSL((i * 0.61803398875 + 0.08) % 1, 0.8, 0.55);
  return [c.r, c.g, c.b];
}

function labelSprite(text, rgb) {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = labelPx;
  const g = canvas.getContext('2d');
  g.fillStyle = `rgb(${rgb.map((v) => Math.round(255 * v)).join(', ')})`;
  g.beginPath();
  g.arc(labelPx / 2, labelPx / 2, labelPx / 2 - 2, 0, 2 * Math.PI);
  g.fill();
  g.strokeStyle = '#10131a';
  g.lineWidth = 3;
  g.stroke();
  g.fillStyle = '#10131a';
  g.font = `bold ${text.length > 2 ? 26 : 34}px system-ui, sans-serif`;
  g.textAlign = 'center';
  g.textBaseline = 'middle';
  g.fillText(text, labelPx / 2, labelPx / 2 + 2);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  // Numbers stay readable where the surface hides their vertex (a key on the far side of a rim).
  // Constant size on the screen (sizeAttenuation off): readable whatever the zoom.
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false, sizeAttenuation: false }));
  sprite.center.set(-0.15, -0.15);
  sprite.renderOrder = 3;
  return sprite;
}

const sphereGeometry = new THREE.SphereGeometry(1, 16, 12);

function createSide(name) {
  const material = new THREE.MeshStandardMaterial({
    color: new THREE.Color(...sideColors[name]), roughness: 0.62, metalness: 0, side: THREE.DoubleSide,
    polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
  });
  const mesh = new THREE.Mesh(new THREE.BufferGeometry(), material);
  mesh.name = `merge-${name}`;
  mesh.matrixAutoUpdate = false;
  mesh.visible = false;
  const overlay = new THREE.Group();
  mesh.add(overlay);
  return {
    name, mesh, overlay, picker: new VertexPicker(), loaded: false, toWelded: null, weldedToRaw: null,
    loops: [], chosenLoop: -1, lines: [], markers: [], normalization: new THREE.Matrix4(), center: new THREE.Vector3(), radius: 1,
  };
}

function disposeObject(object) {
  object.traverse((o) => {
    if (o.geometry && o.geometry !== sphereGeometry) o.geometry.dispose();
    if (o.material) {
      o.material.map?.dispose();
      o.material.dispose();
    }
  });
  object.removeFromParent();
}

export class MergeView {
  constructor(viewer) {
    this.viewer = viewer;
    this.root = new THREE.Group();
    this.root.name = 'merge';
    this.root.visible = false;
    viewer.scene.add(this.root);
    this.frame = new THREE.Group(); // the target's frame
    this.frame.matrixAutoUpdate = false;
    this.root.add(this.frame);
    this.sides = Object.fromEntries(mergeSides.map((name) => [name, createSide(name)]));
    this.frame.add(this.sides.target.mesh);
    this.root.add(this.sides.source.mesh);
    this.arrangement = 'apart';
    this.placement = new THREE.Matrix4();
    this.exploded = new THREE.Matrix4();
    this.viewDirection = null; // [x, y, z] the camera looks from (exploded / placed), or null
    this.showingResult = false;
    this.raycaster = new THREE.Raycaster();
    this.size = new THREE.Vector2();

    // The result: merged mesh (target frame) and its seam (the zip faces) drawn over it.
    this.result = new THREE.Mesh(new THREE.BufferGeometry(), new THREE.MeshStandardMaterial({
      color: 0xffffff, vertexColors: true, roughness: 0.6, metalness: 0, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    }));
    this.result.name = 'merge-result';
    this.result.visible = false;
    this.seam = new THREE.Mesh(new THREE.BufferGeometry(), new THREE.MeshBasicMaterial({ color: seamColor, side: THREE.DoubleSide }));
    this.seam.name = 'merge-seam';
    this.seamEdges = new THREE.LineSegments(new THREE.BufferGeometry(), new THREE.LineBasicMaterial({ color: 0x2a1200 }));
    this.result.add(this.seam, this.seamEdges);
    this.frame.add(this.result);
    this.resultPicker = new VertexPicker();

    // The hover marker: the boundary vertex a click would take.
    this.hover = new THREE.Mesh(sphereGeometry, new THREE.MeshBasicMaterial({ color: 0xffd23f }));
    this.hover.visible = false;
    this.hover.renderOrder = 2;

    // Cut previews: a translucent square on the plane (child of a pivot the gizmo moves) and a
    // marker at a disk's centre.
    this.planePivot = new THREE.Object3D();
    this.planePivot.name = 'merge-plane-pivot';
    this.planeMesh = new THREE.Mesh(new THREE.PlaneGeometry(2, 2), new THREE.MeshBasicMaterial({
      color: 0xff5a5a, transparent: true, opacity: 0.28, side: THREE.DoubleSide, depthWrite: false,
    }));
    this.planeEdge = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints([
      new THREE.Vector3(-1, -1, 0), new THREE.Vector3(1, -1, 0), new THREE.Vector3(1, 1, 0), new THREE.Vector3(-1, 1, 0)]),
    new THREE.LineBasicMaterial({ color: 0xff8a8a }));
    this.planeArrow = new THREE.ArrowHelper(new THREE.Vector3(0, 0, 1), new THREE.Vector3(), 0.5, 0x7dff9a, 0.12, 0.07);
    this.planePivot.add(this.planeMesh, this.planeEdge, this.planeArrow);
    this.planePivot.visible = false;
    this.diskMarker = new THREE.Mesh(sphereGeometry, new THREE.MeshBasicMaterial({ color: 0xff5a5a }));
    this.diskMarker.visible = false;

    // The placement pivot: at the source's centre, in the target's frame.
    this.placePivot = new THREE.Object3D();
    this.placePivot.name = 'merge-place-pivot';
    this.frame.add(this.placePivot);

    this.gizmo = new TransformControls(viewer.camera, viewer.renderer.domElement);
    this.gizmo.setSize(0.8);
    this.gizmoHelper = this.gizmo.getHelper();
    this.gizmoHelper.visible = false;
    this.gizmo.enabled = false;
    this.root.add(this.gizmoHelper);
    this.gizmoKind = null; // 'place' | 'plane'
    this.onPlacement = () => {};
    this.onPlane = () => {};
    this.gizmo.addEventListener('change', () => viewer.requestRender());
    this.gizmo.addEventListener('dragging-changed', (e) => { viewer.controls.enabled = !e.value; });
    this.gizmo.addEventListener('objectChange', () => this.gizmoMoved());
  }

  get active() { return this.root.visible; }

  request() { this.viewer.requestRender(); }

  // Shows the merge scene instead of the viewer's own mesh (or gives the view back). Jobs
  // switch in panel order, so the job shown next may already have put up its own scene group
  // (the Transfer job's pair view): then the viewer's mesh stays hidden and its camera stays.
  setActive(on) {
    if (this.root.visible === on) return;
    this.root.visible = on;
    this.gizmo.enabled = on && Boolean(this.gizmoKind);
    if (on) {
      this.viewer.setMainVisible(false);
      this.frameCamera();
    } else if (!this.otherViewShown()) {
      this.viewer.setMainVisible(true);
      this.viewer.frame();
    }
    this.request();
  }

  otherViewShown() {
    const { scene, overlays } = this.viewer;
    return scene.children.some((c) => c.isGroup && c !== this.root && c !== overlays && c.visible);
  }

  // ---- meshes

  // A mesh for one side (the mergeOpen op's buffers): positions/indices/normals? in the raw
  // layout, toWelded, and the loops (welded vertex lists).
  setMesh(name, { positions, indices, normals, toWelded }, loops) {
    const side = this.sides[name];
    const geometry = new THREE.BufferGeometry();
    applyArrays(geometry, { positions: positions.slice(), normals, indices });
    if (!normals) geometry.computeVertexNormals();
    side.mesh.geometry.dispose();
    side.mesh.geometry = geometry;
    side.mesh.material.vertexColors = false;
    side.mesh.material.color.setRGB(...sideColors[name]);
    side.mesh.material.needsUpdate = true;
    side.mesh.visible = !this.showingResult;
    side.loaded = true;
    side.toWelded = toWelded;
    const weldedCount = toWelded.reduce((m, w) => Math.max(m, w + 1), 0);
    side.weldedToRaw = new Int32Array(weldedCount).fill(-1);
    for (let r = toWelded.length - 1; r >= 0; --r) side.weldedToRaw[toWelded[r]] = r;
    side.picker.setTarget(side.mesh, { toWelded });
    side.loops = loops;
    side.chosenLoop = loops.length === 1 ? 0 : -1;
    geometry.computeBoundingBox();
    side.center = geometry.boundingBox.getCenter(new THREE.Vector3());
    side.radius = geometry.boundingSphere.radius || 1;
    side.normalization = new THREE.Matrix4().makeScale(1 / side.radius, 1 / side.radius, 1 / side.radius)
      .multiply(new THREE.Matrix4().makeTranslation(-side.center.x, -side.center.y, -side.center.z));
    this.drawLoops(name);
    this.clearMarkers(name);
    if (name === 'source') this.resetPlacementPivot();
    this.layout();
    const schedule = window.requestIdleCallback || ((fn) => setTimeout(fn, 0));
    schedule(() => { if (side.mesh.geometry === geometry) side.picker.ensureBvh(); });
  }

  // Local position of a welded vertex of a side ([x, y, z] of its first displayed vertex).
  localPoint(name, welded) {
    const side = this.sides[name];
    const raw = side.weldedToRaw[welded];
    const p = side.mesh.geometry.getAttribute('position');
    return new THREE.Vector3(p.getX(raw), p.getY(raw), p.getZ(raw));
  }

  // ---- boundary loops

  drawLoops(name) {
    const side = this.sides[name];
    for (const line of side.lines) disposeObject(line);
    side.lines = side.loops.map((loop, l) => {
      const points = new Float32Array(loop.length * 6);
      loop.forEach((v, i) => {
        const a = this.localPoint(name, v);
        const b = this.localPoint(name, loop[(i + 1) % loop.length]);
        points.set([a.x, a.y, a.z, b.x, b.y, b.z], 6 * i);
      });
      const geometry = new LineSegmentsGeometry().setPositions(points);
      const material = new LineMaterial({ color: loopColors.other, linewidth: 2.5, worldUnits: false });
      const line = new LineSegments2(geometry, material);
      line.name = `merge-${name}-loop-${l}`;
      line.renderOrder = 1;
      line.onBeforeRender = (renderer) => material.resolution.copy(renderer.getSize(this.size));
      side.overlay.add(line);
      return line;
    });
    this.styleLoops(name);
  }

  chooseLoop(name, loop) {
    this.sides[name].chosenLoop = loop;
    this.styleLoops(name);
  }

  styleLoops(name) {
    const side = this.sides[name];
    side.lines.forEach((line, l) => {
      const chosen = l === side.chosenLoop;
      line.material.color.setHex(chosen ? loopColors.chosen : loopColors.other);
      line.material.linewidth = chosen ? 4 : 2.5;
    });
    this.request();
  }

  // The boundary vertex nearest to a pointer position on the screen (within maxPx CSS pixels),
  // on either mesh, preferring those the camera sees: {side, welded, loop, distance} or null.
  nearestBoundaryVertex(clientX, clientY, maxPx = 36) {
    if (!this.active || this.showingResult) return null;
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    const { camera } = this.viewer;
    camera.updateMatrixWorld();
    this.root.updateMatrixWorld(true);
    let best = null;
    const v = new THREE.Vector3();
    for (const side of Object.values(this.sides)) {
      if (!side.loaded || !side.mesh.visible) continue;
      side.loops.forEach((loop, l) => {
        for (const w of loop) {
          v.copy(this.localPoint(side.name, w)).applyMatrix4(side.mesh.matrixWorld).project(camera);
          if (Math.abs(v.z) > 1) continue;
          const x = rect.left + ((v.x + 1) / 2) * rect.width;
          const y = rect.top + ((1 - v.y) / 2) * rect.height;
          const d = Math.hypot(x - clientX, y - clientY);
          if (d > maxPx || (best && d >= best.distance + (best.visible ? 0 : maxPx))) continue;
          const visible = vertexVisible(this.viewer, side.weldedToRaw[w], { mesh: side.mesh, picker: side.picker });
          // A visible vertex beats a hidden one; among equals the nearer one wins.
          if (!best || (visible && !best.visible) || (visible === best.visible && d < best.distance)) {
            best = { side: side.name, welded: w, loop: l, distance: d, visible };
          }
        }
      });
    }
    return best;
  }

  // Where a welded vertex of a side is on the screen: {x, y, visible}.
  vertexOnScreen(name, welded) {
    const side = this.sides[name];
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    this.viewer.camera.updateMatrixWorld();
    this.root.updateMatrixWorld(true);
    const ndc = this.localPoint(name, welded).applyMatrix4(side.mesh.matrixWorld).project(this.viewer.camera);
    const inView = Math.abs(ndc.x) < 1 && Math.abs(ndc.y) < 1 && Math.abs(ndc.z) < 1;
    return {
      x: rect.left + ((ndc.x + 1) / 2) * rect.width,
      y: rect.top + ((1 - ndc.y) / 2) * rect.height,
      visible: inView && side.mesh.visible && vertexVisible(this.viewer, side.weldedToRaw[welded], { mesh: side.mesh, picker: side.picker }),
    };
  }

  // Where the centre of a side's bounding box is on the screen: {x, y}.
  centreOnScreen(name) {
    const side = this.sides[name];
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    this.viewer.camera.updateMatrixWorld();
    this.root.updateMatrixWorld(true);
    const ndc = side.center.clone().applyMatrix4(side.mesh.matrixWorld).project(this.viewer.camera);
    return { x: rect.left + ((ndc.x + 1) / 2) * rect.width, y: rect.top + ((1 - ndc.y) / 2) * rect.height };
  }

  showHover(pick) {
    this.hover.removeFromParent();
    if (!pick) {
      this.hover.visible = false;
      this.request();
      return;
    }
    const side = this.sides[pick.side];
    side.overlay.add(this.hover);
    this.hover.position.copy(this.localPoint(pick.side, pick.welded));
    this.hover.scale.setScalar(this.markerSize(pick.side) * 1.1);
    this.hover.visible = true;
    this.request();
  }

  // ---- key markers

  clearMarkers(name) {
    const side = this.sides[name];
    for (const m of side.markers) disposeObject(m);
    side.markers = [];
  }

  // pairs: [[targetWelded, sourceWelded], ...]; pending {side, vertex (welded)} or null;
  // selected: index or -1.
  showKeys(pairs, pending, selected) {
    for (const name of mergeSides) this.clearMarkers(name);
    pairs.forEach(([t, s], i) => {
      this.addMarker('target', t, keyColor(i), String(i + 1), i === selected);
      this.addMarker('source', s, keyColor(i), String(i + 1), i === selected);
    });
    if (pending) this.addMarker(pending.side, pending.vertex, pendingColor, String(pairs.length + 1), true);
    this.request();
  }

  // The size of a side's markers (local units): a fraction of its chosen loop's radius (the
  // keys sit on it), else of the mesh.
  markerSize(name) {
    const side = this.sides[name];
    const loop = side.loops[side.chosenLoop];
    if (!loop) return side.radius * 0.015;
    let length = 0;
    loop.forEach((w, i) => { length += this.localPoint(name, w).distanceTo(this.localPoint(name, loop[(i + 1) % loop.length])); });
    return Math.min(side.radius * 0.015, (0.06 * length) / (2 * Math.PI));
  }

  addMarker(name, welded, rgb, text, big) {
    const side = this.sides[name];
    if (!side.loaded) return;
    const group = new THREE.Group();
    const sphere = new THREE.Mesh(sphereGeometry, new THREE.MeshBasicMaterial({ color: new THREE.Color(...rgb) }));
    sphere.scale.setScalar(this.markerSize(name) * (big ? 1.4 : 1));
    sphere.renderOrder = 2;
    const sprite = labelSprite(text, rgb);
    // Screen size: ~26 CSS pixels (30 for the selected / waiting one) over the parent's scale.
    this.root.updateMatrixWorld(true);
    const worldScale = new THREE.Vector3().setFromMatrixScale(side.mesh.matrixWorld).x || 1;
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    const ndc = (2 * (big ? 30 : 26)) / (rect.height || 800);
    sprite.scale.setScalar((ndc * Math.tan(THREE.MathUtils.degToRad(this.viewer.camera.fov) / 2)) / worldScale);
    group.add(sphere, sprite);
    group.position.copy(this.localPoint(name, welded));
    side.overlay.add(group);
    side.markers.push(group);
  }

  // ---- colours (cut previews, fixed vertices): #R·3 in 0..1 or null for the plain colour

  setColors(name, colors) {
    const side = this.sides[name];
    applyArrays(side.mesh.geometry, { colors });
    const use = Boolean(colors);
    if (side.mesh.material.vertexColors !== use) {
      side.mesh.material.vertexColors = use;
      if (use) side.mesh.material.color.set(0xffffff);
      else side.mesh.material.color.setRGB(...sideColors[name]);
      side.mesh.material.needsUpdate = true;
    }
    this.request();
  }

  // ---- layout and camera

  // arrangement: 'apart' | 'exploded' | 'placed'; viewDirection: where the camera looks from
  // (world, [x, y, z]) or null for the default. The camera is framed again when the arrangement
  // changes or `frame` is true.
  setArrangement(arrangement, { viewDirection = this.viewDirection, frame = false } = {}) {
    const changed = arrangement !== this.arrangement;
    this.arrangement = arrangement;
    this.viewDirection = viewDirection;
    this.layout();
    if (changed || frame) this.frameCamera();
  }

  // Turns the whole merge scene for display: basis {right, up} (mesh coordinates) → screen x, y;
  // null: as the meshes are.
  setOrientation(basis) {
    if (basis) {
      const r = new THREE.Vector3(...basis.right);
      const u = new THREE.Vector3(...basis.up);
      const m = new THREE.Matrix4().makeBasis(r, u, r.clone().cross(u)).transpose();
      this.root.quaternion.setFromRotationMatrix(m);
    } else {
      this.root.quaternion.identity();
    }
    this.root.updateMatrixWorld(true);
  }

  setExploded(elements) {
    this.exploded.fromArray(elements);
    this.layout();
  }

  layout() {
    const { target, source } = this.sides;
    const shift = (x) => new THREE.Matrix4().makeTranslation(x, 0, 0);
    const apart = (this.arrangement === 'apart' || !target.loaded) && !this.showingResult;
    this.frame.matrix.copy(apart && source.loaded && target.loaded ? shift(-(1 + gap / 2)).multiply(target.normalization) : target.normalization);
    if (apart) {
      source.mesh.matrix.copy(target.loaded ? shift(1 + gap / 2) : new THREE.Matrix4()).multiply(source.normalization);
    } else {
      source.mesh.matrix.multiplyMatrices(this.frame.matrix, this.arrangement === 'exploded' ? this.exploded : this.placement);
    }
    target.mesh.visible = target.loaded && !this.showingResult;
    source.mesh.visible = source.loaded && !this.showingResult;
    this.result.visible = this.showingResult;
    this.root.updateMatrixWorld(true);
    this.request();
  }

  // Frames the camera on what is shown, from the front and a little above.
  frameCamera() {
    if (!this.active) return;
    let meshes = this.showingResult ? [this.result] : Object.values(this.sides).filter((s) => s.loaded).map((s) => s.mesh);
    const direction = this.arrangement !== 'apart' && this.viewDirection ? this.viewDirection : [0, 0.3, 1];
    // Picking keys (exploded / placed): the seam region — the target around its chosen loop and
    // the source — rather than the whole target.
    const region = !this.showingResult && this.arrangement !== 'apart' ? this.loopRegion('target') : null;
    if (region) meshes = [region, this.sides.source.mesh];
    if (meshes.length) this.viewer.frameMeshes(meshes, { direction });
  }

  // A stand-in mesh (not in the scene) holding the points of a side's chosen loop and a band of
  // the mesh around it (within two loop diameters of the loop's centre), placed like the side:
  // what frameCamera fits when the seam matters more than the whole target.
  loopRegion(name) {
    const side = this.sides[name];
    const loop = side.loops[side.chosenLoop];
    if (!side.loaded || !loop) return null;
    const centre = new THREE.Vector3();
    for (const w of loop) centre.add(this.localPoint(name, w));
    centre.divideScalar(loop.length);
    let reach = 0;
    for (const w of loop) reach = Math.max(reach, this.localPoint(name, w).distanceTo(centre));
    reach *= 2.5;
    const p = side.mesh.geometry.getAttribute('position');
    const kept = [];
    const v = new THREE.Vector3();
    for (let i = 0; i < p.count; ++i) {
      v.fromBufferAttribute(p, i);
      if (v.distanceTo(centre) <= reach) kept.push(v.x, v.y, v.z);
    }
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.Float32BufferAttribute(kept, 3));
    geometry.computeBoundingBox();
    const region = new THREE.Mesh(geometry);
    this.root.updateMatrixWorld(true);
    region.matrixAutoUpdate = false;
    region.matrix.copy(side.mesh.matrixWorld);
    region.matrixWorld.copy(side.mesh.matrixWorld);
    region.matrixWorldNeedsUpdate = true; // updateMatrixWorld() copies matrix (no parent)
    return region;
  }

  // Turns the camera about the orbit target so it looks at a side's chosen loop from outside
  // the mesh (the loop's opening faces the viewer), keeping the distance.
  lookAtLoop(name, outwardLocal) {
    const side = this.sides[name];
    if (!side.loaded || side.chosenLoop < 0) return;
    const { camera, controls } = this.viewer;
    const centreLocal = new THREE.Vector3();
    const loop = side.loops[side.chosenLoop];
    for (const w of loop) centreLocal.add(this.localPoint(name, w));
    centreLocal.divideScalar(loop.length);
    this.root.updateMatrixWorld(true);
    const centre = centreLocal.clone().applyMatrix4(side.mesh.matrixWorld);
    const direction = outwardLocal.clone().transformDirection(side.mesh.matrixWorld).normalize();
    // From the side the camera looks from now, turned 50° towards the loop's axis: the rim is
    // seen as an open ring, not edge-on, with the mesh around it; far enough to see it all.
    const current = camera.position.clone().sub(controls.target).normalize();
    let across = current.clone().addScaledVector(direction, -current.dot(direction));
    if (across.lengthSq() < 1e-6) across = new THREE.Vector3(0, 1, 0).addScaledVector(direction, -direction.y);
    across.normalize();
    const angle = THREE.MathUtils.degToRad(50);
    const tilted = across.multiplyScalar(Math.cos(angle)).addScaledVector(direction, Math.sin(angle)).normalize();
    let length = 0;
    loop.forEach((w, i) => { length += this.localPoint(name, w).distanceTo(this.localPoint(name, loop[(i + 1) % loop.length])); });
    const worldScale = new THREE.Vector3().setFromMatrixScale(side.mesh.matrixWorld).x;
    const loopRadius = (length / (2 * Math.PI)) * worldScale;
    const distance = (loopRadius * 2.2) / Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2);
    controls.target.copy(centre);
    camera.position.copy(centre).addScaledVector(tilted, distance);
    camera.lookAt(centre);
    controls.update();
    this.request();
  }

  // ---- picking on the surfaces (cut tools, the brush)

  // The surface point under a pointer position: {side, vertex (raw), welded, local (hit point,
  // local), normalLocal (the hit face's normal, local)} or null.
  pickSurface(clientX, clientY) {
    if (!this.active || this.showingResult) return null;
    const { camera, renderer } = this.viewer;
    const [x, y] = ndcFromClient(clientX, clientY, renderer.domElement.getBoundingClientRect());
    camera.updateMatrixWorld();
    this.root.updateMatrixWorld(true);
    this.raycaster.setFromCamera(new THREE.Vector2(x, y), camera);
    let best = null;
    for (const side of Object.values(this.sides)) {
      if (!side.loaded || !side.mesh.visible) continue;
      const pick = side.picker.pickRay(this.raycaster.ray);
      if (pick && (!best || pick.distance < best.distance)) best = { ...pick, side: side.name };
    }
    if (!best) return null;
    const side = this.sides[best.side];
    const inverse = side.mesh.matrixWorld.clone().invert();
    const local = new THREE.Vector3().fromArray(best.hit).applyMatrix4(inverse);
    const index = side.mesh.geometry.index.array;
    const p = side.mesh.geometry.getAttribute('position');
    const corner = (k) => new THREE.Vector3().fromBufferAttribute(p, index[3 * best.face + k]);
    const a = corner(0);
    const normalLocal = corner(1).sub(a).cross(corner(2).sub(a)).normalize();
    return { side: best.side, vertex: best.vertex, welded: best.welded, local, normalLocal };
  }

  // The camera's viewing direction in a side's local coordinates (unit, from the eye).
  viewDirectionLocal(name) {
    const { camera } = this.viewer;
    camera.updateMatrixWorld();
    this.root.updateMatrixWorld(true);
    const world = camera.getWorldDirection(new THREE.Vector3());
    const inverse = this.sides[name].mesh.matrixWorld.clone().invert();
    return world.transformDirection(inverse).normalize();
  }

  // A brush target (view/brush.js): the viewer's camera and renderer with a side's mesh.
  brushTarget(name) {
    const { viewer } = this;
    const side = this.sides[name];
    return {
      get camera() { return viewer.camera; },
      get renderer() { return viewer.renderer; },
      get mesh() { return side.mesh; },
      get geometry() { return side.mesh.geometry; },
      get picker() { return side.picker; },
    };
  }

  // ---- cut previews

  // A plane through `pointLocal` with normal `normalLocal` on a side, with the gizmo on it
  // (translate or rotate); null hides it.
  showPlane(name, plane) {
    if (!plane) {
      this.planePivot.visible = false;
      if (this.gizmoKind === 'plane') this.detachGizmo();
      this.planePivot.removeFromParent();
      this.request();
      return;
    }
    const side = this.sides[name];
    side.overlay.add(this.planePivot);
    this.planePivot.position.copy(plane.point);
    this.planePivot.quaternion.setFromUnitVectors(new THREE.Vector3(0, 0, 1), plane.normal.clone().normalize());
    this.planePivot.scale.setScalar(side.radius * 0.75);
    this.planePivot.updateMatrixWorld(true);
    this.planePivot.visible = true;
    this.planeSide = name;
    this.request();
  }

  // The plane the gizmo left: {point, normal} (local to the side it is on).
  planeOf() {
    return {
      point: this.planePivot.position.clone(),
      normal: new THREE.Vector3(0, 0, 1).applyQuaternion(this.planePivot.quaternion).normalize(),
    };
  }

  showDiskCentre(name, welded) {
    this.diskMarker.removeFromParent();
    if (welded === null || welded === undefined) {
      this.diskMarker.visible = false;
      this.request();
      return;
    }
    const side = this.sides[name];
    side.overlay.add(this.diskMarker);
    this.diskMarker.position.copy(this.localPoint(name, welded));
    this.diskMarker.scale.setScalar(side.radius * 0.02);
    this.diskMarker.visible = true;
    this.request();
  }

  // ---- the gizmo: 'plane' (the cut plane) or 'place' (the source's placement)

  attachGizmo(kind, mode) {
    this.gizmoKind = kind;
    const object = kind === 'plane' ? this.planePivot : this.placePivot;
    this.gizmo.attach(object);
    this.gizmo.setMode(mode);
    this.gizmo.setSpace(kind === 'plane' ? 'local' : 'world');
    this.gizmo.enabled = this.active;
    this.gizmoHelper.visible = true;
    this.request();
  }

  setGizmoMode(mode) {
    this.gizmo.setMode(mode);
    this.request();
  }

  detachGizmo() {
    this.gizmoKind = null;
    this.gizmo.detach();
    this.gizmo.enabled = false;
    this.gizmoHelper.visible = false;
    this.viewer.controls.enabled = true;
    this.request();
  }

  // True while the pointer is over a gizmo handle or drags one (a click there is not a pick).
  gizmoBusy() {
    return Boolean(this.gizmoKind) && (this.gizmo.dragging || this.gizmo.axis !== null);
  }

  gizmoMoved() {
    if (this.gizmoKind === 'plane') {
      this.planePivot.scale.setScalar(this.sides[this.planeSide].radius * 0.75);
      this.onPlane(this.planeOf());
    } else if (this.gizmoKind === 'place') {
      // Similarities only: a non-uniform scale handle scales uniformly.
      const s = this.placePivot.scale;
      const uniform = Math.cbrt(Math.abs(s.x * s.y * s.z)) || 1;
      s.setScalar(uniform);
      this.placePivot.updateMatrix();
      const source = this.sides.source;
      this.placement.copy(this.placePivot.matrix).multiply(new THREE.Matrix4().makeTranslation(-source.center.x, -source.center.y, -source.center.z));
      this.layout();
      this.onPlacement(this.placement.toArray());
    }
    this.request();
  }

  // The placement pivot sits at the source's bounding-box centre as the placement moves it.
  resetPlacementPivot() {
    const source = this.sides.source;
    const pivot = this.placement.clone().multiply(new THREE.Matrix4().makeTranslation(source.center.x, source.center.y, source.center.z));
    pivot.decompose(this.placePivot.position, this.placePivot.quaternion, this.placePivot.scale);
    this.placePivot.updateMatrixWorld(true);
  }

  setPlacement(elements) {
    this.placement.fromArray(elements);
    this.resetPlacementPivot();
    this.layout();
  }

  // ---- the result

  // positions: Float32Array #V·3 (target coordinates), indices #F·3, zipFaces: how many of the
  // last faces are the seam, sourceOffset: first source vertex (colours the two parts).
  setResult({ positions, indices, zipFaces, sourceOffset }) {
    const geometry = new THREE.BufferGeometry();
    const count = positions.length / 3;
    const colors = new Float32Array(count * 3);
    for (let v = 0; v < count; ++v) colors.set(v < sourceOffset ? sideColors.target : sideColors.source, 3 * v);
    applyArrays(geometry, { positions, indices, colors });
    geometry.computeVertexNormals();
    this.result.geometry.dispose();
    this.result.geometry = geometry;
    const first = indices.length / 3 - zipFaces;
    const seamGeometry = new THREE.BufferGeometry();
    seamGeometry.setAttribute('position', geometry.getAttribute('position'));
    seamGeometry.setIndex(new THREE.BufferAttribute(indices.slice(3 * first), 1));
    this.seam.geometry.dispose();
    this.seam.geometry = seamGeometry;
    const edges = [];
    for (let f = first; f < indices.length / 3; ++f) {
      for (let k = 0; k < 3; ++k) edges.push(indices[3 * f + k], indices[3 * f + ((k + 1) % 3)]);
    }
    const edgeGeometry = new THREE.BufferGeometry();
    edgeGeometry.setAttribute('position', geometry.getAttribute('position'));
    edgeGeometry.setIndex(edges);
    this.seamEdges.geometry.dispose();
    this.seamEdges.geometry = edgeGeometry;
    this.resultPicker.setTarget(this.result);
    this.request();
  }

  showResult(on) {
    this.showingResult = on;
    if (on) this.detachGizmo();
    this.layout();
  }

  showSeam(on) {
    this.seam.visible = on;
    this.seamEdges.visible = on;
    this.request();
  }

  clearResult() {
    this.showingResult = false;
    this.result.geometry.dispose();
    this.result.geometry = new THREE.BufferGeometry();
    this.layout();
  }
}
