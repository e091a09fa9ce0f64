// The Info panel (part of the Mesh job): the loaded mesh's report as the CLI's `meshmorph
// info` prints it (the worker's load result carries the text).
import { finder, fromHtml } from '../dom.js';

export const panel = {
  id: 'info',
  title: 'Info',
  job: 'mesh',
  create(app) {
    const root = fromHtml('<section class="grow"><h2>Info</h2><pre id="info">no mesh loaded</pre></section>');
    const $ = finder(root);
    app.on('mesh', (mesh) => { $('info').textContent = mesh.text; });
    return root;
  },
};
