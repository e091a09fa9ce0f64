// Page bootstrap: the viewer (view/), the worker client (lib/client.js) and the shell with its
// panels (ui/). Geometry work happens in the worker (worker/worker.js); this thread only
// shows results. The panels list is ui/panels/index.js, the worker's ops list
// worker/ops/index.js.
//
// URL parameters: ?sample=<id> (initial gallery mesh), ?cancel=terminate (use the
// terminate-and-respawn cancel even when SharedArrayBuffer is available; see lib/client.js),
// ?threads=1 (the single-threaded wasm build even when the page is cross-origin isolated).
import { MeshMorphClient } from './lib/client.js';
import { byId } from './ui/dom.js';
import { panels } from './ui/panels/index.js';
import { Shell } from './ui/shell.js';
import { vertexOnScreen } from './view/screen-space.js';
import { Viewer } from './view/viewer.js';

const params = new URLSearchParams(location.search);
const viewer = new Viewer(byId('view'));
const client = new MeshMorphClient({
  createWorker: () => new Worker(new URL('./worker/worker.js', import.meta.url), { type: 'module' }),
  // Served beside the page, not bundled (vite.config.js, meshmorphThreadedModule).
  threadedModuleUrl: params.get('threads') === '1' ? null : new URL('wasm-mt/meshmorph_web_mt.mjs', document.baseURI).href,
  cancelMode: params.get('cancel') === 'terminate' ? 'terminate' : 'auto',
  onStatus: (text) => shell.notice(text), // eslint-disable-line no-use-before-define
  onRestart: (detail) => shell.workerRestarted(detail), // eslint-disable-line no-use-before-define
});
const shell = new Shell({ client, viewer, params });
for (const panel of panels) shell.register(panel);

// Everything the page shows (shell.state, filled in by the panels) for the end-to-end tests.
window.__meshmorph = {
  state: shell.state,
  client,
  get frames() { return viewer.frames; },
  viewer, // benches (tests/e2e/retarget-bench.mjs) time its render loop
  hooks: shell.hooks,
  // Where a displayed vertex is: {x, y} in client pixels and whether the camera sees it.
  vertexOnScreen: (vertex) => vertexOnScreen(viewer, vertex),
  // Resolves once a frame showing the current state has been drawn (tests read pixels then).
  nextFrame: () => new Promise((resolve) => {
    viewer.requestRender();
    requestAnimationFrame(() => requestAnimationFrame(resolve));
  }),
  get cancelMode() { return client.cancelMode; },
  get restarts() { return client.restarts; },
  get threads() { return client.threads; },
};

shell.start();
