// The Retarget job's scene (ui/panels/retarget.js): the source character (the glTF scene as
// three.js loads it, posed by an AnimationMixer at the clip time) and the target (the
// retargeted surface, its positions swapped per frame; or an animated GLB played by its own
// mixer), side by side in one pane or in two split panes (Viewer.setSplit, linked cameras or
// not). The target can be drawn see-through with its joints (spheres) and bones (lines) over it.
// Each side is scaled to the same display height and stands on the same floor; its placement is
// fixed from its rest pose, so root motion shows.
import * as THREE from 'three';
import { JointFollower } from '../lib/retarget-joints.js';
import { insideTest, lastInside } from './inside.js';

const sphere = new THREE.SphereGeometry(1, 14, 10);
const gap = 0.35; // between the two characters, in display heights
const targetColor = 0xd8cdbf;

// A box's 8 corners as a mesh: Viewer.frameMeshes frames meshes by their vertices.
function boxProxy(box) {
  const geometry = new THREE.BufferGeometry();
  const p = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) p.push(x, y, z);
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(p, 3));
  geometry.computeBoundingBox();
  const mesh = new THREE.Mesh(geometry);
  mesh.visible = false;
  return mesh;
}

function createSide(name) {
  const root = new THREE.Group(); // display placement (scale, offset)
  root.name = `retarget-${name}`;
  return { name, root, box: null, proxy: null, loaded: false };
}

export class RetargetView {
  constructor(viewer) {
    this.viewer = viewer;
    this.group = new THREE.Group();
    this.group.visible = false;
    viewer.scene.add(this.group);
    this.sides = { source: createSide('source'), target: createSide('target') };
    this.group.add(this.sides.source.root, this.sides.target.root);
    this.mode = 'side';
    this.linked = true;
    // Source: the glTF scene, its mixer and the playing action.
    this.source = { scene: null, mixer: null, action: null };
    // Target: the surface mesh (positions swapped per frame) or a played GLB.
    this.targetMaterial = new THREE.MeshStandardMaterial({
      color: targetColor, roughness: 0.62, metalness: 0, side: THREE.DoubleSide,
      polygonOffset: true, polygonOffsetFactor: 1, polygonOffsetUnits: 1,
    });
    this.targetMesh = new THREE.Mesh(new THREE.BufferGeometry(), this.targetMaterial);
    this.targetMesh.name = 'retarget-target-surface';
    this.targetMesh.visible = false;
    this.sides.target.root.add(this.targetMesh);
    this.played = null; // {scene, mixer, action, duration} of an opened animated GLB
    // Joints overlay (children of the target side: target coordinates).
    this.jointGroup = new THREE.Group();
    this.jointGroup.renderOrder = 2;
    this.sides.target.root.add(this.jointGroup);
    this.jointMaterial = new THREE.MeshBasicMaterial({ color: 0xffd23f, depthTest: false, transparent: true });
    this.boneMaterial = new THREE.LineBasicMaterial({ color: 0x39e6a0, depthTest: false, transparent: true });
    this.pinnedMaterial = new THREE.MeshBasicMaterial({ color: 0xff4f6d, depthTest: false, transparent: true });
    // Context-graph overlay: line and point sets on each side (source sets in the glTF scene's
    // space, target sets in target coordinates).
    this.graphGroups = { source: new THREE.Group(), target: new THREE.Group() };
    for (const [name, g] of Object.entries(this.graphGroups)) {
      g.visible = false;
      this.sides[name].root.add(g);
    }
    this.graph = [];
    this.joints = { spheres: [], lines: null, bones: [], count: 0 };
    this.dragging = -1; // the joint being dragged
    this.seeThrough = false;
  }

  get active() { return this.group.visible; }

  setActive(on) {
    if (this.group.visible === on) return;
    this.group.visible = on;
    this.viewer.setMainVisible(!on);
    this.applySplit();
    if (on) this.frame();
    this.viewer.requestRender();
  }

  // 'side' | 'split'; linked: the split panes' cameras move together.
  setMode(mode, { linked = this.linked } = {}) {
    const changed = mode !== this.mode;
    this.mode = mode;
    this.linked = linked;
    this.layout();
    this.applySplit();
    if (changed) this.frame();
    this.viewer.requestRender();
  }

