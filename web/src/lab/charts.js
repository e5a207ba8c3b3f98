// The sampler lab's uPlot charts (through plot/chart.js): the discrepancy (and integration
// error) against N, the spectrum's radial average against the line P = 1, and a 1-D warp's
// observed and expected counts. Data from series.js.
import { draw, drop, empty, logX, minorLogGrid, labelHook } from '../plot/chart.js';
import { AXIS, LOG10_AXIS, lgAll, log10Range } from '../plot/axes.js';
import { colorAt } from '../palette.js';
import { SAMPLERS } from './model.js';
import { curveSeries, radialSeries, density1d } from './series.js';

const colorOfSampler = (name) => colorAt(Math.max(0, SAMPLERS.indexOf(name === 'independent' ? 'uniform' : name)));

/** Discrepancy (and RMS error) against N, log-log, reference slopes labelled "up to log factors". */
export function renderCurve(el, result) {
  if (!result) {
    drop('lab-curve');
    empty(el, 'Choose samplers and press Draw curves.');
    return;
  }
  const s = curveSeries(result);
  const data = [s.x];
  const series = [{}];
  for (const c of s.series) {
    data.push(lgAll(c.y));
    series.push({ label: c.label, stroke: colorOfSampler(c.sampler), width: 2, points: { show: true, size: 5 } });
  }
  for (const c of s.errors) {
    data.push(lgAll(c.y));
    series.push({ label: c.label, stroke: colorOfSampler(c.sampler), width: 1.5, dash: [6, 4], points: { show: true, size: 5, fill: '#fff' } });
  }
  const labels = [];
  for (const r of s.refs) {
    labels.push({ idx: data.length, label: r.order === 1 ? 'N⁻¹ (up to log factors)' : 'N⁻¹ᐟ² (up to log factors)' });
    data.push(lgAll(r.y));
    series.push({ label: r.label, stroke: '#888', width: 1, dash: [3, 4], points: { show: false } });
  }
  const all = [...s.series, ...s.errors, ...s.refs].flatMap((c) => c.y).filter((v) => v !== null && v > 0);
  const yRange = all.length ? log10Range(all) : [-4, 0];
  const xRange = [s.x[0], s.x[s.x.length - 1]];
  const sig = JSON.stringify(series.map((x) => x.label || ''));
  draw('lab-curve', el, sig, (c) => ({
    scales: { x: logX(c, 2), y: { range: () => c.yRange } },
    axes: [
      { ...AXIS, label: 'N [points]' },
      { ...AXIS, ...LOG10_AXIS, label: s.errors.length ? 'discrepancy (solid), RMS error (dashed)' : 'L2-star discrepancy (RMS over sets)' },
    ],
    series,
    hooks: { drawClear: [minorLogGrid], draw: [labelHook(labels)] },
  }), data, { xRange, yRange });
}

/** The radial average of the spectrum, with the line P = 1 of independent points. */
export function renderRadial(el, spectrum) {
  if (!spectrum) {
    drop('lab-radial');
    empty(el, 'No spectrum yet.');
    return;
  }
  const r = radialSeries(spectrum);
  const positive = r.y.filter((v) => v > 0);
  const yRange = positive.length ? log10Range([...positive, 1]) : [-2, 1];
  const data = [r.x, lgAll(r.y.map((v) => (v > 0 ? v : null))), lgAll(r.one)];
  draw('lab-radial', el, 'radial', (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [{ ...AXIS, label: 'frequency |k|' }, { ...AXIS, ...LOG10_AXIS, label: 'radially averaged power' }],
    series: [{}, { label: 'power', stroke: '#0072B2', width: 2, points: { show: false } },
      { label: 'P = 1 (independent points)', stroke: '#888', width: 1, dash: [4, 4], points: { show: false } }],
    hooks: { draw: [labelHook([{ idx: 2, label: 'P = 1: independent points' }])] },
  }), data, { xRange: [r.x[0] ?? 0, r.x[r.x.length - 1] ?? 1], yRange });
}

/** A 1-D warp's observed and expected counts per bin. */
export function renderDensity1d(el, result, coordinate) {
  if (!result) {
    drop('lab-warp1d');
    el.replaceChildren();
    return;
  }
  const d = density1d(result);
  draw('lab-warp1d', el, `warp1d ${coordinate}`, (c) => ({
    scales: { x: { time: false, range: () => c.xRange } },
    axes: [{ ...AXIS, label: coordinate }, { ...AXIS, label: 'samples per bin', size: 62 }],
    series: [{}, { label: 'observed', stroke: '#D55E00', width: 1.5, points: { show: true, size: 4 } },
      { label: 'expected', stroke: '#1b1f24', width: 1.5, dash: [5, 3], points: { show: false } }],
  }), [d.x, d.observed, d.expected], { xRange: [Math.min(0, d.x[0]), Math.max(1, d.x[d.x.length - 1])] });
}
