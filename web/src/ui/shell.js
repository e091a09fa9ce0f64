// The page's shell: hosts the panels (ui/panels/) under a job switcher bar, and owns what all
// jobs share: the status line, the progress overlay with Cancel, the error banner, the busy
// state and the one way to run a worker op (runOp). Panels get the shell as their `app`:
//   app.state     what the page shows (window.__meshmorph.state; each panel adds its fields)
//   app.client    the worker client (lib/client.js); app.viewer the three.js view (view/)
//   app.params    the page's URL parameters
//   app.runOp(label, op, options, buffers, extra) → result or null (the error is shown)
//   app.on(event, fn) / app.emit(event, detail)   events between panels: 'ready' (the worker
//                 is up), 'mesh' (a mesh was loaded; detail = app.state.mesh), 'job' (switched)
//   app.showError(e), app.clearError(), app.setStatus(text)
//   app.hooks     functions for the end-to-end tests (window.__meshmorph.hooks)
//   app.onDrop(job, {describe(clientX) → text, drop(fileList, clientX)})  files dropped on the
//                 view go to the job that is shown (never to another one); while an op runs a
//                 drop is refused with a message
//   app.notice(text) a message that is not an error (e.g. the worker was replaced)
//   app.refuse({code, message}) an action not done (a toast for a few seconds)
// Controls marked `data-idle` in a panel's markup are disabled while an op runs or the
// worker is not ready.
import { toMeshMorphError } from '../lib/errors.js';
import { byId, fromHtml } from './dom.js';
import { ErrorBanner } from './error-banner.js';
import { ProgressView } from './progress.js';
import { JobSwitcher } from './switcher.js';

export class Shell {
  constructor({ client, viewer, params }) {
    this.client = client;
    this.viewer = viewer;
    this.params = params;
    this.state = {
      ready: false,
      busy: null,   // {id, label} of the running request
      error: null,  // {code, message} of the last error shown
    };
    this.hooks = {};  // functions panels offer the end-to-end tests (window.__meshmorph.hooks)
    this.events = new EventTarget();
    this.panels = []; // {panel, element, job} in registration order
    this.host = byId('panels');
    this.statusLine = byId('status');
    this.progress = new ProgressView(() => {
      if (this.state.busy) client.cancel(this.state.busy.id);
    });
    this.errors = new ErrorBanner();
    this.switcher = new JobSwitcher(byId('jobs'), (job) => this.showJob(job));
    this.dropTargets = new Map();
    this.setupDrop();
  }

  get job() { return this.switcher.selected; }

  onDrop(job, target) {
    this.dropTargets.set(job, target);
  }

  // Drag and drop on the view: the overlay says where the files will go (the shown job's
  // target), a drop goes there, and only there.
  setupDrop() {
    const viewport = byId('viewport');
    const overlay = fromHtml('<div id="drop-overlay" hidden></div>');
    byId('view').after(overlay);
    let depth = 0;
    const describe = (x) => {
      if (this.state.busy) return `Busy: ${this.state.busy.label}… drop again when it has finished`;
      const target = this.dropTargets.get(this.job);
      return target ? target.describe(x) : 'This job does not open files';
    };
    viewport.addEventListener('dragenter', (e) => {
      e.preventDefault();
      depth += 1;
      overlay.textContent = describe(e.clientX);
      overlay.hidden = false;
    });
    viewport.addEventListener('dragleave', () => {
      depth = Math.max(0, depth - 1);
      if (!depth) overlay.hidden = true;
    });
    viewport.addEventListener('dragover', (e) => {
      e.preventDefault();
      overlay.textContent = describe(e.clientX);
    });
    viewport.addEventListener('drop', (e) => {
      e.preventDefault();
      depth = 0;
      overlay.hidden = true;
      const files = e.dataTransfer?.files;
      if (!files?.length) return;
      const target = this.dropTargets.get(this.job);
      if (this.state.busy) {
        this.refuse({ code: 'Busy', message: `“${this.state.busy.label}” is still running: the dropped file was not opened. Drop it again when it has finished.` });
        return;
      }
      if (!target) {
        this.showError({ code: 'Unsupported', message: `the ${this.jobTitle(this.job)} job does not open dropped files` });
        return;
      }
      target.drop(files, e.clientX);
    });
  }

