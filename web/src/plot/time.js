// The second plot: each estimator's error (RMSE, or sqrt(variance) without an exact value)
// against its run time per estimate, on log-log axes: points joined in the order of N, each
// timing's 95% interval, reference slopes t^-1/2 and t^-1, the times too short for the clock
// shaded, adaptive estimators' time without training dashed; and under it the equal-time
// verdict and each slope's words (claims/equal_time.js, claims/time_slope.js).
import { timeSeries, CLOCK_STEPS_FITTED, decadeRange } from '../series.js';
import { equalTimeClaim, timeSlopeClaim, timeNote, referenceFloorOf } from '../claims.js';
import { AXIS, LOG10_AXIS, decadeLabel, lg, lgAll, log10Range, shortSeconds, runLabels, isRender } from './axes.js';
import { uPlot, charts, dom, draw, drop, empty, setText, logX, log10Y, minorLogGrid } from './chart.js';
import { colorOf, isHidden, setLegend } from './legend.js';
import { placeGuideLabels } from './guide_labels.js';
import { textPx } from '../ui/text_size.js';

/** Joins each series' points in the order of N (time is not monotone in N: uPlot's own
 *  lines would join them in the order of x). */
function pathsInOrder(getPaths) {
  return (u) => {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.beginPath();
    ctx.rect(u.bbox.left, u.bbox.top, u.bbox.width, u.bbox.height);
    ctx.clip();
    const guides = []; // the reference lines' names: drawn last, apart
    for (const { name, color, points, dash = null, whiskers = [], width = null, label = null } of getPaths()) {
      if (isHidden(name)) continue;
      // each point's timing interval (95%, over the replicates), with end caps
      ctx.strokeStyle = color;
      ctx.lineWidth = 1 * px;
      ctx.setLineDash([]);
      for (const [lo, hi, y] of whiskers) {
        const cy = u.valToPos(y, 'y', true);
        const x0 = u.valToPos(lo, 'x', true);
        const x1 = u.valToPos(hi, 'x', true);
        ctx.beginPath();
        ctx.moveTo(x0, cy); ctx.lineTo(x1, cy);
        ctx.moveTo(x0, cy - 3 * px); ctx.lineTo(x0, cy + 3 * px);
        ctx.moveTo(x1, cy - 3 * px); ctx.lineTo(x1, cy + 3 * px);
        ctx.stroke();
      }
      ctx.strokeStyle = color;
      ctx.lineWidth = (width ?? (dash ? 1.5 : 2)) * px;
      ctx.setLineDash(dash ? dash.map((v) => v * px) : []);
      ctx.beginPath();
      points.forEach(([x, y], i) => {
        const cx = u.valToPos(x, 'x', true);
        const cy = u.valToPos(y, 'y', true);
        if (i === 0) ctx.moveTo(cx, cy);
        else ctx.lineTo(cx, cy);
      });
      ctx.stroke();
      if (label && points.length) {
        // a reference line's name at its end (inside the plot), drawn once every line is
        const [x, y] = points[points.length - 1];
        guides.push({ label, x: Math.min(u.valToPos(x, 'x', true), u.bbox.left + u.bbox.width) - 2 * px, y: u.valToPos(y, 'y', true) - 2 * px });
      }
    }
    drawGuideLabels(u, ctx, guides, px);
    ctx.restore();
  };
}

/** The guide lines' names, right-aligned at their ends, moved apart where they would overlap
 *  (the t^-1/2 and t^-1 lines end close together on a short plot: a phone). */
function drawGuideLabels(u, ctx, guides, px) {
  if (!guides.length) return;
  ctx.setLineDash([]);
  ctx.fillStyle = '#555';
  const size = textPx(11);
  ctx.font = `${size * px}px "DejaVu Sans", sans-serif`;
  ctx.textAlign = 'right';
  ctx.textBaseline = 'bottom';
  const ys = placeGuideLabels(guides.map((g) => ({ x: g.x, y: g.y, width: ctx.measureText(g.label).width })),
    { height: (size + 2) * px, gap: 1 * px, top: u.bbox.top, bottom: u.bbox.top + u.bbox.height });
  guides.forEach((g, i) => ctx.fillText(g.label, g.x, ys[i]));
  lastGuideLabels = guides.map((g, i) => ({ label: g.label, x: g.x / px, y: ys[i] / px, wanted: g.y / px, height: size + 2 }));
}

// The guide labels as last drawn (CSS pixels): for tests (window.mcplayDebug.guideLabels).
let lastGuideLabels = [];
export function guideLabels() {
  return lastGuideLabels.map((g) => ({ ...g }));
}


/** Shades the times below `floor` seconds (too short for the clock) and says so. */
function clockBandHook(floor, stepSeconds) {
  return (u) => {
    if (!(floor > 0)) return;
    const x1 = u.valToPos(floor, 'x', true);
    const x0 = u.bbox.left;
    if (!(x1 > x0)) return;
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.fillStyle = 'rgba(120, 128, 138, 0.10)';
    ctx.fillRect(x0, u.bbox.top, Math.min(x1, u.bbox.left + u.bbox.width) - x0, u.bbox.height);
    ctx.fillStyle = '#5a6470';
    ctx.font = `${textPx(10) * px}px "DejaVu Sans", sans-serif`;
    ctx.textBaseline = 'bottom';
    ctx.textAlign = 'left';
    const text = `under ${CLOCK_STEPS_FITTED} clock steps (${shortSeconds(stepSeconds)}): not fitted`;
    ctx.fillText(text, x0 + 4 * px, u.bbox.top + u.bbox.height - 4 * px, Math.max(40 * px, x1 - x0 - 8 * px));
    ctx.restore();
  };
}

