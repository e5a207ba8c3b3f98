// The live view's two charts (through plot/chart.js, so their axes are the study's: log-log,
// powers of two for spp, decades for the relative MSE): each estimator's relative MSE against
// spp and against its seconds, one curve per estimator, a point per level as the passes arrive.
import { draw, drop, empty, logX, nTicks, minorLogGrid, labelHook } from '../plot/chart.js';
import { AXIS, LOG10_AXIS, lg, log10Range, decadeLabel } from '../plot/axes.js';
import { colorAt } from '../palette.js';
import { alignPoints } from './model.js';

function chart(key, el, live, xKey, emptyText) {
  const { order } = live;
  const { xs, ys } = alignPoints(order, live.estimators, xKey);
  if (!xs.length) {
    drop(key);
    empty(el, emptyText);
    return 0;
  }
  const all = ys.flat().filter((v) => v !== null);
  // the reference's own noise: relative MSEs near it measure the reference, not the image
  const floor = live.reference.floor > 0 ? live.reference.floor : null;
  const yRange = log10Range(floor ? [...all, floor] : all);
  const xRange = xKey === 'spp'
    ? [xs[0], Math.max(xs[xs.length - 1], xs[0] * 2)]
    : [10 ** Math.floor(Math.log10(xs[0])), 10 ** Math.ceil(Math.log10(xs[xs.length - 1]) + 1e-9)];
  const series = [{}, ...order.map((n) => {
    const color = colorAt(live.colors[n] ?? order.indexOf(n));
    return { label: n, stroke: color, width: 2, spanGaps: true, points: { show: true, size: 6, fill: color } };
  })];
  const data = [xs, ...ys.map((y) => y.map(lg))];
  if (floor) {
    series.push({ label: 'the reference\'s own noise', stroke: '#8a8f96', width: 1, dash: [6, 5], points: { show: false } });
    data.push(xs.map(() => lg(floor)));
  }
  draw(key, el, JSON.stringify([order, xKey, Boolean(floor)]), (c) => ({
    scales: { x: logX(c, xKey === 'spp' ? 2 : 10), y: { range: () => c.yRange } },
    axes: [
      xKey === 'spp'
        ? { ...AXIS, label: 'spp [samples per pixel]', values: nTicks }
        : { ...AXIS, label: 'seconds per image (its bands\' seconds / workers)', values: (u, splits) => splits.map(decadeLabel) },
      { ...AXIS, ...LOG10_AXIS, label: 'relative MSE against the reference' },
    ],
    series,
    hooks: { drawClear: [minorLogGrid], draw: [labelHook(floor ? [{ idx: data.length - 1, label: 'the reference\'s own noise' }] : [])] },
  }), data, { xRange, yRange });
  return all.length;
}

/** Draws both charts from the view's state; returns the number of points drawn in each. */
export function renderLiveCharts(dom, live) {
  const wait = live.reference.status === 'ready' || live.reference.status === 'none'
    ? 'The curves start with the first pass measured against the reference.'
    : 'The curves wait for the reference (its progress is shown above); the images converge meanwhile.';
  return {
    spp: chart('live-spp', dom.spp, live, 'spp', wait),
    seconds: chart('live-seconds', dom.seconds, live, 'seconds', wait),
  };
}