  // The client replaced a worker that failed (crash, out of memory) or that a cancel had to stop
  // (code Cancelled): the new one has loaded the meshes again. The error of a request that failed
  // is already shown; this adds what happened next, and tells the panels ('restarted').
  workerRestarted({ code, why, restored }) {
    const meshes = restored.filter((k) => k.startsWith('mesh:')).length;
    const what = code === 'OutOfMemory' ? 'ran out of memory'
      : code === 'Cancelled' ? (why === 'terminated' ? 'was stopped for a cancel' : 'did not stop in time for a cancel') : 'stopped';
    const text = `The geometry worker ${what}; a new one was started`
      + `${meshes ? ` and ${meshes === 1 ? 'the loaded mesh was' : `the ${meshes} loaded meshes were`} restored` : ''}.`;
    if (code !== 'Cancelled') {
      this.state.recoveries = (this.state.recoveries || 0) + 1;
      this.state.recovery = { code, restored, text };
      if (this.state.error) this.errors.show({ code: this.state.error.code, message: `${this.state.error.message}\n${text}` });
    }
    this.notice(text);
    this.emit('restarted', { code, restored });
  }

  // An action the page did not do (e.g. a drop while something loads): a toast on the view
  // for a few seconds (the error banner would be cleared by the op that is running), recorded
  // as state.error like an error.
  refuse({ code, message }) {
    this.state.error = { code, message };
    this.toast ??= Object.assign(document.createElement('div'), { id: 'toast', role: 'status' });
    if (!this.toast.isConnected) byId('viewport').append(this.toast);
    this.toast.textContent = message;
    this.toast.hidden = false;
    clearTimeout(this.toastTimer);
    this.toastTimer = setTimeout(() => { this.toast.hidden = true; }, 6000);
    console.info(`[meshmorph] ${code}: ${message}`);
  }

  notice(text) {
    this.setStatus(text);
    console.info(`[meshmorph] ${text}`);
  }

  // panel: {id, title, job?, create(app) → Element}. `job` is the switcher entry the panel
  // appears under (default: its own id); the entry's title is the title of the panel whose id
  // is the job's.
  register(panel) {
    if (this.panels.some((p) => p.panel.id === panel.id)) throw new Error(`panel '${panel.id}' is registered twice`);
    const job = panel.job || panel.id;
    const element = panel.create(this);
    element.dataset.panel = panel.id;
    this.host.append(element);
    this.panels.push({ panel, element, job });
    this.switcher.add(job, this.jobTitle(job));
    element.hidden = job !== this.switcher.selected;
    this.updateControls();
  }

  jobTitle(job) {
    return this.panels.find((p) => p.panel.id === job)?.panel.title || job;
  }

  showJob(job) {
    for (const p of this.panels) p.element.hidden = p.job !== job;
    this.emit('job', job);
  }

  on(name, fn) {
    this.events.addEventListener(name, (e) => fn(e.detail));
  }

  emit(name, detail) {
    this.events.dispatchEvent(new CustomEvent(name, { detail }));
  }

  setStatus(text) {
    this.statusLine.textContent = text;
  }

  showError(e) {
    const error = toMeshMorphError(e, 'Error');
    this.state.error = { code: error.code, message: error.message };
    this.errors.show(error);
    // Shown to the user and handled: information in the console, not an error (the e2e runs
    // require a console free of warnings and errors).
    console.info(`[meshmorph] ${error.code}: ${error.message}`);
  }

  clearError() {
    this.errors.hide();
  }

  setBusy(busy) {
    this.state.busy = busy;
    if (busy) this.progress.show(busy.label);
    else this.progress.hide();
    this.updateControls();
  }

  updateControls() {
    const idle = this.state.ready && !this.state.busy;
    for (const control of this.host.querySelectorAll('[data-idle]')) {
      control.disabled = !idle;
      control.closest('label.button')?.classList.toggle('disabled', !idle);
    }
  }

  // Runs one worker op with the progress bar and Cancel button; errors are shown, not thrown
  // (returns null), so every caller leaves the page usable.
  async runOp(label, op, options, buffers, extra = {}) {
    this.clearError();
    const { id, promise } = this.client.run(op, options, buffers, {
      ...extra,
      onProgress: (stage, fraction) => this.progress.update(label, stage, fraction),
    });
    this.setBusy({ id, label });
    try {
      return await promise;
    } catch (e) {
      this.showError(e);
      return null;
    } finally {
      this.setBusy(null);
    }
  }

  // Waits for the worker, then tells the panels ('ready').
  start() {
    this.setBusy(null);
    this.client.ready.then(
      () => {
        this.state.ready = true;
        this.setBusy(null);
        this.setStatus(`ready · ${this.client.runtimeSummary}`);
        this.emit('ready');
      },
      (e) => {
        this.setStatus('the geometry module failed to start');
        this.showError(e);
      },
    );
  }
}
