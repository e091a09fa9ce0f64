// The ops list: every file of worker ops, by name. The worker (worker.js) and the node test
// host (tests/js/node_worker.mjs) register exactly these. A new job adds its file here
// (one import, one entry); each file exports `ops = {opName: (ctx, options, buffers) => …}`
// (see mesh.js for the signature and ctx).
import * as debug from './debug.js';
import * as edit from './edit.js';
import * as mesh from './mesh.js';
import * as merge from './merge.js';
import * as retarget from './retarget.js';
import * as transfer from './transfer.js';

export const opFiles = {
  'mesh.js': mesh,
  'edit.js': edit,
  'transfer.js': transfer,
  'retarget.js': retarget,
  'merge.js': merge,
  'debug.js': debug,
};
