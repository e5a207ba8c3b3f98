// The sample view (state.samples, #plot-samples): for each selected estimator, a card with its
// first points in the sampler's unit square (strata grid, VEGAS map, MISER boxes) and in the
// domain (1D: f at the points), and the running estimate of their weights; the replay of the
// first k points and the pair of axes a d > 2 set is shown on (presentation only: the state
// does not hold them); VEGAS's map through its training. renderSampleViews also draws the
// charts of weights.js from the same points.
import { replayIsEstimator, domainView, mapFor, mappedGrid } from '../series.js';
import { el } from '../dom.js';
import { densityWords } from '../claims.js';
import { dom, empty } from './chart.js';
import { sceneColor, swatch } from './legend.js';
import { PANEL, panel, dots, strataLines, mapLines, boxOutlines, strataText, runningPanel, firstRandomizationSize, sobolNetCells } from './sample_panels.js';
import { renderOverlay, renderMisWeights, renderWeights } from './weights.js';
import { largeText } from '../ui/text_size.js';

let samplesDrawn = null; // [data, weights, status, sceneInfo] last drawn
const BIG_PANEL = 400;   // logical size of the panels of a randomized QMC set's one randomization

// The replay of the sample view (presentation only, like VEGAS's training slider): the first k
// points of each set (null: all), and the pair of axes a set of d > 2 is projected on.
const replay = { k: null, axes: [0, 1], timer: null, state: null };

/** The sample view's own controls (#samples-k, #samples-play, the two axis selects), wired once. */
export function mountSampleControls() {
  const $ = (id) => document.getElementById(id);
  const slider = $('samples-k');
  if (!slider) return;
  const redraw = () => {
    const st = replay.state;
    if (st && st.samples.data) renderScatter(st, st.samples.data);
  };
  slider.addEventListener('input', () => {
    clearInterval(replay.timer);
    replay.k = Number(slider.value);
    redraw();
  });
  $('samples-play').addEventListener('click', () => {
    const st = replay.state;
    if (!st || !st.samples.data) return;
    clearInterval(replay.timer);
    // k from 1 to n in about 60 steps spaced evenly in log k, so that the first points are seen
    const n = st.samples.data.n;
    const steps = [...new Set(Array.from({ length: 61 }, (_, i) => Math.max(1, Math.round(n ** (i / 60)))))];
    let i = 0;
    replay.k = steps[0];
    redraw();
    replay.timer = setInterval(() => {
      i += 1;
      replay.k = steps[Math.min(i, steps.length - 1)];
      redraw();
      if (i >= steps.length - 1) clearInterval(replay.timer);
    }, 70);
  });
  for (const [id, at] of [['samples-axis-a', 0], ['samples-axis-b', 1]]) {
    $(id).addEventListener('change', (e) => {
      replay.axes = at === 0 ? [Number(e.target.value), replay.axes[1]] : [replay.axes[0], Number(e.target.value)];
      redraw();
    });
  }
}

/** The replay controls of a new point set: k back to all, axes offered for d > 2. */
function syncSampleControls(data) {
  const $ = (id) => document.getElementById(id);
  const slider = $('samples-k');
  if (!slider) return;
  const n = data ? data.n : 1;
  slider.max = String(n);
  slider.disabled = !data;
  $('samples-play').disabled = !data;
  const d = data ? data.dimension : 0;
  $('samples-axes-block').hidden = !(d > 2);
  if (d > 2) {
    if (!(replay.axes[0] < d && replay.axes[1] < d)) replay.axes = [0, 1];
    for (const [id, at] of [['samples-axis-a', 0], ['samples-axis-b', 1]]) {
      const sel = $(id);
      if (sel.options.length !== d) {
        sel.replaceChildren(...Array.from({ length: d }, (_, k) => el('option', { value: String(k) }, `${at === 0 ? 'across' : 'up'}: axis ${k + 1}`)));
      }
      sel.value = String(replay.axes[at]);
    }
  }
}

