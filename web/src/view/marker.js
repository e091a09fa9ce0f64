// A marker for one vertex: a small sphere in the overlay group of view/viewer.js (which sizes
// it to the mesh). It is depth-tested, so it is hidden behind the surface like the vertex it
// marks; centred on the vertex, half of it stands out of the surface.
import * as THREE from 'three';

const sphere = new THREE.SphereGeometry(1, 16, 12);

export class VertexMarker {
  // onChange: called after every visible change (the viewer requests a frame).
  constructor({ color, onChange = () => {} }) {
    this.object = new THREE.Mesh(sphere, new THREE.MeshBasicMaterial({ color }));
    this.object.visible = false;
    this.object.renderOrder = 1;
    this.onChange = onChange;
  }

  setSize(radius) {
    this.object.scale.setScalar(radius);
    if (this.object.visible) this.onChange();
  }

  // point: [x, y, z] in world space.
  show(point) {
    this.object.position.fromArray(point);
    this.object.visible = true;
    this.onChange();
  }

  hide() {
    if (!this.object.visible) return;
    this.object.visible = false;
    this.onChange();
  }
}
