// An options form generated from a job's options schema (the optionSchema op's options: [{name, kind,
// default, min, max, choices, help}], kinds integer, number, boolean, choice, text): one control
// per option with its help as a line under it and as a tooltip, inside a collapsible
// <details>. values() gives only the options the user changed from their defaults, under the
// schema's names — what a spec's "options" object or an op's options take.
import { fromHtml } from './dom.js';

function control(option) {
  const { kind, name } = option;
  if (kind === 'boolean') {
    const input = fromHtml(`<input type="checkbox" />`);
    input.checked = Boolean(option.default);
    return { input, read: () => input.checked, write: (v) => { input.checked = Boolean(v); } };
  }
  if (kind === 'choice') {
    const input = document.createElement('select');
    for (const c of option.choices || []) input.add(new Option(c, c));
    input.value = option.default;
    return { input, read: () => input.value, write: (v) => { input.value = String(v); } };
  }
  const input = document.createElement('input');
  input.name = name;
  if (kind === 'integer' || kind === 'number') {
    input.type = 'number';
    input.step = kind === 'integer' ? '1' : 'any';
    if (Number.isFinite(option.min)) input.min = String(option.min);
    if (Number.isFinite(option.max)) input.max = String(option.max);
    input.value = String(option.default);
    return { input, read: () => Number(input.value), write: (v) => { input.value = String(v); } };
  }
  input.type = 'text';
  input.value = option.default ?? '';
  return { input, read: () => input.value, write: (v) => { input.value = String(v); } };
}

function range(option) {
  const parts = [];
  if (Number.isFinite(option.min)) parts.push(`≥ ${option.min}`);
  if (Number.isFinite(option.max)) parts.push(`≤ ${option.max}`);
  return parts.length ? ` (${parts.join(', ')})` : '';
}

export class OptionsForm {
  // schema: the optionSchema array; title: the <summary> text.
  constructor(schema, { title = 'Options' } = {}) {
    this.schema = schema;
    this.element = fromHtml(`<details class="options"><summary></summary><div class="options-list"></div></details>`);
    this.element.querySelector('summary').textContent = title;
    const list = this.element.querySelector('.options-list');
    this.controls = new Map();
    for (const option of schema) {
      const c = control(option);
      c.input.id = `opt-${option.name}`;
      c.input.dataset.option = option.name;
      const row = fromHtml(`<div class="option"><label></label><p class="hint"></p></div>`);
      const label = row.querySelector('label');
      label.append(`${option.name} `, c.input);
      label.title = `${option.help}${range(option)} · default ${option.default}`;
      row.querySelector('.hint').textContent = `${option.help}${range(option)}`;
      list.append(row);
      this.controls.set(option.name, { ...c, option });
    }
  }

  // {name: value} of the options that differ from their defaults.
  values() {
    const out = {};
    for (const [name, { read, option }] of this.controls) {
      const value = read();
      if (value !== option.default) out[name] = value;
    }
    return out;
  }

  // Sets the given options (others go back to their defaults); unknown names are ignored here
  // (the core rejects them with a message when the spec is used).
  setValues(values = {}) {
    for (const [name, { write, option }] of this.controls) write(name in values ? values[name] : option.default);
  }
}
