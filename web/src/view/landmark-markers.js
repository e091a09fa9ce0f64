// Numbered, colour-matched markers of landmark pairs on the two meshes of view/pair-view.js:
// pair i has the same colour (pairColor) on both sides, a sphere (view/marker.js) on the
// vertex and a sprite with its number next to it. Markers are children of their side's mesh, so
// they follow its placement; their size follows the mesh's radius. The selected pair is drawn
// larger, the pending half of a pair (clicked on one side, waiting for the other) in white.
import * as THREE from 'three';
import { VertexMarker } from './marker.js';

// Colour of pair i ([r, g, b] in 0..1): hues a golden angle apart, so neighbours differ.
export function pairColor(i) {
  const c = new THREE.Color().setHSL((i * 0.61803398875 + 0.08) % 1, 0.8, 0.55);
  return [c.r, c.g, c.b];
}

const pendingColor = [1, 1, 1];
const labelPx = 64;

// A sprite showing `text` on a disc of colour `rgb`.
function labelSprite(text, rgb) {
  const canvas = document.createElement('canvas');
  canvas.width = canvas.height = labelPx;
  const g = canvas.getContext('2d');
  g.fillStyle = `rgb(${rgb.map((v) => Math.round(255 * v)).join(', ')})`;
  g.beginPath();
  g.arc(labelPx / 2, labelPx / 2, labelPx / 2 - 2, 0, 2 * Math.PI);
  g.fill();
  g.fillStyle = '#10131a';
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
    this.items = [];   // {side, object: Group, dispose}
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
    const view = this.pairView;
    const mesh = view.sides[side].mesh;
    const radius = view.localRadius(side) * (big ? 0.022 : 0.015);
    const marker = new VertexMarker({ color: new THREE.Color(...rgb) });
    marker.setSize(radius);
    marker.show(view.localPoint(side, vertex));
    const sprite = labelSprite(text, rgb);
    sprite.position.copy(marker.object.position);
    sprite.scale.setScalar(view.localRadius(side) * (big ? 0.12 : 0.09));
    const object = new THREE.Group();
    object.add(marker.object, sprite);
    mesh.add(object);
    this.items.push({
      side,
      object,
      dispose: () => {
        marker.object.material.dispose();
        sprite.material.map.dispose();
        sprite.material.dispose();
      },
    });
  }
}
