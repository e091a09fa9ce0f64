// A job's options panel, generated from its options schema (the optionSchema op, the same JSON
// as `meshmorph options <job> --json`: [{name, kind, default, min, max, choices, help}], kinds
// integer, number, boolean, choice, text) with lil-gui: one controller per option, starting at
// the schema's default (the paper's value), its one-line help under it and as a tooltip, in a
// collapsible lil-gui panel (closed at first). values() gives only the options the user changed
// from their defaults, under the schema's names — what a spec's "options" object or an op's
// options take. Each option's input carries id `opt-<name>` and data-option (tests, labels).
import GUI from 'lil-gui';

// A short range text for the help line: "1 … 3", "≥ 1e-12".
function range(option) {
  const lo = Number.isFinite(option.min);
  const hi = Number.isFinite(option.max);
  if (lo && hi) return ` (${option.min} … ${option.max})`;
  if (lo) return ` (≥ ${option.min})`;
  if (hi) return ` (≤ ${option.max})`;
  return '';
}

// A slider only where dragging makes sense: a bounded range of at most `sliderSpan` steps
// (integers) or a bounded real range that is not astronomically wide.
const sliderSpan = 64;
function wantsSlider(option) {
  if (!Number.isFinite(option.min) || !Number.isFinite(option.max)) return false;
  const span = option.max - option.min;
  return option.kind === 'integer' ? span <= sliderSpan : span > 0 && span <= 1000 && option.min >= 0;
}

export class OptionsForm {
  // schema: the optionSchema array; title: the panel's title; sliders: {name: max} — a slider up
  // to `max` for an option the schema leaves unbounded above (widths in units of a diagonal,
  // where a few units already cover the whole mesh); a larger value (typed, or from a spec)
  // widens it.
  constructor(schema, { title = 'Options', sliders = {} } = {}) {
    this.schema = schema;
    this.sliders = sliders;
    this.values_ = Object.fromEntries(schema.map((o) => [o.name, o.default ?? (o.kind === 'text' ? '' : 0)]));
    this.gui = new GUI({ autoPlace: false, title, closeFolders: true, width: undefined });
    this.gui.domElement.classList.add('options');
    this.element = this.gui.domElement;
    this.controls = new Map();
    for (const option of schema) {
      const controller = this.addController(option);
      const input = controller.$input || controller.$select;
      if (input) {
        input.id = `opt-${option.name}`;
        input.dataset.option = option.name;
      }
      controller.domElement.classList.add('option');
      controller.domElement.title = `${option.help}${range(option)} · default ${option.default}`;
      const hint = document.createElement('div');
      hint.className = 'option-help';
      hint.textContent = `${option.help}${range(option)}`;
      controller.domElement.after(hint);
      this.controls.set(option.name, { controller, option, hint });
    }
    this.gui.close();
  }

  addController(option) {
    const { name, kind } = option;
    const object = this.values_;
    if (kind === 'choice') return this.gui.add(object, name, option.choices || []);
    if (kind === 'boolean') {
      object[name] = Boolean(object[name]);
      return this.gui.add(object, name);
    }
    if (kind === 'integer' || kind === 'number') {
      object[name] = Number(object[name]);
      const soft = Number.isFinite(option.max) ? undefined : this.sliders[name];
      const slider = soft !== undefined || wantsSlider(option);
      const c = this.gui.add(object, name);
      if (Number.isFinite(option.min)) c.min(option.min);
      if (soft !== undefined) {
        c.max(soft);
        // A typed value above the slider widens it instead of being cut to it (lil-gui clamps
        // typed values to [min, max] through _clamp; lil-gui is pinned in package.json).
        const lo = Number.isFinite(option.min) ? option.min : -Infinity;
        c._clamp = (v) => Math.max(lo, v);
        c.onChange((v) => { if (v > c._max) c.max(v); });
        return c;
      }
      // Without a slider the maximum is enforced here (lil-gui draws a slider as soon as both
      // bounds are set).
      if (slider) c.max(option.max);
      else if (Number.isFinite(option.max)) {
        c.onChange((v) => { if (v > option.max) c.setValue(option.max); });
      }
      if (kind === 'integer') c.step(1);
      return c;
    }
    object[name] = String(object[name] ?? '');
    return this.gui.add(object, name);
  }

  // {name: value} of the options that differ from their defaults.
  values() {
    const out = {};
    for (const [name, { option }] of this.controls) {
      const value = this.values_[name];
      if (value !== option.default) out[name] = value;
    }
    return out;
  }

  // Sets the given options (others go back to their defaults); unknown names are ignored here
  // (the core rejects them with a message when the spec is used).
  setValues(values = {}) {
    for (const [name, { controller, option }] of this.controls) {
      controller.setValue(name in values ? values[name] : option.default);
    }
  }

  // Enables or disables every control (while an op runs).
  setEnabled(on) {
    for (const { controller } of this.controls.values()) controller.enable(on);
  }

  open(on = true) { this.gui.open(on); }
}
