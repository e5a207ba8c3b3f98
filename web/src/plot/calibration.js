// The plots that check the error bars: the histogram of z = (estimate - exact) / std. error
// over the replicates against the standard normal density, and the coverage of the 95%
// intervals against N with its binomial band (render studies: the share of pixels covered).
import { calibrationSeries, coverageSeries, fmt } from '../series.js';
import { conservativeClaim, withinText, coverageText, coincidentGroups, coincidentNote } from '../claims.js';
import { withAlpha } from '../palette.js';
import { AXIS, runLabels, isRender } from './axes.js';
import { uPlot, dom, draw, drop, empty, setText, logX, nTicks } from './chart.js';
import { colorOf, setLegend } from './legend.js';

export const COVERAGE_NOTE = {
  integral: 'Share of replicates whose own 95% interval holds the exact value; grey: 0.95 and its binomial 95% band for the number of replicates.',
  render: 'Share of the pixels (and colour channels) whose own 95% error bar covers the reference pixel, averaged over the replicates; grey: 0.95. At 1 spp a pixel has no error bar.',
};

/** Draws the z-score histogram (state.calibration: all levels pooled, or one N) and its legend. */
export function renderCalibration(state, run, records) {
  const which = state.calibration;
  const cs = calibrationSeries(records, run.order, run.exact, which);
  const data = [cs.x, cs.normal, ...cs.series.map((s) => s.y)];
  const stepped = uPlot.paths.stepped({ align: 1 });
  const series = [{}, { label: 'standard normal', stroke: '#000', width: 2, points: { show: false } },
    ...cs.series.map((s) => {
      const color = colorOf(run, s.name);
      return { label: s.name, stroke: color, width: 2, fill: withAlpha(color, 0.08), paths: stepped, points: { show: false } };
    })];
  let ymax = 0.45;
  for (const s of cs.series) for (const v of s.y) if (v !== null && v > ymax) ymax = v;
  const render = isRender(run);
  const names = runLabels(run);
  const known = run.exact !== null && run.exact !== undefined;
  const sig = JSON.stringify([run.order, run.colors, render, known]);
  const zLabel = render ? 'z = (image mean luminance − mean of replicates) / std. error'
    : known ? 'z = (estimate − exact) / std. error' : 'z = (estimate − mean of replicates) / std. error';
  draw('calibration', dom.calibration, sig, (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [
      { ...AXIS, label: zLabel, space: 40 },
      { ...AXIS, label: 'density', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
    ],
    series,
    cursor: { drag: { x: false, y: false } },
  }), data, { xRange: [cs.x[0], cs.x[cs.x.length - 1]], yRange: [0, Math.ceil(ymax * 1.1 * 10) / 10] });

  const note = document.getElementById('calibration-note');
  if (note) {
    note.textContent = render
      ? 'Render studies: z of each image\'s mean luminance against the mean of the level\'s replicates, over its own error bar (from the pixels\' variances; 1 spp gives none). A check of the size of the error bars, not of a bias.'
      : known
      ? 'Histogram of z = (estimate − exact) / std. error over the replicates, against the standard normal density (black): calibrated error bars follow it; about 95% of z lie within ±1.96.'
      : 'No exact value: z is taken against each N\'s mean of the replicates, which checks the size of the error bars but not a bias.';
  }
  setLegend('calibration', dom['legend-calibration'], [
    { name: 'N(0, 1)', color: '#000', ref: true, parts: [] },
    ...cs.series.map((s) => {
      const parts = [];
      const within = withinText(s, which, names.n);
      if (within) parts.push({ text: within, className: 'fit' });
      else if (s.exactRuns) parts.push({ text: 'exact to round-off: no z', className: 'fit' });
      else if (s.zeroSe) parts.push({ text: 'no z: every replicate has a zero error bar', className: 'fit' });
      else parts.push(run.status === 'running' ? 'no replicates yet' : 'no z');
      if (s.total && s.exactRuns) parts.push({ text: `${s.exactRuns} runs exact to round-off (no z)`, className: 'fit' });
      if (s.below + s.above) parts.push({ text: `${s.below + s.above} interval${s.below + s.above === 1 ? '' : 's'} far too narrow (z beyond ±5)`, className: 'badge' });
      if (s.zeroSe) parts.push({ text: `${s.zeroSe} with a zero error bar`, className: 'badge' });
      const wide = render ? null : conservativeClaim(records[s.name], { exact: run.exact, reps: run.settings ? run.settings.reps : null, nName: names.n });
      if (wide) parts.push({ text: wide.text, className: wide.holds === false ? 'badge' : 'fit' });
      return { name: s.name, color: colorOf(run, s.name), parts };
    }),
  ]);
}

