// The Retarget job's timeline (under the view): play / pause, a scrub bar over the clip with
// the frames computed so far drawn under it (the buffered ranges), the time, the speed, and a
// small per-frame plot (bone-length change) under it. It only shows and reports: the panel owns
// the clock (lib/frame-store.js PlaybackClock).
import { fromHtml } from './dom.js';

const markup = `
<div class="timeline" hidden>
  <div class="timeline-row">
    <button id="rt-play" type="button" title="Play / pause (Space)">▶</button>
    <div class="timeline-track">
      <canvas id="rt-buffered" class="timeline-buffered" width="600" height="6" title="Frames computed so far"></canvas>
      <input id="rt-scrub" type="range" min="0" max="1" step="any" value="0" aria-label="Clip time" />
    </div>
    <span id="rt-time" class="timeline-time">0.00 s</span>
    <label class="timeline-speed" title="Playback speed">speed
      <select id="rt-speed">
        <option value="0.25">¼×</option><option value="0.5">½×</option><option value="1" selected>1×</option><option value="2">2×</option>
      </select>
    </label>
  </div>
  <div class="timeline-plot-row" hidden>
    <div class="timeline-plot-box"><canvas id="rt-plot" class="timeline-plot" width="600" height="40"></canvas><div class="timeline-plot-cursor"></div></div>
    <span id="rt-plot-label" class="timeline-plot-label"></span>
  </div>
</div>`;

// One series scaled to its own maximum (NaN = a gap); returns that maximum (1 when all are 0).
function drawSeries(g, c, values, color) {
  let max = 0;
  for (const v of values) if (Number.isFinite(v)) max = Math.max(max, v);
  if (!(max > 0)) max = 1;
  const n = values.length;
  g.strokeStyle = color;
  g.lineWidth = 1.5;
  g.beginPath();
  let pen = false;
  values.forEach((v, k) => {
    if (!Number.isFinite(v)) {
      pen = false;
      return;
    }
    const x = n > 1 ? (k / (n - 1)) * (c.width - 2) + 1 : c.width / 2;
    const y = c.height - 2 - (v / max) * (c.height - 6);
    if (pen) g.lineTo(x, y);
    else g.moveTo(x, y);
    pen = true;
  });
  g.stroke();
  return max;
}

export class Timeline {
  // onPlay(playing), onSeek(time), onSpeed(speed)
  constructor({ onPlay = () => {}, onSeek = () => {}, onSpeed = () => {} } = {}) {
    this.element = fromHtml(markup);
    const q = (id) => this.element.querySelector(`#${id}`);
    this.play = q('rt-play');
    this.scrub = q('rt-scrub');
    this.time = q('rt-time');
    this.speed = q('rt-speed');
    this.buffered = q('rt-buffered');
    this.plot = q('rt-plot');
    this.plotLabel = q('rt-plot-label');
    this.plotRow = this.element.querySelector('.timeline-plot-row');
    this.plotCursor = this.element.querySelector('.timeline-plot-cursor');
    this.playing = false;
    this.range = { start: 0, end: 1 };
    this.ranges = [];
    this.count = 0;
    this.play.addEventListener('click', () => onPlay(!this.playing));
    this.scrub.addEventListener('input', () => onSeek(Number(this.scrub.value)));
    this.speed.addEventListener('change', () => onSpeed(Number(this.speed.value)));
  }

  show(on) { this.element.hidden = !on; }

  setRange(start, end) {
    this.range = { start, end };
    this.scrub.min = String(start);
    this.scrub.max = String(Math.max(end, start + 1e-6));
  }

  setTime(t, frame = null) {
    if (document.activeElement !== this.scrub) this.scrub.value = String(t);
    this.time.textContent = `${t.toFixed(2)} s${frame == null ? '' : ` · frame ${frame + 1}/${this.count}`}`;
  }

  setPlaying(on) {
    this.playing = on;
    this.play.textContent = on ? '❚❚' : '▶';
    this.play.setAttribute('aria-pressed', String(on));
  }

  // ranges: [[first, end)] of frames computed, out of count.
  setBuffered(ranges, count) {
    this.ranges = ranges;
    this.count = count;
    const c = this.buffered;
    const w = c.clientWidth || c.width;
    if (c.width !== w) c.width = w;
    const g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    g.fillStyle = '#2e3544';
    g.fillRect(0, 0, c.width, c.height);
    if (!count) return;
    g.fillStyle = '#5b9cf2';
    for (const [a, b] of ranges) g.fillRect((a / count) * c.width, 0, Math.max(1, ((b - a) / count) * c.width), c.height);
  }

  // values: per frame (NaN = not computed), a fraction (drawn as %); label: what it is. second
  // (optional): another series {values, color, legend(max) → text} on its own scale (e.g. counts).
  setPlot(values, label, second = null) {
    this.plotRow.hidden = !values;
    if (!values) return;
    this.plotLabel.textContent = label;
    const c = this.plot;
    const w = c.clientWidth || c.width;
    if (c.width !== w) c.width = w;
    const g = c.getContext('2d');
    g.clearRect(0, 0, c.width, c.height);
    g.fillStyle = '#1a1f2a';
    g.fillRect(0, 0, c.width, c.height);
    const max = drawSeries(g, c, values, '#ffd23f');
    g.font = '10px system-ui, sans-serif';
    g.fillStyle = '#8d96a8';
    g.fillText(`max ${(100 * max).toFixed(1)} %`, 4, 10);
    this.plotMax = max;
    this.plotSecondMax = null;
    if (second) {
      const m2 = drawSeries(g, c, second.values, second.color);
      const text = second.legend(m2);
      g.fillStyle = second.color;
      g.fillText(text, c.width - g.measureText(text).width - 4, 10);
      this.plotSecondMax = m2;
    }
  }

  // A cursor on the plot at frame `frame` of `count`, with the value in the label's tooltip.
  markPlot(frame, count) {
    this.plotCursor.hidden = !(count > 1 && frame >= 0);
    if (this.plotCursor.hidden) return;
    this.plotCursor.style.left = `${(100 * frame) / (count - 1)}%`;
  }
}
