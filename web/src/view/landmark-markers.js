// Numbered, colour-matched markers of landmark pairs on the two meshes of view/pair-view.js:
// pair i has the same colour (pairColor) on both sides, a sphere (view/marker.js) on the
// vertex and a sprite with its number next to it. Markers are children of their side's mesh, so
// they follow its placement; their size follows the mesh's radius. The selected pair is drawn
// larger, the pending half of a pair (clicked on one side, waiting for the other) in white.
// Numbers are sprites drawn on top (no depth test, so the surface never cuts them), and so
// an occlusion check hides the number of a vertex the camera does not see (a BVH ray from the
// camera, view/screen-space.js; a vertex a few percent of the mesh's size behind the surface,
// like the underside of a paw's tip, counts as seen) before every frame: numbers never show
// through the mesh.
// Suggested pairs (not accepted yet) are drawn as rings with their number in a dark disc.
import * as THREE from 'three';
import { VertexMarker } from './marker.js';
import { vertexVisible } from './screen-space.js';

// Colour of pair i ([r, g, b] in 0..1): hues a golden angle apart, so neighbours differ.
export function pairColor(i) {
  const c = new THREE.Color().setHSL((i * 0.61803398875 + 0.08) % 1, 0.8, 0.55);
  return [c.r, c.g, c.b];
}

const pendingColor = [1, 1, 1];
// A number shows when the first surface point on the line of sight to its vertex is at most
// this far (relative to the mesh's radius) in front of it.
export const labelTolerance = 0.04;
const labelPx = 64;

// A sprite showing `text` on a disc of colour `rgb`.
function labelSprite(text, rgb, { suggested = false } = {}) {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = labelPx;
  const g = canvas.getContext('2d');
  const colour = `rgb(${rgb.map((v) => Math.round(255 * v)).join(', ')})`;
  g.fillStyle = suggested ? '#10131a' : colour;
  g.beginPath();
  g.arc(labelPx / 2, labelPx / 2, labelPx / 2 - 4, 0, 2 * Math.PI);
  g.fill();
  if (suggested) {
    g.lineWidth = 5;
    g.strokeStyle = colour;
    g.setLineDash([9, 5]);
    g.stroke();
  }
  g.fillStyle = suggested ? colour : '#10131a';
  g.font = `bold ${text.length > 2 ? 26 : 34}px system-ui, sans-serif`;
  g.textAlign = 'center';
  g.textBaseline = 'middle';
  g.fillText(text, labelPx / 2, labelPx / 2 + 2);
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const sprite = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthTest: false }));
  sprite.center.set(-0.25, -0.25); // up and right of the vertex, the marker stays visible
  sprite.renderOrder = 2;
  return sprite;
}

export class LandmarkMarkers {
  // pairView: view/pair-view.js; onChange: request a frame.
  constructor(pairView, onChange) {
    this.pairView = pairView;
    this.onChange = onChange;
    this.items = [];   // {side, vertex, label, text, suggested, object: Group, dispose}
    this.suggestions = []; // the same for suggested pairs
    pairView.viewer.beforeRender.add(() => this.updateOcclusion());
  }

  // Hides the numbers of vertices the camera (of their side's pane) does not see.
  updateOcclusion() {
    const view = this.pairView;
    if (!view.active) return;
    for (const item of [...this.items, ...this.suggestions]) {
      const side = view.sides[item.side];
      item.label.visible = vertexVisible(view.viewer, item.vertex, { mesh: side.mesh, picker: side.picker, camera: view.view(item.side).camera, tolerance: labelTolerance });
    }
  }

  // [{side, text, vertex, suggested, visible}] of the numbers as last drawn (tests).
  labels() {
    return [...this.items, ...this.suggestions].map((i) => ({ side: i.side, text: i.text, vertex: i.vertex, suggested: i.suggested, visible: i.label.visible }));
  }

  // Suggested pairs [[rVertex, sVertex]] (raw vertices), numbered S1, S2, … in the colours the
  // pairs would get once accepted (from `firstIndex` on).
  showSuggestions(pairs, firstIndex) {
    for (const item of this.suggestions) {
      item.object.removeFromParent();
      item.dispose();
    }
    this.suggestions = [];
    pairs.forEach(([r, s], i) => {
      const colour = pairColor(firstIndex + i);
      this.suggestions.push(this.make('reference', r, colour, `S${i + 1}`, false, true), this.make('source', s, colour, `S${i + 1}`, false, true));
    });
    this.onChange();
  }

  clear() {
    for (const item of this.items) {
      item.object.removeFromParent();
      item.dispose();
    }
    this.items = [];
  }

  // Shows the pairs: pairs [[rVertex, sVertex] as displayed (raw) vertex indices], pending
  // {side, vertex} or null, selected: index or -1.
  show(pairs, pending, selected) {
    this.clear();
    pairs.forEach(([r, s], i) => {
      const big = i === selected;
      this.add('reference', r, pairColor(i), String(i + 1), big);
      this.add('source', s, pairColor(i), String(i + 1), big);
    });
    if (pending) this.add(pending.side, pending.vertex, pendingColor, String(pairs.length + 1), true);
    this.onChange();
  }

  add(side, vertex, rgb, text, big) {
    this.items.push(this.make(side, vertex, rgb, text, big, false));
  }

  make(side, vertex, rgb, text, big, suggested) {
    const view = this.pairView;
    const mesh = view.sides[side].mesh;
    const radius = view.localRadius(side) * (big ? 0.022 : suggested ? 0.011 : 0.015);
    const marker = new VertexMarker({ color: new THREE.Color(...rgb) });
    marker.setSize(radius);
    marker.show(view.localPoint(side, vertex));
    const sprite = labelSprite(text, rgb, { suggested });
    sprite.position.copy(marker.object.position);
    sprite.scale.setScalar(view.localRadius(side) * (big ? 0.12 : 0.09));
    const object = new THREE.Group();
    object.add(marker.object, sprite);
    mesh.add(object);
    return {
      side,
      vertex,
      text,
      suggested,
      label: sprite,
      object,
      dispose: () => {
        marker.object.material.dispose();
        sprite.material.map.dispose();
        sprite.material.dispose();
      },
    };
  }
}