  applySplit() {
    const { viewer } = this;
    if (!(this.active && this.mode === 'split')) {
      if (viewer.split) viewer.setSplit(null);
      return;
    }
    const { source, target } = this.sides;
    viewer.setSplit({
      linked: this.linked,
      beforePass: (i) => { source.root.visible = i === 0; target.root.visible = i === 1; },
      afterPasses: () => { source.root.visible = true; target.root.visible = true; },
    });
  }

  // ---- source

  // gltf: GLTFLoader's result (its scene is added here: do not add it elsewhere). The rest
  // box is measured at time 0 of `clipIndex` (or the bind pose without clips).
  setSource(gltf, clipIndex = 0) {
    const side = this.sides.source;
    if (this.source.scene) side.root.remove(this.source.scene);
    this.source.mixer?.stopAllAction();
    this.source = { scene: gltf.scene, mixer: new THREE.AnimationMixer(gltf.scene), action: null, clips: gltf.animations };
    side.root.add(gltf.scene);
    this.setClip(clipIndex);
    this.measure('source');
  }

  setClip(index) {
    const { mixer, clips } = this.source;
    if (!mixer) return;
    mixer.stopAllAction();
    this.source.action = null;
    const clip = clips[index];
    if (clip) {
      this.source.action = mixer.clipAction(clip);
      this.source.action.play();
    }
    mixer.setTime(0);
    this.viewer.requestRender();
  }

  // The source at clip time t (seconds).
  setSourceTime(t) {
    if (!this.source.mixer || !this.source.action) return;
    this.source.mixer.setTime(t);
  }

  // ---- target

