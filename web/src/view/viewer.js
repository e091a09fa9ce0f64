// The three.js view: renderer, camera with orbit controls, lights, one mesh whose
// BufferGeometry is swapped by lib/arrays.js, vertex picking on it (picking.js) and overlay
// markers (marker.js). Renders on demand (controls change, geometry change, resize) instead
// of every frame, so an idle page costs nothing and headless tests on a software GPU stay fast.
//
// Materials: the plain analysis material (vertex colours for eigenfunctions and edit sets) or
// the loaded glTF document's own materials and textures (view/document-materials.js, on the
// raw layout the worker sends), chosen with setMaterialMode; colours always use the analysis
// material.
// Panes: one camera over the whole canvas, or two side by side (setSplit: a second camera
// with its own orbit controls, linked to the first or not; view/pair-view.js uses it for the
// Transfer job). The camera reframes what it framed last when the canvas changes size.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { applyArrays } from '../lib/arrays.js';
import { disposeDocumentMaterials } from './document-materials.js';
import { VertexMarker } from './marker.js';
import { VertexPicker, ndcFromClient } from './picking.js';

export const backgroundColor = 0x1d2230;
// Above this many displayed vertices the picking BVH is not built: its build (seconds on the
// main thread for a million vertices) would freeze the page.
export const maxPickVertices = 400000;
const surfaceColor = 0xc9cfd8;

