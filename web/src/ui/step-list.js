// A guided list of steps (an <ol>): every step has a title and, while it is the current one, a
// line naming the next action. Steps before the current one are shown as done.
import { fromHtml } from './dom.js';

export class StepList {
  // steps: [{title}]
  constructor(steps) {
    this.element = fromHtml('<ol class="steps"></ol>');
    this.items = steps.map(({ title }) => {
      const li = fromHtml('<li><span class="step-title"></span><span class="step-next"></span></li>');
      li.querySelector('.step-title').textContent = title;
      this.element.append(li);
      return li;
    });
    this.current = 0;
  }

  // Makes step `index` (0-based) current, with `next` (text) as its next action.
  set(index, next) {
    this.current = index;
    this.items.forEach((li, i) => {
      li.classList.toggle('done', i < index);
      li.classList.toggle('current', i === index);
      li.querySelector('.step-next').textContent = i === index ? next : '';
    });
  }
}
