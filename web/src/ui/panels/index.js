// The panels list: every panel the shell (ui/shell.js) hosts, in display order. A new job adds
// its panel file here (one import, one entry); see docs/web.md.
import { panel as edit } from './edit.js';
import { panel as eigen } from './eigen.js';
import { panel as info } from './info.js';
import { panel as merge } from './merge.js';
import { panel as mesh } from './mesh.js';
import { panel as retarget } from './retarget.js';
import { panel as transfer } from './transfer.js';

export const panels = [mesh, eigen, info, edit, transfer, merge, retarget];