export class Viewer {
  constructor(canvas) {
    // preserveDrawingBuffer keeps the last frame readable (screenshots, e2e pixel checks,
    // drawImage) at a small cost that does not matter for a single mesh.
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio, 2));
    this.renderer.setClearColor(backgroundColor);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.01, 100);
    this.camera2 = new THREE.PerspectiveCamera(40, 1, 0.01, 100); // the right pane (split)

    // Hemisphere light for a soft ambient term, a key light that follows the camera (the
    // side the user looks at is always lit) and a rim light from behind for silhouettes.
    // Each camera has its own pair; the second pair is on only while its pane is drawn.
    this.scene.add(new THREE.HemisphereLight(0xf2f4ff, 0x3a3530, 1.0));
    this.cameraLights = [this.camera, this.camera2].map((camera) => {
      const key = new THREE.DirectionalLight(0xffffff, 1.6);
      key.position.set(0.6, 0.8, 1);
      const rim = new THREE.DirectionalLight(0xbfd4ff, 0.7);
      rim.position.set(-0.5, 0.3, -1);
      camera.add(key, rim);
      this.scene.add(camera);
      return [key, rim];
    });
    for (const light of this.cameraLights[1]) light.visible = false;

    this.material = new THREE.MeshStandardMaterial({
      color: surfaceColor, roughness: 0.62, metalness: 0.0, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.wireMaterial = new THREE.MeshBasicMaterial({ color: 0x10131a, wireframe: true, transparent: true, opacity: 0.35 });
    this.analysisMaterial = this.material;
    this.document = null;          // document-materials.js result for the shown mesh, or null
    this.materialMode = 'document'; // 'document' (when there is one) or 'analysis'
    this.geometry = new THREE.BufferGeometry();
    this.mesh = new THREE.Mesh(this.geometry, this.material);
    this.wire = new THREE.Mesh(this.geometry, this.wireMaterial);
    this.wire.visible = false;
    this.scene.add(this.mesh, this.wire);
    this.overlays = new THREE.Group(); // markers and other helpers drawn over the mesh
    this.scene.add(this.overlays);
    this.markers = [];
    this.picker = new VertexPicker();
    this.toWelded = null; // raw → welded vertex map of the shown mesh, when known

    this.controls = new OrbitControls(this.camera, canvas);
    this.controls.enableDamping = false;
    this.controls.addEventListener('change', () => this.cameraMoved(0));
    this.controls2 = new OrbitControls(this.camera2, canvas);
    this.controls2.enableDamping = false;
    this.controls2.enabled = false;
    this.controls2.addEventListener('change', () => this.cameraMoved(1));
    this.split = null;   // {linked, beforePass(i), afterPasses()} while two panes are shown
    this.framing = [null, null]; // per pane: the meshes it framed last (resize reframes them)
    this.beforeRender = new Set(); // fns called before each frame (e.g. label occlusion)
    // In split view the pane under the pointer gets the orbit controls (capture phase: before
    // OrbitControls sees the event).
    const route = (e) => {
      if (!this.split) return;
      const right = e.clientX >= this.paneRect(1).left;
      this.controls.enabled = !right;
      this.controls2.enabled = right;
    };
    canvas.parentElement.addEventListener('pointerdown', route, true);
    canvas.parentElement.addEventListener('wheel', route, { capture: true, passive: true });

    this.frames = 0;  // rendered frames (tests wait for this to advance)
    this.pendingFrame = false;
    this.size = { width: 0, height: 0 };
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
  }

  resize() {
    const canvas = this.renderer.domElement;
    const width = canvas.clientWidth || 1;
    const height = canvas.clientHeight || 1;
    const changed = width !== this.size.width || height !== this.size.height;
    this.size = { width, height };
    this.renderer.setSize(width, height, false);
    this.updateAspects();
    // The camera reframes what it showed (keeping its direction) when the view changes size.
    if (changed) this.reframe();
    this.requestRender();
  }

  updateAspects() {
    const { width, height } = this.size;
    const paneWidth = this.split ? width / 2 : width;
    for (const camera of [this.camera, this.camera2]) {
      camera.aspect = paneWidth / height;
      camera.updateProjectionMatrix();
    }
  }

  // Frames again what each pane framed last, looking from where its camera looks now.
  reframe() {
    for (const pane of this.split ? [0, 1] : [0]) {
      const framed = this.framing[pane];
      if (!framed) continue;
      const camera = pane ? this.camera2 : this.camera;
      const controls = pane ? this.controls2 : this.controls;
      const direction = camera.position.clone().sub(controls.target);
      if (!(direction.lengthSq() > 0)) continue;
      this.frameMeshes(framed.meshes, { direction: direction.toArray(), pane });
    }
  }

  // The client rectangle of pane i (the whole canvas when not split).
  paneRect(i = 0) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    if (!this.split) return rect;
    const width = rect.width / 2;
    return { left: rect.left + i * width, top: rect.top, width, height: rect.height, right: rect.left + (i + 1) * width, bottom: rect.bottom };
  }

  paneCamera(i = 0) { return i ? this.camera2 : this.camera; }

  // Two panes (config {linked, beforePass(i), afterPasses()}) or one (null). The second camera
  // starts where the first one is.
  setSplit(config) {
    this.split = config;
    if (config) {
      this.camera2.position.copy(this.camera.position);
      this.camera2.quaternion.copy(this.camera.quaternion);
      this.controls2.target.copy(this.controls.target);
      this.controls2.update();
    } else {
      this.controls.enabled = true;
      this.controls2.enabled = false;
    }
    this.updateAspects();
    this.requestRender();
  }

  // A camera moved (its orbit controls): linked panes follow it.
  cameraMoved(pane) {
    if (this.split?.linked && !this.syncing) {
      this.syncing = true;
      const [from, to] = pane ? [this.camera2, this.camera] : [this.camera, this.camera2];
      const [fromControls, toControls] = pane ? [this.controls2, this.controls] : [this.controls, this.controls2];
      to.position.copy(from.position);
      to.quaternion.copy(from.quaternion);
      to.near = from.near;
      to.far = from.far;
      to.updateProjectionMatrix();
      toControls.target.copy(fromControls.target);
      toControls.update();
      this.syncing = false;
    }
    this.requestRender();
  }

  requestRender() {
    if (this.pendingFrame) return;
    this.pendingFrame = true;
    requestAnimationFrame(() => {
      this.pendingFrame = false;
      this.render();
      this.frames += 1;
    });
  }

  render() {
    for (const fn of this.beforeRender) fn();
    const { renderer } = this;
    if (!this.split) {
      renderer.setScissorTest(false);
      renderer.setViewport(0, 0, this.size.width, this.size.height);
      renderer.render(this.scene, this.camera);
      return;
    }
    const half = this.size.width / 2;
    renderer.setScissorTest(true);
    for (const i of [0, 1]) {
      renderer.setViewport(i * half, 0, half, this.size.height);
      renderer.setScissor(i * half, 0, half, this.size.height);
      for (const [pane, lights] of this.cameraLights.entries()) for (const light of lights) light.visible = pane === i;
      this.split.beforePass?.(i);
      renderer.render(this.scene, this.paneCamera(i));
    }
    this.split.afterPasses?.();
    for (const [pane, lights] of this.cameraLights.entries()) for (const light of lights) light.visible = pane === 0;
    renderer.setScissorTest(false);
  }

  // A new mesh: positions/normals/indices (+ toWelded, the raw → welded vertex map) from the
  // worker's load result. Replaces the geometry (sizes differ), frames the camera on it,
  // hides the markers and points picking at the new geometry (its BVH is rebuilt on the next
  // pick).
  // `open`: the surface has boundaries, so its inside can be seen and back faces are drawn
  // (on closed meshes they only add dark speckles along silhouettes).
  setMesh({ positions, normals, indices, toWelded = null }, { open = true } = {}) {
    this.material.side = open ? THREE.DoubleSide : THREE.FrontSide;
    this.material.needsUpdate = true;
    this.mesh.userData.pickSide = this.material.side;
    disposeDocumentMaterials(this.document);
    this.document = null;
    const geometry = new THREE.BufferGeometry();
    applyArrays(geometry, { positions, normals, indices });
    if (!normals) geometry.computeVertexNormals();
    this.mesh.material = this.material;
    this.mesh.geometry = geometry;
    this.wire.geometry = geometry;
    this.geometry.dispose();
    this.geometry = geometry;
    this.toWelded = toWelded;
    this.picker.setTarget(this.mesh, { toWelded });
    const radius = geometry.boundingSphere?.radius || 1;
    for (const marker of this.markers) {
      marker.setSize(radius * 0.012);
      marker.hide();
    }
    this.setColors(null);
    this.frame();
    // Build the picking BVH when the page is idle (~0.1–0.3 s for 50k vertices), not on the
    // first hover; a pick before that builds it itself.
    this.pickable = positions.length / 3 <= maxPickVertices;
    if (!this.pickable) return;
    const schedule = window.requestIdleCallback || ((fn) => setTimeout(fn, 0));
    schedule(() => {
      if (this.geometry === geometry) this.picker.ensureBvh();
    });
  }

  // The vertex under a pointer position (clientX/clientY, as in mouse events) or null; see
  // picking.js for the result. Null while the mesh is hidden (setMainVisible).
  // The document's materials for the shown mesh (document-materials.js result; it must belong
  // to the current geometry): texture coordinates and one group per primitive.
  setDocumentMaterials(display) {
    disposeDocumentMaterials(this.document);
    this.document = display;
    if (display.uv) this.geometry.setAttribute('uv', new THREE.BufferAttribute(display.uv, 2));
    if (display.uv1) this.geometry.setAttribute('uv1', new THREE.BufferAttribute(display.uv1, 2));
    this.geometry.clearGroups();
    for (const g of display.groups) this.geometry.addGroup(g.start, g.count, g.materialIndex);
    this.applyMaterial();
  }

  // 'document' (the file's own materials, when it has them) or 'analysis' (plain surface).
  setMaterialMode(mode) {
    this.materialMode = mode;
    this.applyMaterial();
  }

  // What the mesh is drawn with now: 'document' or 'analysis'.
  get shownMaterial() {
    return this.mesh.material === this.material ? 'analysis' : 'document';
  }

  applyMaterial() {
    const useDocument = this.materialMode === 'document' && this.document && !this.material.vertexColors;
    this.mesh.material = useDocument ? this.document.materials : this.material;
    this.requestRender();
  }

  pickAt(clientX, clientY) {
    if (!this.geometry.getAttribute('position') || !this.mesh.visible || !this.pickable) return null;
    const [x, y] = ndcFromClient(clientX, clientY, this.renderer.domElement.getBoundingClientRect());
    this.camera.updateMatrixWorld();
    return this.picker.pickNdc(x, y, this.camera);
  }

  // A marker (small sphere) for a vertex, sized to the current mesh; hidden until shown.
  createMarker({ color }) {
    const marker = new VertexMarker({ color, onChange: () => this.requestRender() });
    marker.setSize((this.geometry.boundingSphere?.radius || 1) * 0.012);
    this.markers.push(marker);
    this.overlays.add(marker.object);
    return marker;
  }

  // New positions for the shown mesh (#R·3, raw layout; same triangles), e.g. an edit preview:
  // updated in place, normals recomputed, the picking BVH refitted at the next pick.
  // `normals` (same layout) when the caller has them (the worker computes them for edits).
  setPositions(positions, normals = null) {
    applyArrays(this.geometry, { positions, normals });
    if (!normals) this.geometry.computeVertexNormals();
    this.picker.refitLater();
    this.requestRender();
  }

  // Per-vertex colours (#R·3 in 0..1, raw layout) or null for the plain surface.
  setColors(colors) {
    applyArrays(this.geometry, { colors });
    const useColors = Boolean(colors);
    if (this.material.vertexColors !== useColors) {
      this.material.vertexColors = useColors;
      this.material.color.set(useColors ? 0xffffff : surfaceColor);
      this.material.needsUpdate = true;
      this.applyMaterial(); // colours are drawn with the analysis material
    }
    this.requestRender();
  }

  setWireframe(on) {
    this.wireframe = on;
    this.wire.visible = on && this.mesh.visible;
    this.requestRender();
  }

  // Shows or hides the loaded mesh, its wireframe and the overlays (markers): a job that shows
  // other meshes in the scene (ui/panels/transfer.js) hides them while it is shown.
  setMainVisible(on) {
    this.mesh.visible = on;
    this.wire.visible = on && Boolean(this.wireframe);
    this.overlays.visible = on;
    this.requestRender();
  }

  // Looks at the mesh from the front, slightly above, at the distance where it fills ~85% of
  // the narrower side of the view. The fit uses the vertices themselves: a bounding sphere or
  // box seen obliquely frames most shapes far too small.
  frame() {
    this.frameMeshes([this.mesh]);
  }

  // The same for several meshes at once (each with its own placement, e.g. two meshes side by
  // side): the camera looks at the centre of their world-space bounding box, from `direction`
  // ([x, y, z], default front right, slightly above).
  // `pane`: which camera (0, or 1 = the right pane in split view).
  frameMeshes(meshes, { direction: viewDirection = [0.35, 0.25, 1], pane = 0 } = {}) {
    const camera = this.paneCamera(pane);
    const controls = pane ? this.controls2 : this.controls;
    this.framing[pane] = { meshes };
    const box = new THREE.Box3();
    for (const mesh of meshes) {
      if (!mesh.geometry.boundingBox) continue;
      mesh.updateMatrixWorld();
      box.union(mesh.geometry.boundingBox.clone().applyMatrix4(mesh.matrixWorld));
    }
    if (box.isEmpty()) return;
    const radius = box.getSize(new THREE.Vector3()).length() / 2;
    if (!(radius > 0)) return;
    const tanY = Math.tan(THREE.MathUtils.degToRad(camera.fov) / 2) * 0.85;
    const tanX = tanY * camera.aspect;
    const direction = new THREE.Vector3(...viewDirection).normalize();
    const center = box.getCenter(new THREE.Vector3());
    // Start from the box's sphere distance, then move along the view axis until every vertex
    // is inside the (shrunk) frustum: a point at camera-space (x, y, z) needs depth
    // max(|x|/tanX, |y|/tanY), and moving back by Δ adds Δ to every depth.
    let distance = radius / Math.sin(Math.atan(Math.min(tanX, tanY)));
    camera.position.copy(center).addScaledVector(direction, distance);
    camera.lookAt(center);
    camera.updateMatrixWorld();
    let shift = -Infinity;
    for (const mesh of meshes) {
      const position = mesh.geometry.getAttribute('position');
      if (!position) continue;
      const m = new THREE.Matrix4().multiplyMatrices(camera.matrixWorldInverse, mesh.matrixWorld).elements;
      const p = position.array;
      for (let i = 0; i < p.length; i += 3) {
        const x = m[0] * p[i] + m[4] * p[i + 1] + m[8] * p[i + 2] + m[12];
        const y = m[1] * p[i] + m[5] * p[i + 1] + m[9] * p[i + 2] + m[13];
        const z = m[2] * p[i] + m[6] * p[i + 1] + m[10] * p[i + 2] + m[14];
        const need = Math.max(Math.abs(x) / tanX, Math.abs(y) / tanY) + z;
        if (need > shift) shift = need;
      }
    }
    distance += shift;
    // Clip planes and zoom range follow the mesh's scale (files come in mm or in m).
    camera.near = distance / 100;
    camera.far = distance * 20;
    controls.maxDistance = distance * 8;
    camera.position.copy(center).addScaledVector(direction, distance);
    camera.updateProjectionMatrix();
    controls.target.copy(center);
    controls.update();
    this.requestRender();
  }
}
