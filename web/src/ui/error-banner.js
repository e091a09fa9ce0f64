// The error banner on the view: code and message of the last error, dismissable.
import { byId } from './dom.js';

export class ErrorBanner {
  constructor() {
    this.root = byId('error');
    this.code = byId('error-code');
    this.message = byId('error-message');
    byId('error-close').addEventListener('click', () => this.hide());
  }

  // error: a MeshMorphError (lib/errors.js).
  show(error) {
    this.code.textContent = error.code;
    this.message.textContent = error.message;
    this.root.hidden = false;
  }

  hide() {
    this.root.hidden = true;
  }
}
