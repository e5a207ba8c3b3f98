// The first plot: each estimator's variance (its MSE when the exact value is known; a render
// study's relative MSE) against N on log-log axes, with its 95% band, the reference slopes
// N^-1, N^-2, N^-3 (spp^-1 for renders), a run kept for comparison dashed, and the levels that
// are exact to round-off marked along the bottom; its legend gives each estimator's fitted order.
import { varianceSeries, anchorOf, referenceLines } from '../series.js';
import { orderClaim, exactnessText, varianceNote, referenceFloorOf, referenceNoiseWords } from '../claims.js';
import { withAlpha } from '../palette.js';
import { keptFor } from '../state.js';
import { AXIS, LOG10_AXIS, sup, lgAll, log10Range, runLabels, isRender } from './axes.js';
import { uPlot, dom, draw, setText, logX, log10Y, nTicks, minorLogGrid, labelHook } from './chart.js';
import { colorOf, levelFlags, setLegend } from './legend.js';

/** Marks the levels that are exact to round-off (no point on a log axis): a row of squares in
 *  the series' colour along the bottom of the plot, one row per such estimator (the legend
 *  says which); filled where the replicates equal the exact value, hollow where they only agree
 *  with each other (claims/exact.js). */
function exactHook(rows) {
  return (u) => {
    if (!rows.length) return;
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    rows.forEach(({ color, exactAt }, r) => {
      const y = u.bbox.top + u.bbox.height - (7 + 11 * r) * px;
      ctx.fillStyle = color;
      ctx.strokeStyle = color;
      ctx.lineWidth = 1.5 * px;
      exactAt.forEach((kind, i) => {
        if (!kind) return;
        const x = u.valToPos(u.data[0][i], 'x', true);
        if (kind === 'exact') ctx.fillRect(x - 3.5 * px, y - 3.5 * px, 7 * px, 7 * px);
        else ctx.strokeRect(x - 3 * px, y - 3 * px, 6 * px, 6 * px);
      });
    });
    ctx.restore();
  };
}

let exactRows = [];

/** Draws the variance (MSE, relative MSE) plot of a run and its legend; `records` has every
 *  estimator of run.order (empty until its first level). */