/** Draws the sample view and the charts of its weights, when the points or the scene changed. */
export function renderSampleViews(state) {
  if (!dom.samples) return;
  replay.state = state;
  const smp = state.samples;
  const sig = [smp.data, smp.weights, smp.status, state.sceneInfo, smp.message, largeText()];
  if (samplesDrawn && sig.every((v, i) => v === samplesDrawn[i])) return;
  if (!samplesDrawn || samplesDrawn[0] !== smp.data) {
    clearInterval(replay.timer);
    replay.k = null;
    syncSampleControls(smp.data);
  }
  samplesDrawn = sig;
  dom.samples.classList.toggle('loading', smp.status === 'loading');
  if (smp.status === 'error') {
    empty(dom.samples, `No sample points: ${smp.message}`);
  } else if (!smp.data) {
    empty(dom.samples, smp.status === 'loading' ? 'Drawing the points…' : 'Select an estimator to see its points.');
  } else {
    renderScatter(state, smp.data);
  }
  renderOverlay(state, smp.data);
  renderMisWeights(state, smp.data);
  renderWeights(state, smp.weights);
}

/** One card per estimator: its first k points in u and in the domain, and their running estimate. */
function renderScatter(state, data) {
  const d = data.dimension;
  const view = domainView(data, state.scene && state.scene.domain, replay.axes);
  const [a, b] = d > 2 ? view.axes : [0, 1];
  const k = Math.max(1, Math.min(data.n, replay.k ?? data.n));
  const exact = state.sceneInfo && typeof state.sceneInfo.exact === 'number' ? state.sceneInfo.exact : null;
  const out = document.getElementById('samples-k-out');
  if (out) out.textContent = `${k} of ${data.n} points`;
  const slider = document.getElementById('samples-k');
  if (slider && Number(slider.value) !== k) slider.value = String(k);
  const mapped = {};
  const cards = data.estimators.map((full) => {
    const color = sceneColor(state, full.name);
    // A randomized QMC set of K randomizations: only the first one is drawn (all K on top of
    // each other look like independent points); its points come first.
    const total = full.u[0] ? full.u[0].length : 0;
    const oneSet = firstRandomizationSize(full);
    const drawn = oneSet ?? total;
    const net = oneSet !== null || full.randomizations === 1 ? (d >= 2 ? sobolNetCells(full, drawn, [a, b]) : null) : null;
    // the first k points (the replay); the strata, map and boxes are the whole set's
    const first = (arr) => (Array.isArray(arr) ? arr.slice(0, Math.min(k, drawn)) : arr);
    const e = { ...full, u: full.u.map(first), x: full.x.map(first), f: first(full.f), weight: first(full.weight) };
    const n = e.u[0] ? e.u[0].length : 0;
    // u space: the sampler's unit square (1D: u against the point's index)
    // one randomization's panels are drawn large (its card spans two columns where there is room)
    const side = oneSet !== null ? BIG_PANEL : PANEL;
    const pu = panel(side, side, [0, 1], [0, 1]);
    const uy = d >= 2 ? e.u[b] : e.u[0].map((_, i) => (i + 0.5) / drawn);
    const drawU = (edges) => {
      pu.clear();
      strataLines(pu, net ? net[0] : e.strata[a], 'x');
      if (d >= 2) strataLines(pu, net ? net[1] : e.strata[b], 'y');
      if (edges) {
        mapLines(pu, edges[a], 'x');
        if (d >= 2 && edges[b]) mapLines(pu, edges[b], 'y');
      }
      if (e.boxes) boxOutlines(pu, e.boxes, d, [a, b]);
      pu.frame();
      pu.ctx.save();
      pu.clip();
      dots(pu.ctx, e.u[a], uy, pu.X, pu.Y, color, drawn);
      pu.ctx.restore();
    };
    drawU(e.map_edges);
    // the training history holds the map's first two axes only
    const training = a === 0 && b === 1 ? mapTraining(e, drawU) : null;
    // a designed set's spread is not the error of its first points' mean: no band
    const running = runningPanel(full, k, exact, color, replayIsEstimator(full));
    // x space: the domain (1D: f at the points, with the curve of f)
    let px;
    if (d === 1) {
      const curve = data.curve;
      // the y range of f on the grid (or at the points), cut as in the overlay for a singular f
      const all = (curve ? curve.f : e.f).filter(Number.isFinite);
      const lo = Math.min(0, ...all);
      let hi = Math.max(...all);
      // a maximum at an end of the grid is an endpoint singularity: cut it as the overlay does
      const atEnd = curve && (curve.f[0] === hi || curve.f[curve.f.length - 1] === hi);
      const sorted = all.slice().sort((a, b) => a - b);
      const q = sorted[Math.floor(0.75 * (sorted.length - 1))];
      if (atEnd && hi > 20 * q && q > 0) hi = 20 * q;
      if (!(hi > lo)) hi = lo + 1;
      px = panel(side, side, view.xRange, [lo, hi]);
      px.frame();
      px.ctx.save();
      px.clip();
      if (curve) {
        px.ctx.strokeStyle = '#8a8f96';
        px.ctx.lineWidth = 1;
        px.ctx.beginPath();
        curve.x.forEach((x, i) => (i ? px.ctx.lineTo(px.X(x), px.Y(curve.f[i])) : px.ctx.moveTo(px.X(x), px.Y(curve.f[i]))));
        px.ctx.stroke();
      }
      dots(px.ctx, e.x[0], e.f, px.X, px.Y, color, n);
      // rug
      px.ctx.strokeStyle = color;
      px.ctx.beginPath();
      const yb = px.Y(lo);
      for (const x of e.x[0]) {
        const cx = Math.round(px.X(x)) + 0.5;
        px.ctx.moveTo(cx, yb);
        px.ctx.lineTo(cx, yb - 5);
      }
      px.ctx.stroke();
      px.ctx.restore();
    } else {
      px = panel(side, side, view.xRange, view.yRange);
      px.ctx.save();
      px.clip();
      const o = view.outline;
      px.ctx.strokeStyle = '#5a6470';
      px.ctx.lineWidth = 1;
      px.ctx.beginPath();
      if (o.type === 'circle') {
        const r = Math.abs(px.X(o.cx + o.r) - px.X(o.cx));
        px.ctx.ellipse(px.X(o.cx), px.Y(o.cy), r, Math.abs(px.Y(o.cy + o.r) - px.Y(o.cy)), 0, 0, 2 * Math.PI);
      } else if (o.type === 'polygon') {
        o.points.forEach(([x, y], i) => (i ? px.ctx.lineTo(px.X(x), px.Y(y)) : px.ctx.moveTo(px.X(x), px.Y(y))));
        px.ctx.closePath();
      }
      px.ctx.stroke();
      // the strata cells in the domain, when the sampler's map is known (checked on its points)
      const known = e.strata.length === 2 && e.strata[0] <= 64 && e.strata[1] <= 64 && data.domain === 'disk'
        ? mapFor(e, state.scene && state.scene.domain) : null;
      if (known) {
        px.ctx.strokeStyle = 'rgba(90, 100, 112, 0.4)';
        px.ctx.beginPath();
        for (const line of mappedGrid(known.map, e.strata)) {
          line.forEach(([x, y], i) => (i ? px.ctx.lineTo(px.X(x), px.Y(y)) : px.ctx.moveTo(px.X(x), px.Y(y))));
        }
        px.ctx.stroke();
        mapped[e.name] = known.name;
      }
      dots(px.ctx, e.x[view.axes[0]], e.x[view.axes[1]], px.X, px.Y, color, drawn);
      px.ctx.restore();
      px.frame();
    }
    const facts = `${e.sampler}; p: ${densityWords(e)}; ${strataText(full, d)}`;
    // what the two panels show of a randomized QMC set, said where the points are
    const setCap = oneSet !== null
      ? `randomization 1 of ${full.randomizations}: its ${drawn} points (the run of N = ${total} averages ${full.randomizations} such sets)`
        + `${net ? `; grey: ${net[0]} × ${net[1]} cells, one point in each (a net)` : ''}`
      : net ? `one randomized sequence of ${drawn} points; grey: ${net[0]} × ${net[1]} cells, one point in each (a net)` : '';
    const runningCap = running ? `${running.text}. ${replayIsEstimator(full)
      ? 'Independent points: the mean of the first k is the estimate at N = k; shaded: its 95% interval.'
      : `A designed set: only all ${full.u[0].length} points make the estimate (the first k are not a design of k points).`}` : '';
    return el('div', { className: `sample-card${oneSet !== null ? ' one-set' : ''}`,
      dataset: { estimator: e.name, points: String(n), ...(oneSet !== null ? { randomizations: String(full.randomizations), shown: String(drawn) } : {}) } },
      el('h3', {}, swatch(color), e.name, el('span', { className: 'muted small' }, oneSet !== null ? `${n} of ${total} points: one randomization of ${full.randomizations}` : `${n} points`)),
      el('p', { className: 'facts' }, facts),
      training,
      setCap ? el('p', { className: 'set-cap' }, setCap) : null,
      el('div', { className: 'pair' },
        el('div', {}, pu.c, el('p', { className: 'cap' }, d === 1 ? 'u (across) by point index (up)' : d > 2 ? `u: axes ${a + 1} (across) and ${b + 1} (up) of ${d}` : 'u (unit square)')),
        el('div', {}, px.c, el('p', { className: 'cap' }, d === 1 ? 'x (across), f(x) (up); grey: f' : `x: ${view.labels.join(', ')}${view.note ? ` (${view.note})` : ''}${mapped[e.name] ? `; strata through the ${mapped[e.name]} map` : ''}`))),
      running ? el('div', { className: 'running', dataset: { k: String(k) } }, running.canvas,
        el('p', { className: 'cap' }, `running estimate: ${runningCap}`)) : null);
  });
  dom.samples.replaceChildren(...cards);
  const adaptive = data.estimators.find((e) => e.run_n > data.n);
  const qmc = data.estimators.find((e) => firstRandomizationSize(e) !== null);
  if (dom.samplesNote) {
    dom.samplesNote.textContent = `The first ${data.n} points of each selected estimator (replicate 0 of the study at N = ${data.n}, seed ${data.seed}):`
      + ' left in the unit square of its sampler (u) with its strata grid, right in the domain (x)'
      + `${view.note ? `, ${view.note}` : ''}. A polar map squeezes the cells of u near r = 0; the concentric map keeps them even.`
      + (adaptive ? ` Adaptive estimators (VEGAS, MISER) learn from a run of N = ${adaptive.run_n} (replicate 0 at that N):`
        + ` they show what it learnt and the first ${data.n} points of its estimate; the slider replays VEGAS's training.` : '')
      + (qmc ? ` A randomized quasi-Monte Carlo estimator (${qmc.name}) splits N into K independent randomizations of N/K points:`
        + ` its card draws the first randomization only (${firstRandomizationSize(qmc)} points of ${qmc.randomizations}`
        + ` sets here), since K sets drawn together look like independent points; choose more points to see a larger set.` : '');
  }
}

