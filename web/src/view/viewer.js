// The three.js view: renderer, camera with orbit controls, lights, one mesh whose
// BufferGeometry is swapped by lib/arrays.js, vertex picking on it (picking.js) and overlay
// markers (marker.js). Renders on demand (controls change, geometry change, resize) instead
// of every frame, so an idle page costs nothing and headless tests on a software GPU stay fast.
import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { applyArrays } from '../lib/arrays.js';
import { VertexMarker } from './marker.js';
import { VertexPicker, ndcFromClient } from './picking.js';

export const backgroundColor = 0x1d2230;
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

    // Hemisphere light for a soft ambient term, a key light that follows the camera (the
    // side the user looks at is always lit) and a rim light from behind for silhouettes.
    this.scene.add(new THREE.HemisphereLight(0xf2f4ff, 0x3a3530, 1.0));
    const key = new THREE.DirectionalLight(0xffffff, 1.6);
    key.position.set(0.6, 0.8, 1);
    this.camera.add(key);
    const rim = new THREE.DirectionalLight(0xbfd4ff, 0.7);
    rim.position.set(-0.5, 0.3, -1);
    this.camera.add(rim);
    this.scene.add(this.camera);

    this.material = new THREE.MeshStandardMaterial({
      color: surfaceColor, roughness: 0.62, metalness: 0.0, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.wireMaterial = new THREE.MeshBasicMaterial({ color: 0x10131a, wireframe: true, transparent: true, opacity: 0.35 });
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
    this.controls.addEventListener('change', () => this.requestRender());

    this.frames = 0;  // rendered frames (tests wait for this to advance)
    this.pendingFrame = false;
    new ResizeObserver(() => this.resize()).observe(canvas);
    this.resize();
  }

  resize() {
    const canvas = this.renderer.domElement;
    const width = canvas.clientWidth || 1;
    const height = canvas.clientHeight || 1;
    this.renderer.setSize(width, height, false);
    this.camera.aspect = width / height;
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  requestRender() {
    if (this.pendingFrame) return;
    this.pendingFrame = true;
    requestAnimationFrame(() => {
      this.pendingFrame = false;
      this.renderer.render(this.scene, this.camera);
      this.frames += 1;
    });
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
    const geometry = new THREE.BufferGeometry();
    applyArrays(geometry, { positions, normals, indices });
    if (!normals) geometry.computeVertexNormals();
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
    const schedule = window.requestIdleCallback || ((fn) => setTimeout(fn, 0));
    schedule(() => {
      if (this.geometry === geometry) this.picker.ensureBvh();
    });
  }

  // The vertex under a pointer position (clientX/clientY, as in mouse events) or null; see
  // picking.js for the result. Null while the mesh is hidden (setMainVisible).
  pickAt(clientX, clientY) {
    if (!this.geometry.getAttribute('position') || !this.mesh.visible) return null;
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
  setPositions(positions) {
    applyArrays(this.geometry, { positions });
    this.geometry.computeVertexNormals();
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
  frameMeshes(meshes, { direction: viewDirection = [0.35, 0.25, 1] } = {}) {
    const box = new THREE.Box3();
    for (const mesh of meshes) {
      if (!mesh.geometry.boundingBox) continue;
      mesh.updateMatrixWorld();
      box.union(mesh.geometry.boundingBox.clone().applyMatrix4(mesh.matrixWorld));
    }
    if (box.isEmpty()) return;
    const radius = box.getSize(new THREE.Vector3()).length() / 2;
    if (!(radius > 0)) return;
    const tanY = Math.tan(THREE.MathUtils.degToRad(this.camera.fov) / 2) * 0.85;
    const tanX = tanY * this.camera.aspect;
    const direction = new THREE.Vector3(...viewDirection).normalize();
    const center = box.getCenter(new THREE.Vector3());
    // Start from the box's sphere distance, then move along the view axis until every vertex
    // is inside the (shrunk) frustum: a point at camera-space (x, y, z) needs depth
    // max(|x|/tanX, |y|/tanY), and moving back by Δ adds Δ to every depth.
    let distance = radius / Math.sin(Math.atan(Math.min(tanX, tanY)));
    this.camera.position.copy(center).addScaledVector(direction, distance);
    this.camera.lookAt(center);
    this.camera.updateMatrixWorld();
    let shift = -Infinity;
    for (const mesh of meshes) {
      const position = mesh.geometry.getAttribute('position');
      if (!position) continue;
      const m = new THREE.Matrix4().multiplyMatrices(this.camera.matrixWorldInverse, mesh.matrixWorld).elements;
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
    this.camera.near = distance / 100;
    this.camera.far = distance * 20;
    this.controls.maxDistance = distance * 8;
    this.camera.position.copy(center).addScaledVector(direction, distance);
    this.camera.updateProjectionMatrix();
    this.controls.target.copy(center);
    this.controls.update();
    this.requestRender();
  }
}