export function renderVariance(state, run, records) {
  const render = isRender(run);
  const names = runLabels(run);
  // A render level's variance is its relative MSE against the reference (mse is the same number).
  // With a run kept for comparison (same scene), the x axis spans both ladders.
  const kept = keptFor(state);
  const xs = kept ? [...new Set([...run.ladder, ...kept.ladder])].sort((a, b) => a - b) : run.ladder;
  const vs = varianceSeries(records, run.order, render ? null : run.exact, xs);
  const anchor = anchorOf(vs.x, vs.series);
  const orders = render ? [1] : [1, 2, 3];
  const refs = referenceLines(vs.x, anchor, orders);
  const data = [vs.x];
  const series = [{}];
  const bands = [];
  const noiseAt = new Map(); // data index of a series -> its levels at the reference's noise
  vs.series.forEach((s) => {
    const color = colorOf(run, s.name);
    const yi = data.length;
    noiseAt.set(yi, s.noiseAt);
    data.push(lgAll(s.y), lgAll(s.hi), lgAll(s.lo));
    series.push(
      { label: s.name, stroke: color, width: 2, points: { show: true, size: 6, fill: color } },
      { label: `${s.name} 95% high`, stroke: withAlpha(color, 0.35), width: 0.5, points: { show: false } },
      { label: `${s.name} 95% low`, stroke: withAlpha(color, 0.35), width: 0.5, points: { show: false } },
    );
    bands.push({ series: [yi + 1, yi + 2], fill: withAlpha(color, 0.14) });
  });
  // The kept run's variance, dashed and lighter.
  const keptSeries = kept ? varianceSeries(kept.records, kept.order, render ? null : kept.exact, vs.x).series : [];
  keptSeries.forEach((s) => {
    const color = colorOf(run, s.name);
    data.push(lgAll(s.y));
    series.push({ label: `${s.name} (kept)`, stroke: withAlpha(color, 0.7), width: 1.5, dash: [5, 4],
      points: { show: true, size: 4, fill: '#fff' } });
  });
  // Three reference series always (all null until there is a first point), so the chart keeps
  // its series while the levels stream in.
  const refItems = [];
  orders.map((k) => `${render ? 'spp' : 'N'}${sup(-k)}`).forEach((label, i) => {
    refItems.push({ idx: data.length, label });
    data.push(refs[i] ? lgAll(refs[i].y) : vs.x.map(() => null));
    series.push({ label, stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } });
  });
  const values = [...vs.series.flatMap((s) => [...s.y, ...s.lo, ...s.hi]), ...keptSeries.flatMap((s) => s.y)];
  const yRange = log10Range(values);
  // Exact levels, drawn as a labelled row along the bottom (the hook reads the latest rows).
  exactRows = vs.series.filter((s) => s.exactAt.some(Boolean)).map((s) => ({ color: colorOf(run, s.name), exactAt: s.exactAt }));
  const xRange = vs.x.length > 1 ? [vs.x[0], vs.x[vs.x.length - 1]] : [vs.x[0] / 2, vs.x[0] * 2];
  const quantity = render ? names.errorAxis || names.error
    : vs.quantity === 'mse' ? 'MSE of the estimate' : 'variance of the estimate';
  const title = document.getElementById('variance-title');
  if (title) {
    title.textContent = render ? `${names.error[0].toUpperCase()}${names.error.slice(1)} against ${names.n}`
      : vs.quantity === 'mse' ? 'MSE against N (exact value known)' : 'Variance against N';
  }
  setText('variance-note', varianceNote(render ? 'render' : 'integral', records, run.order));
  // A render level at the reference's noise: its value in words in the hover readout.
  const noiseWords = render ? referenceNoiseWords(referenceFloorOf(run.result)) : null;
  const sig = JSON.stringify([vs.quantity, run.order, run.colors, run.kind, names.nAxis, quantity,
    keptSeries.map((k) => k.name)]);
  draw('variance', dom.variance, sig, (c) => ({
    scales: { x: logX(c, 2), y: log10Y(c) },
    axes: [
      { ...AXIS, label: names.nAxis, values: nTicks, space: 30 },
      { ...AXIS, ...LOG10_AXIS, label: quantity },
    ],
    series,
    bands,
    cursor: { drag: { x: false, y: false } },
    hooks: { drawAxes: [minorLogGrid], draw: [(u) => labelHook(refItems)(u), (u) => exactHook(exactRows)(u)] },
  }), data, { xRange, yRange, readoutWords: (k, i) => (noiseAt.has(k) && noiseAt.get(k)[i] ? noiseWords : null) });

  setLegend('variance', dom['legend-variance'], vs.series.map((s) => {
    const r = records[s.name];
    const exactValue = render ? null : run.exact;
    const measure = render ? names.error : 'variance';
    const order = orderClaim(r, { which: 'fit', exact: exactValue, nName: names.n, measure });
    const mseOrder = vs.quantity === 'mse' && !render && !s.exact
      ? orderClaim(r, { which: 'mse_fit', exact: exactValue, nName: names.n, measure: 'MSE' }) : null;
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [
        // The plotted MSE's own order, then the variance's (a flat MSE under a falling
        // variance is a bias: bias_dominates says from which N). A number only where a power
        // law holds (claims/fit.js).
        ...(mseOrder ? ['order of MSE', { text: mseOrder.text, className: 'fit' }] : []),
        ...(s.exact ? [{ fit: `${exactnessText(s.exact)} (${s.exact === 'exact' ? '■' : '□'} along the bottom)`, name: s.name }] : [
          render ? `order of ${names.error}` : vs.quantity === 'mse' ? 'of variance' : 'order of variance',
          { fit: order.text, name: s.name }]),
        ...levelFlags(r).map((w) => ({ warning: w })),
        ...(r.warnings || []).map((w) => ({ warning: w })),
      ],
    };
  }).concat(keptSeries.map((k) => ({
    name: `${k.name} (kept)`,
    color: withAlpha(colorOf(run, k.name), 0.7),
    dashed: true,
    parts: [{ text: `${kept.label}: order ${orderClaim(kept.records[k.name], { exact: render ? null : kept.exact, nName: names.n }).text}`, className: 'fit' }],
  }))));
}
