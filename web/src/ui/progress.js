// The progress overlay on the view: label, bar and the Cancel button of the running request.
import { byId } from './dom.js';

export class ProgressView {
  // onCancel: called when the user presses Cancel.
  constructor(onCancel) {
    this.root = byId('progress');
    this.label = byId('progress-label');
    this.bar = byId('progress-bar');
    byId('cancel').addEventListener('click', () => onCancel());
  }

  show(label) {
    this.root.hidden = false;
    this.label.textContent = label;
    this.bar.value = 0;
  }

  update(label, stage, fraction) {
    this.label.textContent = `${label} · ${stage} ${Math.round(fraction * 100)}%`;
    this.bar.value = fraction;
  }

  hide() {
    this.root.hidden = true;
  }
}