let trainingTimer = null;

/**
 * VEGAS's map through its training (e.map_history: the first two axes' edges before training
 * and after each iteration): a slider over the snapshots and a replay button that steps through
 * them. `drawU(edges)` redraws the unit-square panel; the last snapshot shows the frozen map.
 */
function mapTraining(e, drawU) {
  const h = e.map_history;
  if (!Array.isArray(h) || h.length < 2) return null;
  const last = h.length - 1;
  const label = el('span', { className: 'small muted map-step' });
  const slider = el('input', { type: 'range', min: '0', max: String(last), value: String(last), className: 'map-iteration' });
  slider.setAttribute('aria-label', `${e.name}: VEGAS map after training step`);
  const show = (k) => {
    slider.value = String(k);
    label.textContent = k === 0 ? 'map before training' : k === last ? `map after training (${last} steps): frozen` : `map after training step ${k} of ${last}`;
    drawU(k === last ? e.map_edges : h[k]);
  };
  slider.addEventListener('input', () => {
    clearInterval(trainingTimer);
    show(Number(slider.value));
  });
  const play = el('button', { type: 'button', className: 'replay', textContent: '▶ replay training' });
  play.addEventListener('click', () => {
    clearInterval(trainingTimer);
    let k = 0;
    show(k);
    trainingTimer = setInterval(() => {
      k += 1;
      show(k);
      if (k >= last) clearInterval(trainingTimer);
    }, 350);
  });
  show(last);
  return el('div', { className: 'map-training', dataset: { steps: String(last) } }, play, slider, label);
}