/** Draws the error-against-time plot of a run, its legend and the equal-time verdict. */
export function renderTime(state, run, records) {
  // The page's clock (performance.now, which the wasm core times with) rounds to a step: times
  // under CLOCK_STEPS_FITTED steps are drawn but not fitted.
  const step = state.clockStep > 0 ? state.clockStep / 1000 : 0;
  const floor = CLOCK_STEPS_FITTED * step;
  const ts = timeSeries(records, run.order, floor);
  const data = [ts.x, ...ts.series.map((s) => lgAll(s.y))];
  const noLine = () => null;
  const series = [{}, ...ts.series.map((s) => {
    const color = colorOf(run, s.name);
    return { label: s.name, stroke: color, width: 2, paths: noLine, points: { show: true, size: 7, fill: color } };
  })];
  const lines = ts.series.map((s) => ({
    name: s.name, color: colorOf(run, s.name), points: s.points.map(([t, e]) => [t, lg(e)]),
    whiskers: s.whiskers.map(([lo, hi, e]) => [lo, hi, lg(e)]),
  }));
  // Reference slopes, dashed grey, from the fastest timed point (at the largest error there) to
  // the right edge: t^-1/2 (Monte Carlo when the cost grows like N) and t^-1.
  const timed = ts.series.flatMap((s) => s.points).filter(([t]) => t >= floor);
  if (timed.length) {
    const t0 = Math.min(...timed.map(([t]) => t));
    const e0 = Math.max(...timed.filter(([t]) => t === t0).map(([, e]) => e));
    const tMax = Math.max(...ts.x);
    if (tMax > t0) {
      for (const [k, label] of [[0.5, 't⁻½'], [1, 't⁻¹']]) {
        lines.unshift({ name: `reference ${label}`, color: '#8a8f96', dash: [6, 5], width: 1, label,
          points: [[t0, lg(e0)], [tMax, lg(e0 * (tMax / t0) ** -k)]] });
      }
    }
  }
  // Adaptive estimators: dashed, the error at the time spent estimating only; the gap to the
  // solid line is what training (VEGAS) or probing (MISER) cost.
  for (const s of ts.series) {
    if (s.estimating.length) lines.push({ name: s.name, color: colorOf(run, s.name), dash: [6, 4], points: s.estimating.map(([t, e]) => [t, lg(e)]) });
  }
  const render = isRender(run);
  const names = runLabels(run);
  const known = render || (run.exact !== null && run.exact !== undefined);
  const xRange = decadeRange([...ts.x, ...ts.series.flatMap((s) => s.estimating.map(([t]) => t))], [1e-6, 1]);
  const yRange = log10Range(ts.series.flatMap((s) => s.y));
  // A short label where the plot is too short for the long one (a phone).
  const roomy = !dom.time || dom.time.clientHeight === 0 || dom.time.clientHeight >= 340;
  const yLabel = render ? names.rootAxis || names.error
    : known ? (roomy ? 'RMSE (error against the exact value)' : 'RMSE') : (roomy ? 'error = sqrt(variance)' : 'sqrt(variance)');
  const sig = JSON.stringify([run.order, run.colors, known, yLabel, names.timeAxis]);
  const title = document.getElementById('time-title');
  if (title) title.textContent = render ? 'Error against time per image' : 'Error against run time';
  const note = timeNote(render ? 'render' : 'integral');
  setText('time-kind-note', note.lead);
  setText('time-adaptive-note', note.adaptive);
  if (!ts.x.length) {
    drop('time');
    empty(dom.time, run.status === 'running' ? 'Waiting for the first N…' : 'No timings.');
  } else {
    draw('time', dom.time, sig, (c) => ({
      scales: { x: logX(c, 10), y: log10Y(c) },
      axes: [
        { ...AXIS, label: names.timeAxis, values: (u, splits) => splits.map(decadeLabel), space: 20 },
        { ...AXIS, ...LOG10_AXIS, label: yLabel },
      ],
      series,
      cursor: { drag: { x: false, y: false } },
      hooks: { drawAxes: [minorLogGrid, (u) => clockBandHook(charts.time.floor, charts.time.step)(u)],
        draw: [(u) => pathsInOrder(() => charts.time.lines)(u)] },
    }), data, { xRange, yRange, lines, floor, step });
  }
  // Each slope with its uncertainty, only where a line fits the timed points (claims/time_slope.js).
  const measure = known && !render ? 'mse' : 'variance';
  const exactValue = render ? null : run.exact;
  setLegend('time', dom['legend-time'], ts.series.map((s) => {
    const measureName = render ? names.error : measure === 'mse' ? 'MSE' : 'variance';
    const slope = timeSlopeClaim(records[s.name], { exact: exactValue, floorSeconds: floor, measure, nName: names.n, measureName });
    const fitFrom = slope.slope !== null && s.untimed ? ` (t ≥ ${shortSeconds(floor)})` : '';
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [slope.text ? { text: `${slope.text}${fitFrom}`, className: 'fit' } : '',
        s.trainingShare === null ? '' : { text: `training: ${Math.round(100 * s.trainingShare)}% of the time (dashed: without it)`, className: 'fit' }],
    };
  }));
  // The equal-time statement, once the run is over: none from times the clock cannot resolve.
  const verdict = run.status === 'running' ? null
    : equalTimeClaim(records, run.order, { exact: exactValue, floorSeconds: floor, clockKnown: state.clockStep > 0, render,
      referenceFloor: render ? referenceFloorOf(run.result) : null });
  setText('time-verdict', verdict ? verdict.text : '');
}
