// A small animated preview of a clip (the Retarget job's clip library): its own little WebGL
// canvas showing a copy of a character (SkeletonUtils.clone: the main view keeps the original)
// playing the chosen clip in a loop. It draws only while shown and the page is visible.
import * as THREE from 'three';
import { clone as cloneSkinned } from 'three/examples/jsm/utils/SkeletonUtils.js';

export class ClipPreview {
  constructor({ width = 150, height = 150 } = {}) {
    this.element = document.createElement('canvas');
    this.element.className = 'clip-preview';
    this.element.width = width;
    this.element.height = height;
    this.renderer = null; // created on first show (one more WebGL context only when used)
    this.scene = new THREE.Scene();
    this.scene.add(new THREE.HemisphereLight(0xf2f4ff, 0x3a3530, 1.2));
    const key = new THREE.DirectionalLight(0xffffff, 1.4);
    key.position.set(0.6, 1, 1);
    this.scene.add(key);
    this.camera = new THREE.PerspectiveCamera(35, width / height, 0.01, 100);
    this.model = null;
    this.mixer = null;
    this.last = 0; // performance.now() of the last drawn frame
    this.running = false;
    this.frames = 0;
    this.clipName = null;
    // While the main view plays the same clip the preview holds still (one WebGL context
    // drawing per frame instead of two).
    this.paused = false;
  }

  // gltf: the loaded character; index: the clip to play (null: the bind pose).
  show(gltf, index) {
    if (!this.renderer) {
      this.renderer = new THREE.WebGLRenderer({ canvas: this.element, antialias: true, alpha: true, preserveDrawingBuffer: true });
      this.renderer.setClearColor(0x1d2230, 1);
    }
    if (this.model) this.scene.remove(this.model);
    this.model = cloneSkinned(gltf.scene);
    this.scene.add(this.model);
    this.mixer = new THREE.AnimationMixer(this.model);
    const clip = index == null ? null : gltf.animations[index];
    this.clipName = clip ? clip.name : null;
    if (clip) this.mixer.clipAction(clip).play();
    this.mixer.setTime(0);
    this.model.updateMatrixWorld(true);
    const box = new THREE.Box3().setFromObject(this.model);
    const size = box.getSize(new THREE.Vector3());
    const center = box.getCenter(new THREE.Vector3());
    const radius = Math.max(size.x, size.y, size.z) || 1;
    this.camera.position.copy(center).add(new THREE.Vector3(0.35, 0.25, 1).normalize().multiplyScalar(radius * 2.1));
    this.camera.near = radius / 100;
    this.camera.far = radius * 20;
    this.camera.updateProjectionMatrix();
    this.camera.lookAt(center);
    this.start();
  }

  start() {
    if (this.running || !this.renderer) return;
    this.running = true;
    this.last = performance.now();
    const loop = (now) => {
      if (!this.running) return;
      const dt = Math.min(Math.max(0, (now - this.last) / 1000), 0.1);
      this.last = now;
      if (!this.paused && !document.hidden && this.element.isConnected && this.element.offsetParent !== null) {
        this.mixer?.update(dt);
        this.renderer.render(this.scene, this.camera);
        this.frames += 1;
      }
      requestAnimationFrame(loop);
    };
    requestAnimationFrame(loop);
  }

  stop() {
    this.running = false;
  }
}