  // The target surface: {positions (#V·3), indices}; replaces a played GLB.
  setTargetMesh({ positions, indices }) {
    this.clearPlayed();
    const geometry = new THREE.BufferGeometry();
    geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(positions), 3));
    geometry.setIndex(new THREE.BufferAttribute(indices instanceof Uint32Array ? indices : Uint32Array.from(indices), 1));
    geometry.computeVertexNormals();
    geometry.computeBoundingBox();
    geometry.computeBoundingSphere();
    this.targetMesh.geometry.dispose();
    this.targetMesh.geometry = geometry;
    this.targetMesh.visible = true;
    this.measure('target', geometry.boundingBox.clone());
  }

  // New target positions (same vertices): a frame of the retargeted clip.
  setTargetPositions(positions) {
    const attribute = this.targetMesh.geometry.getAttribute('position');
    if (!attribute || attribute.array.length !== positions.length) return;
    attribute.array.set(positions);
    attribute.needsUpdate = true;
    this.targetMesh.geometry.computeVertexNormals();
    this.viewer.requestRender();
  }

  targetPositions() {
    return this.targetMesh.geometry.getAttribute('position')?.array ?? null;
  }

  // See-through target (joints and bones show over it).
  setSeeThrough(on) {
    this.seeThrough = on;
    const m = this.targetMaterial;
    m.transparent = on;
    m.opacity = on ? 0.35 : 1;
    m.depthWrite = !on;
    m.needsUpdate = true;
    this.viewer.requestRender();
  }

  // Joints (Float32Array or [x,y,z][] in target coordinates) and bones ([child, parent]).
  setJoints(positions, bones = []) {
    this.clearJoints();
    const flat = Array.isArray(positions) ? positions.flat() : Array.from(positions);
    const count = flat.length / 3;
    const box = this.sides.target.box;
    const size = box ? box.getSize(new THREE.Vector3()).y || box.getSize(new THREE.Vector3()).length() : 1;
    const radius = 0.012 * size;
    // Pins stay red when the same joints are drawn again (a new run redraws them).
    const pinned = this.pinned ?? new Set();
    for (let j = 0; j < count; ++j) {
      const s = new THREE.Mesh(sphere, pinned.has(j) ? this.pinnedMaterial : this.jointMaterial);
      s.scale.setScalar(radius);
      s.renderOrder = 3;
      this.jointGroup.add(s);
      this.joints.spheres.push(s);
    }
    const lineGeometry = new THREE.BufferGeometry();
    lineGeometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(bones.length * 6), 3));
    this.joints.lines = new THREE.LineSegments(lineGeometry, this.boneMaterial);
    this.joints.lines.renderOrder = 2;
    this.joints.lines.frustumCulled = false;
    this.jointGroup.add(this.joints.lines);
    this.joints.bones = bones;
    this.joints.count = count;
    this.moveJoints(flat);
  }

  // New joint positions (same joints): the joints following a frame.
  moveJoints(flat) {
    const { spheres, lines, bones } = this.joints;
    spheres.forEach((s, j) => s.position.set(flat[3 * j], flat[3 * j + 1], flat[3 * j + 2]));
    if (lines) {
      const p = lines.geometry.getAttribute('position');
      bones.forEach(([a, b], i) => {
        p.setXYZ(2 * i, flat[3 * a], flat[3 * a + 1], flat[3 * a + 2]);
        p.setXYZ(2 * i + 1, flat[3 * b], flat[3 * b + 1], flat[3 * b + 2]);
      });
      p.needsUpdate = true;
    }
    this.viewer.requestRender();
  }

  // The context graph: sets {positions (#P·3), lines (#L·2, empty = points), color [r, g, b, a],
  // source (true: over the source, in the glTF scene's space at the bind pose; else over the
  // target, in target coordinates)}.
  setGraph(sets) {
    this.clearGraph();
    for (const set of sets) {
      const geometry = new THREE.BufferGeometry();
      geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(set.positions), 3));
      const color = new THREE.Color(set.color[0], set.color[1], set.color[2]);
      const common = { color, transparent: true, opacity: set.color[3] ?? 1, depthTest: false };
      let object;
      if (set.lines.length) {
        geometry.setIndex(new THREE.BufferAttribute(Uint32Array.from(set.lines), 1));
        object = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial(common));
      } else {
        object = new THREE.Points(geometry, new THREE.PointsMaterial({ ...common, size: 5, sizeAttenuation: false }));
      }
      object.renderOrder = 2;
      object.frustumCulled = false;
      object.userData.side = set.source ? 'source' : 'target';
      this.graphGroups[object.userData.side].add(object);
      this.graph.push(object);
    }
    this.viewer.requestRender();
  }

  // New positions of graph set i (the nodes following a frame).
  moveGraph(i, positions) {
    const a = this.graph[i]?.geometry.getAttribute('position');
    if (!a || a.array.length !== positions.length) return;
    a.array.set(positions);
    a.needsUpdate = true;
  }

  clearGraph() {
    for (const o of this.graph) {
      o.parent?.remove(o);
      o.geometry.dispose();
      o.material.dispose();
    }
    this.graph = [];
    this.viewer.requestRender();
  }

  setGraphVisible(on) {
    for (const g of Object.values(this.graphGroups)) g.visible = on;
    this.viewer.requestRender();
  }

  // The source's skinned vertices at the bind pose (bindMatrix · v: the glTF scene's space) and
  // their triangles, built once per source scene (every overlay set's follower uses them).
  sourceBindPose() {
    const scene = this.source.scene;
    if (this.bindPose?.scene === scene) return this.bindPose;
    const meshes = [];
    scene?.traverse((o) => { if (o.isSkinnedMesh) meshes.push(o); });
    const refs = [];
    const rest = [];
    const triangles = [];
    const v = new THREE.Vector3();
    for (const mesh of meshes) {
      const p = mesh.geometry.getAttribute('position');
      const base = refs.length;
      for (let i = 0; i < p.count; ++i) {
        v.fromBufferAttribute(p, i).applyMatrix4(mesh.bindMatrix);
        rest.push(v.x, v.y, v.z);
        refs.push([mesh, i]);
      }
      const index = mesh.geometry.index;
      const vertex = (q) => new THREE.Vector3(rest[3 * (base + q)], rest[3 * (base + q) + 1], rest[3 * (base + q) + 2]);
      const n = index ? index.count : p.count;
      for (let t = 0; t + 2 < n; t += 3) {
        const [a, b, c] = [t, t + 1, t + 2].map((q) => (index ? index.getX(q) : q));
        triangles.push(new THREE.Triangle(vertex(a), vertex(b), vertex(c)));
      }
    }
    this.bindPose = { scene, meshes, refs, rest: Float32Array.from(rest), triangles };
    return this.bindPose;
  }

  // Points on the source (the glTF scene's space at the bind pose: the core's source units) made
  // to follow the playing clip: each keeps its offset from the mean of its k nearest skinned
  // vertices at the bind pose (lib/retarget-joints.js JointFollower) and moves with their skinned
  // positions. Returns {at() → Float32Array #P·3 for the pose shown, gap: the largest distance
  // from a point to the bind-pose surface} or null (no skinned mesh).
  sourceFollower(points, k = 4) {
    const { refs, rest, triangles } = this.sourceBindPose();
    const v = new THREE.Vector3();
    if (!refs.length || !points.length) return null;
    const follower = new JointFollower(rest, points, k);
    const used = [...new Set(follower.near.flat())];
    const current = new Float32Array(rest.length); // only the `used` vertices are read
    // gap: the farthest point from the bind-pose surface (its triangles), a check that the
    // points and this surface share units (the core's nodes lie on its source surface).
    let gap = 0;
    const q = new THREE.Vector3();
    const onSurface = new THREE.Vector3();
    for (const p of points) {
      q.set(p[0], p[1], p[2]);
      let best = Infinity;
      for (const tri of triangles) best = Math.min(best, tri.closestPointToPoint(q, onSurface).distanceToSquared(q));
      gap = Math.max(gap, Math.sqrt(best));
    }
    const root = this.sides.source.root;
    const inverse = new THREE.Matrix4();
    return {
      gap,
      at: () => {
        root.updateMatrixWorld(true);
        inverse.copy(root.matrixWorld).invert();
        for (const u of used) {
          const [mesh, i] = refs[u];
          mesh.getVertexPosition(i, v).applyMatrix4(mesh.matrixWorld).applyMatrix4(inverse);
          current[3 * u] = v.x;
          current[3 * u + 1] = v.y;
          current[3 * u + 2] = v.z;
        }
        return follower.at(current);
      },
    };
  }

  // Pinned joints (indices) drawn in their own colour.
  setPinned(indices) {
    const pinned = new Set(indices);
    this.pinned = pinned;
    this.joints.spheres.forEach((s, j) => { s.material = pinned.has(j) ? this.pinnedMaterial : this.jointMaterial; });
    this.viewer.requestRender();
  }

  // Joint spheres the person can drag with the primary button (the orbit controls do not see
  // that press). The joint moves in the plane through it facing the camera and stays inside the
  // target: where the pointer leaves the mesh, the joint stops at the surface (inside.js);
  // onDrop(j, [x, y, z]) in target coordinates when the button goes up. canDrag() says whether
  // dragging is on now.
  // Returns a function that detaches the listeners.
  attachJointDrag({ canDrag = () => true, onDrop = () => {} }) {
    const canvas = this.viewer.renderer.domElement;
    const parent = canvas.parentElement;
    let drag = null; // {j, plane, flat, pointerId}
    const local = (clientX, clientY) => {
      const hit = this.targetRay(clientX, clientY).ray.intersectPlane(drag.plane, new THREE.Vector3());
      return hit ? hit.applyMatrix4(this.sides.target.root.matrixWorld.clone().invert()) : null;
    };
    const down = (e) => {
      if (e.button !== 0 || !this.active || !this.jointGroup.visible || !canDrag()) return;
      const j = this.jointAt(e.clientX, e.clientY);
      if (j < 0) return;
      e.stopPropagation();
      e.preventDefault();
      const { camera } = this.view('target');
      const world = this.joints.spheres[j].getWorldPosition(new THREE.Vector3());
      const normal = camera.getWorldDirection(new THREE.Vector3());
      const flat = this.joints.spheres.flatMap((s) => s.position.toArray());
      // The inside test of the rest surface (drags happen in the rest pose), built once per target
      // surface: tens of ms at 50k faces.
      if (!this.insideCache || this.insideCache.geometry !== this.targetMesh.geometry) {
        const g = this.targetMesh.geometry;
        this.insideCache = { geometry: g, inside: insideTest(g.getAttribute('position').array, g.index.array) };
      }
      const start = this.joints.spheres[j].position.clone();
      const inside = this.insideCache.inside;
      drag = {
        j, plane: new THREE.Plane().setFromNormalAndCoplanarPoint(normal, world), flat, pointerId: e.pointerId,
        inside, last: inside(start) ? start : null,
      };
      this.dragging = j;
      window.addEventListener('pointermove', move, true);
      window.addEventListener('pointerup', up, true);
    };
    const move = (e) => {
      if (!drag || e.pointerId !== drag.pointerId) return;
      e.stopPropagation();
      let p = local(e.clientX, e.clientY);
      if (!p) return;
      // Keep the joint inside: past the surface it stops where the segment from its last inside
      // position leaves the mesh (a joint that started outside moves freely until it is in).
      if (drag.inside(p)) drag.last = p.clone();
      else if (drag.last) p = lastInside(drag.inside, drag.last, p);
      drag.flat.splice(3 * drag.j, 3, p.x, p.y, p.z);
      this.moveJoints(drag.flat);
    };
    const up = (e) => {
      if (!drag || e.pointerId !== drag.pointerId) return;
      e.stopPropagation();
      const { j, flat } = drag;
      drag = null;
      this.dragging = -1;
      window.removeEventListener('pointermove', move, true);
      window.removeEventListener('pointerup', up, true);
      onDrop(j, flat.slice(3 * j, 3 * j + 3));
    };
    parent.addEventListener('pointerdown', down, true);
    return () => {
      parent.removeEventListener('pointerdown', down, true);
      window.removeEventListener('pointermove', move, true);
      window.removeEventListener('pointerup', up, true);
    };
  }

  // A raycaster through a client pixel of the target's pane (world coordinates).
  targetRay(clientX, clientY) {
    const { camera, rect } = this.view('target');
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(ndc, camera);
    return raycaster;
  }

  // The point inside the target under a client pixel, where a click places a pin: the middle of
  // the stretch of the view ray inside the surface shown (from where it enters the mesh to where
  // it next leaves it), in target coordinates — the limb's centre in depth, as a marker is placed
  // on a front view. Null where the pixel misses the target. Called in the rest pose.
  insidePointAt(clientX, clientY) {
    const { rect } = this.view('target');
    if (!this.targetMesh.visible || clientX < rect.left || clientX > rect.left + rect.width
        || clientY < rect.top || clientY > rect.top + rect.height) return null;
    const raycaster = this.targetRay(clientX, clientY);
    this.group.updateMatrixWorld(true);
    this.targetMesh.geometry.computeBoundingSphere(); // the positions shown may have moved
    const hits = raycaster.intersectObject(this.targetMesh, false); // both faces: the material is double-sided
    if (!hits.length) return null;
    // The display scales the target to height 1: a millionth of that separates two crossings.
    const exit = hits.find((h) => h.distance > hits[0].distance + 1e-6);
    const world = exit ? hits[0].point.clone().lerp(exit.point, 0.5) : hits[0].point.clone();
    return world.applyMatrix4(this.sides.target.root.matrixWorld.clone().invert()).toArray();
  }

  // A click (press and release within a few pixels, so an orbit is not one) on the target pane
  // while canClick() says placing is on: onClick(clientX, clientY). A press that starts a joint's
  // drag is not a click (attach this after attachJointDrag: its listener runs first).
  // Returns a function that detaches the listeners.
  attachTargetClick({ canClick = () => false, onClick = () => {} }) {
    const parent = this.viewer.renderer.domElement.parentElement;
    let down = null;
    const press = (e) => {
      down = e.button === 0 && this.active && this.dragging < 0 && canClick() ? { x: e.clientX, y: e.clientY, id: e.pointerId } : null;
    };
    const release = (e) => {
      if (!down || e.pointerId !== down.id) return;
      const moved = Math.hypot(e.clientX - down.x, e.clientY - down.y);
      down = null;
      if (moved <= 4 && canClick()) onClick(e.clientX, e.clientY);
    };
    parent.addEventListener('pointerdown', press, true);
    window.addEventListener('pointerup', release, true);
    return () => {
      parent.removeEventListener('pointerdown', press, true);
      window.removeEventListener('pointerup', release, true);
    };
  }

  // The joint whose sphere is under a client pixel (within 10 px of its centre, the nearest), or -1.
  jointAt(clientX, clientY) {
    let best = -1;
    let bestD = 10;
    this.joints.spheres.forEach((s, j) => {
      const q = this.toScreen('target', s.position.toArray());
      const d = Math.hypot(q.x - clientX, q.y - clientY);
      if (d < bestD) {
        bestD = d;
        best = j;
      }
    });
    return best;
  }

  clearJoints() {
    for (const s of this.joints.spheres) this.jointGroup.remove(s);
    if (this.joints.lines) {
      this.jointGroup.remove(this.joints.lines);
      this.joints.lines.geometry.dispose();
    }
    this.joints = { spheres: [], lines: null, bones: [], count: 0 };
    this.viewer.requestRender();
  }

  setJointsVisible(on) {
    this.jointGroup.visible = on;
    this.viewer.requestRender();
  }

  // An animated GLB (a retargeted export opened again) instead of the surface: played by its
  // own mixer; playedTime(t) poses it.
  setPlayed(gltf) {
    this.clearPlayed();
    this.clearJoints();
    const mixer = new THREE.AnimationMixer(gltf.scene);
    const clip = gltf.animations[0] ?? null;
    const action = clip ? mixer.clipAction(clip) : null;
    action?.play();
    mixer.setTime(0);
    this.played = { scene: gltf.scene, mixer, action, duration: clip?.duration ?? 0 };
    this.targetMesh.visible = false;
    // Measured in its own coordinates, before it hangs under the placed side.
    gltf.scene.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(gltf.scene);
    this.sides.target.root.add(gltf.scene);
    this.measure('target', box);
  }

  setPlayedTime(t) {
    if (!this.played) return;
    this.played.mixer.setTime(t);
    this.viewer.requestRender();
  }

  clearPlayed() {
    if (!this.played) return;
    this.played.mixer.stopAllAction();
    this.sides.target.root.remove(this.played.scene);
    this.played = null;
  }

  // ---- placement

  // A side's rest box (its own coordinates); the source's is measured from its scene.
  measure(name, box = null) {
    const side = this.sides[name];
    if (!box) {
      const scene = this.source.scene;
      scene.updateMatrixWorld(true);
      side.root.updateMatrixWorld(true);
      box = new THREE.Box3();
      const inverse = side.root.matrixWorld.clone().invert();
      scene.traverse((o) => {
        if (!o.isMesh || !o.geometry) return;
        o.geometry.computeBoundingBox?.();
        if (o.isSkinnedMesh) o.computeBoundingBox();
        const b = (o.boundingBox ?? o.geometry.boundingBox).clone().applyMatrix4(o.matrixWorld).applyMatrix4(inverse);
        box.union(b);
      });
    }
    side.box = box;
    if (side.proxy) side.root.remove(side.proxy);
    side.proxy = boxProxy(box);
    side.root.add(side.proxy);
    side.loaded = true;
    this.layout();
    this.frame();
  }

  // The target's up axis (0..2 = +x, +y, +z; 3..5 = −x, −y, −z, as the joints fit reports it):
  // the target side is turned so that it stands upright (a Z-up PLY from a dataset). Display only.
  setTargetUp(axis = 1) {
    const dir = new THREE.Vector3().setComponent(axis % 3, axis >= 3 ? -1 : 1);
    this.sides.target.root.quaternion.setFromUnitVectors(dir, new THREE.Vector3(0, 1, 0));
    this.layout();
    this.frame();
    this.viewer.requestRender();
  }

  // Each side scaled to display height 1 (its box's height, after its turn), its box centred in x
  // and z and standing on y = 0; side by side the source is left, the target right.
  layout() {
    for (const side of Object.values(this.sides)) {
      if (!side.box) continue;
      const box = side.box.clone().applyMatrix4(new THREE.Matrix4().makeRotationFromQuaternion(side.root.quaternion));
      const size = box.getSize(new THREE.Vector3());
      const height = size.y > 0 ? size.y : size.length() || 1;
      const scale = 1 / height;
      const center = box.getCenter(new THREE.Vector3());
      side.root.scale.setScalar(scale);
      side.root.position.set(-center.x * scale, -box.min.y * scale, -center.z * scale);
      if (this.mode === 'side') side.root.position.x += (side.name === 'source' ? -1 : 1) * (0.5 + gap / 2) * Math.max(1, size.x * scale);
    }
    this.group.updateMatrixWorld(true);
  }

  frame() {
    if (!this.active) return;
    const proxies = Object.values(this.sides).filter((s) => s.proxy).map((s) => s.proxy);
    if (!proxies.length) return;
    this.viewer.frameMeshes(proxies, { direction: [0, 0.25, 1] });
    if (this.mode === 'split') this.viewer.frameMeshes(proxies, { direction: [0, 0.25, 1], pane: 1 });
  }

  // Which pane shows a side, its camera and rectangle.
  view(name) {
    const pane = this.mode === 'split' && this.active && name === 'target' ? 1 : 0;
    return { pane, camera: this.viewer.paneCamera(pane), rect: this.viewer.paneRect(pane) };
  }

  // Client pixel of a point in a side's coordinates.
  toScreen(name, point) {
    const { camera, rect } = this.view(name);
    const p = new THREE.Vector3(...point).applyMatrix4(this.sides[name].root.matrixWorld).project(camera);
    return { x: rect.left + ((p.x + 1) / 2) * rect.width, y: rect.top + ((1 - p.y) / 2) * rect.height };
  }
}
