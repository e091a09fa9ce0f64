// The table of landmark pairs in the Transfer panel: number (in the pair's marker colour),
// reference vertex, source vertex and a delete button per row; a click on a row selects the
// pair (its markers grow). Knows nothing about meshes: the panel gives it the pairs.
import { pairColor } from '../view/landmark-markers.js';

const css = (rgb) => `rgb(${rgb.map((v) => Math.round(255 * v)).join(', ')})`;

export class LandmarkTable {
  // onSelect(index), onDelete(index)
  constructor({ onSelect, onDelete }) {
    this.element = document.createElement('table');
    this.element.className = 'landmarks';
    this.element.innerHTML = '<thead><tr><th>#</th><th>reference</th><th>source</th><th></th></tr></thead><tbody></tbody>';
    this.body = this.element.querySelector('tbody');
    this.onSelect = onSelect;
    this.onDelete = onDelete;
  }

  // pairs: [[r, s], ...] (welded indices), pending: {side, vertex} or null, selected: index or -1.
  show(pairs, pending, selected) {
    this.body.replaceChildren();
    pairs.forEach(([r, s], i) => {
      const row = document.createElement('tr');
      row.dataset.index = String(i);
      row.classList.toggle('selected', i === selected);
      const number = document.createElement('td');
      number.className = 'pair-number';
      number.textContent = String(i + 1);
      number.style.background = css(pairColor(i));
      const del = document.createElement('button');
      del.type = 'button';
      del.className = 'pair-delete';
      del.textContent = '×';
      del.title = `Delete pair ${i + 1}`;
      del.addEventListener('click', (e) => {
        e.stopPropagation();
        this.onDelete(i);
      });
      const cells = [number, ...[r, s].map((v) => Object.assign(document.createElement('td'), { textContent: String(v) })), document.createElement('td')];
      cells[3].append(del);
      row.append(...cells);
      row.addEventListener('click', () => this.onSelect(i === selected ? -1 : i));
      this.body.append(row);
    });
    if (pending) {
      const row = document.createElement('tr');
      row.className = 'pending';
      const cell = (text) => Object.assign(document.createElement('td'), { textContent: text });
      row.append(cell(String(pairs.length + 1)),
        cell(pending.side === 'reference' ? String(pending.vertex) : '…'),
        cell(pending.side === 'source' ? String(pending.vertex) : '…'), cell(''));
      this.body.append(row);
    }
    this.element.hidden = pairs.length === 0 && !pending;
  }
}
