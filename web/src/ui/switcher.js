// The job switcher bar: one button per job, one job selected at a time. It knows nothing about
// the jobs themselves; the shell adds them (ui/shell.js) as panels register.
export class JobSwitcher {
  // nav: the bar's element; onSelect(jobId) is called when the selection changes.
  constructor(nav, onSelect) {
    this.nav = nav;
    this.onSelect = onSelect;
    this.buttons = new Map();
    this.selected = null;
  }

  add(id, title) {
    if (this.buttons.has(id)) return;
    const button = document.createElement('button');
    button.type = 'button';
    button.textContent = title;
    button.dataset.job = id;
    button.setAttribute('role', 'tab');
    button.addEventListener('click', () => this.select(id));
    this.nav.append(button);
    this.buttons.set(id, button);
    if (this.selected === null) this.select(id);
  }

  select(id) {
    if (!this.buttons.has(id)) return;
    this.selected = id;
    for (const [job, button] of this.buttons) button.setAttribute('aria-selected', String(job === id));
    this.onSelect(id);
  }
}
