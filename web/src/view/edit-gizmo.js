// The edit gizmo: a three.js TransformControls (translate / rotate / scale) on a pivot object
// placed at the handle's centroid. The handle's transform is the pivot's motion since it was
// placed, H = P · P₀⁻¹ (P the pivot's matrix, P₀ its rest matrix), as a column-major 4x4 array
// (Matrix4.elements): the "matrix" of an edit spec. While the gizmo is dragged the viewer's
// orbit controls are off. The viewer renders on demand, so every gizmo change requests a frame.
import * as THREE from 'three';
import { TransformControls } from 'three/addons/controls/TransformControls.js';

export class EditGizmo {
  // onChange(matrix) while dragging; onRelease(matrix) when the user lets go.
  constructor(viewer, { onChange = () => {}, onRelease = () => {} } = {}) {
    this.viewer = viewer;
    this.pivot = new THREE.Object3D();
    this.rest = new THREE.Matrix4();
    this.restInverse = new THREE.Matrix4();
    this.controls = new TransformControls(viewer.camera, viewer.renderer.domElement);
    this.controls.setSize(0.9);
    this.helper = this.controls.getHelper();
    this.helper.visible = false;
    this.controls.enabled = false;
    viewer.scene.add(this.pivot);
    viewer.overlays.add(this.helper);
    this.controls.addEventListener('change', () => viewer.requestRender());
    this.controls.addEventListener('objectChange', () => onChange(this.matrix()));
    this.controls.addEventListener('dragging-changed', (e) => {
      viewer.controls.enabled = !e.value;
      if (!e.value) onRelease(this.matrix());
    });
  }

  get dragging() {
    return this.controls.dragging;
  }

  // Shows the gizmo at `center` ([x, y, z], world space) with the handle at rest.
  attach(center) {
    this.pivot.position.fromArray(center);
    this.pivot.quaternion.identity();
    this.pivot.scale.setScalar(1);
    this.pivot.updateMatrix();
    this.pivot.updateMatrixWorld(true);
    this.rest.copy(this.pivot.matrix);
    this.restInverse.copy(this.rest).invert();
    this.controls.attach(this.pivot);
    this.controls.enabled = true;
    this.helper.visible = true;
    this.viewer.requestRender();
  }

  detach() {
    this.controls.detach();
    this.controls.enabled = false;
    this.helper.visible = false;
    this.viewer.controls.enabled = true;
    this.viewer.requestRender();
  }

  // Hides / shows the attached gizmo keeping its pose (switching jobs).
  hide() {
    this.helper.visible = false;
    this.controls.enabled = false;
    this.viewer.requestRender();
  }

  show() {
    if (!this.controls.object) return;
    this.helper.visible = true;
    this.controls.enabled = true;
    this.viewer.requestRender();
  }

  setMode(mode) {
    this.controls.setMode(mode);
  }

  // The handle transform H = P · P₀⁻¹ as 16 numbers (column-major).
  matrix() {
    this.pivot.updateMatrix();
    return new THREE.Matrix4().multiplyMatrices(this.pivot.matrix, this.restInverse).toArray();
  }

  // Puts the pivot where the handle transform `elements` takes it (undo / redo / a loaded spec).
  setMatrix(elements) {
    const p = new THREE.Matrix4().fromArray(elements).multiply(this.rest);
    p.decompose(this.pivot.position, this.pivot.quaternion, this.pivot.scale);
    this.pivot.updateMatrixWorld(true);
    this.viewer.requestRender();
  }

  // Client coordinates of the middle of one of the gizmo's picking handles ('X', 'Y', 'Z',
  // 'XY'…, of the current mode), for tests that drag it with the real mouse; null if absent.
  handleOnScreen(name) {
    const picker = this.controls._gizmo.picker[this.controls.mode];
    this.helper.updateMatrixWorld(true);
    const target = picker.children.find((c) => c.name === name);
    if (!target) return null;
    target.geometry.computeBoundingBox();
    const world = target.geometry.boundingBox.getCenter(new THREE.Vector3()).applyMatrix4(target.matrixWorld);
    const ndc = world.project(this.viewer.camera);
    const rect = this.viewer.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + ((ndc.x + 1) / 2) * rect.width, y: rect.top + ((1 - ndc.y) / 2) * rect.height };
  }
}
