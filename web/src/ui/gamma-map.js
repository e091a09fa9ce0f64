// The functional matrix Γ of a transfer (k×k, row-major; info.gamma of the transfer op) as a
// small heat map on a canvas: Γᵢⱼ / max|Γ| through the page's diverging blue–white–red map
// (lib/colormap.js), so a dominant diagonal shows as a red or blue line on white. The first K+1
// rows (the transferred coefficients) are marked by a tick on the left.
import { divergingColor } from '../lib/colormap.js';

const sizePx = 160;

export class GammaMap {
  constructor() {
    this.element = document.createElement('canvas');
    this.element.className = 'gamma-map';
    this.element.width = this.element.height = sizePx;
    this.element.hidden = true;
  }

  // gamma: number[k·k], k, transferred: how many leading rows were transferred (K+1).
  show(gamma, k, transferred = 0) {
    const canvas = this.element;
    canvas.hidden = !(k > 0);
    if (!(k > 0)) return;
    const cell = Math.max(1, Math.floor((sizePx - 6) / k));
    canvas.width = canvas.height = cell * k + 6;
    const g = canvas.getContext('2d');
    g.clearRect(0, 0, canvas.width, canvas.height);
    let max = 0;
    for (const v of gamma) max = Math.max(max, Math.abs(v));
    const rgb = [0, 0, 0];
    for (let i = 0; i < k; ++i) {
      for (let j = 0; j < k; ++j) {
        divergingColor(max > 0 ? gamma[i * k + j] / max : 0, rgb);
        g.fillStyle = `rgb(${rgb.map((v) => Math.round(255 * v)).join(', ')})`;
        g.fillRect(6 + j * cell, 6 + i * cell, cell, cell);
      }
    }
    g.fillStyle = '#ffd23f';
    g.fillRect(0, 6, 3, Math.min(transferred, k) * cell);
    canvas.title = `Γ (${k}×${k}), colour = Γᵢⱼ / max|Γ| (max ${max.toPrecision(3)}); the yellow tick marks the ${transferred} transferred rows`;
  }

  hide() {
    this.element.hidden = true;
  }
}