/** Draws the coverage against N (none without an exact value) and its legend. */
export function renderCoverage(state, run, records) {
  const render = isRender(run);
  const names = runLabels(run);
  const cs = coverageSeries(records, run.order, run.ladder);
  const reps = run.settings ? run.settings.reps : 32;
  // Render studies: coverage is a share of pixels (not independent of each other): no band.
  const half = render ? 0 : 1.96 * Math.sqrt(0.95 * 0.05 / reps);
  setText('coverage-note', COVERAGE_NOTE[render ? 'render' : 'integral']);
  const data = [cs.x, cs.x.map(() => 0.95), cs.x.map(() => Math.min(1, 0.95 + half)), cs.x.map(() => 0.95 - half),
    ...cs.series.map((s) => s.y)];
  const series = [{}, { label: '0.95', stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } },
    { label: 'band high', stroke: 'transparent', width: 0, points: { show: false } },
    { label: 'band low', stroke: 'transparent', width: 0, points: { show: false } },
    ...cs.series.map((s) => {
      const color = colorOf(run, s.name);
      return { label: s.name, stroke: color, width: 2, points: { show: true, size: 6, fill: color } };
    })];
  let ymin = 0.8;
  for (const s of cs.series) for (const v of s.y) if (v !== null && v < ymin) ymin = v;
  ymin = Math.max(0, Math.floor((Math.min(ymin, 0.95 - half) - 0.02) * 10) / 10);
  const known = render || (run.exact !== null && run.exact !== undefined);
  if (!known) {
    drop('coverage');
    empty(dom.coverage, 'Coverage needs the exact value, which this scene does not know.');
  } else {
    const xRange = cs.x.length > 1 ? [cs.x[0], cs.x[cs.x.length - 1]] : [cs.x[0] / 2, cs.x[0] * 2];
    draw('coverage', dom.coverage, JSON.stringify([run.order, run.colors, reps, render, names.nAxis]), (c) => ({
      scales: { x: logX(c, 2), y: { range: () => c.yRange } },
      axes: [
        { ...AXIS, label: names.nAxis, values: nTicks, space: 30 },
        { ...AXIS, label: render ? 'pixels covered by their 95% error bars' : 'coverage of the 95% intervals', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 2)) },
      ],
      series,
      bands: [{ series: [2, 3], fill: 'rgba(120, 128, 136, 0.15)' }],
      cursor: { drag: { x: false, y: false } },
    }), data, { xRange, yRange: [ymin, 1.0001] });
  }
  // Curves that coincide (several estimators at 1.00) are drawn on top of each other: say so.
  const groups = coincidentGroups(cs.series);
  setLegend('coverage', dom['legend-coverage'], cs.series.map((s) => {
    const wide = render ? null : conservativeClaim(records[s.name], { exact: run.exact, reps, nName: names.n });
    const same = coincidentNote(s.name, groups);
    return {
      name: s.name,
      color: colorOf(run, s.name),
      parts: [{ text: coverageText(cs.x, s.y, names.n), className: 'fit' },
        wide && wide.coverageText ? { text: wide.coverageText, className: wide.holds === false ? 'badge' : 'fit' } : '',
        same ? { text: same, className: 'fit' } : ''],
    };
  }));
}
