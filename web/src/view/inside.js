// Inside test for a target surface, for keeping a dragged joint inside the mesh (the page's
// counterpart of the core's TriangleBvh::inside, which decides when the fit runs): the parity of
// ray crossings along three fixed, skewed directions, by majority, on a three-mesh-bvh tree.
import * as THREE from 'three';
import { MeshBVH } from 'three-mesh-bvh';

const directions = [
  new THREE.Vector3(0.577, 0.577, 0.577),
  new THREE.Vector3(-0.8, 0.36, 0.48).normalize(),
  new THREE.Vector3(0.1, -0.9, 0.42).normalize(),
];

// positions: #V·3 floats, indices: #F·3. Returns p (THREE.Vector3) → boolean.
export function insideTest(positions, indices) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(Float32Array.from(positions), 3));
  geometry.setIndex(new THREE.BufferAttribute(Uint32Array.from(indices), 1));
  const bvh = new MeshBVH(geometry);
  const ray = new THREE.Ray();
  return (p) => {
    let votes = 0;
    for (const d of directions) {
      ray.set(p, d);
      if (bvh.raycast(ray, THREE.DoubleSide).length % 2 === 1) votes += 1;
    }
    return votes >= 2;
  };
}

// The last point inside on the segment from a (inside) to b (outside), by bisection.
export function lastInside(inside, a, b, steps = 12) {
  let lo = a.clone();
  let hi = b.clone();
  for (let k = 0; k < steps; k += 1) {
    const mid = lo.clone().lerp(hi, 0.5);
    if (inside(mid)) lo = mid;
    else hi = mid;
  }
  return lo;
}
