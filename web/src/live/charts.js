// The live view's two charts (through plot/chart.js, so their axes are the study's: log-log,
// powers of two for spp, decades for the relative MSE): each estimator's relative MSE against
// spp and against its seconds, one curve per estimator, a point per level as the passes arrive.
// A level at the reference's noise has no number: it is drawn as an open ring on the dashed
// floor (model.js: belowReferenceNoise), never below it.
import { draw, drop, empty, logX, nTicks, minorLogGrid, labelHook, uPlot } from '../plot/chart.js';
import { AXIS, LOG10_AXIS, lg, log10Range, decadeLabel } from '../plot/axes.js';
import { colorAt } from '../palette.js';
import { alignPoints } from './model.js';

/** Open rings on the floor (or the plot's bottom edge without one) at the levels of each
 *  series at the reference's noise: `noise[k]` lists series k + 1's x indices, drawn in colors[k]. */
function noiseRings(noise, floorY, colors) {
  return (u) => {
    const ctx = u.ctx;
    const px = uPlot.pxRatio || 1;
    ctx.save();
    ctx.lineWidth = 2 * px;
    noise.forEach((idx, k) => {
      const ser = u.series[k + 1];
      if (!ser || !ser.show || !idx.length) return;
      ctx.strokeStyle = colors[k];
      for (const i of idx) {
        const x = u.valToPos(u.data[0][i], 'x', true);
        const y = floorY === null ? u.bbox.top + u.bbox.height - 5 * px : u.valToPos(floorY, 'y', true);
        ctx.beginPath();
        ctx.arc(x, y, 5 * px, 0, 2 * Math.PI);
        ctx.stroke();
      }
    });
    ctx.restore();
  };
}

function chart(key, el, live, xKey, emptyText) {
  const { order } = live;
  // the reference's own noise: relative MSEs near it measure the reference, not the image
  const floor = live.reference.floor > 0 ? live.reference.floor : null;
  const { xs, ys, noise } = alignPoints(order, live.estimators, xKey, floor);
  if (!xs.length) {
    drop(key);
    empty(el, emptyText);
    return { points: 0, noise: 0, lowest: null };
  }
  const all = ys.flat().filter((v) => v !== null);
  const rings = noise.reduce((a, idx) => a + idx.length, 0);
  const yRange = log10Range(floor ? [...all, floor] : all.length ? all : [1]);
  const xRange = xKey === 'spp'
    ? [xs[0], Math.max(xs[xs.length - 1], xs[0] * 2)]
    : [10 ** Math.floor(Math.log10(xs[0])), 10 ** Math.ceil(Math.log10(xs[xs.length - 1]) + 1e-9)];
  const colors = order.map((n) => colorAt(live.colors[n] ?? order.indexOf(n)));
  const series = [{}, ...order.map((n, k) => {
    const color = colors[k];
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
    hooks: {
      drawClear: [minorLogGrid],
      draw: [labelHook(floor ? [{ idx: data.length - 1, label: 'the reference\'s own noise' }] : []), (u) => c.rings(u)],
    },
  }), data, { xRange, yRange, rings: noiseRings(noise, floor ? lg(floor) : null, colors) });
  return { points: all.length + rings, noise: rings, lowest: all.length ? Math.min(...all) : null };
}

/** Draws both charts from the view's state; returns for each {points (rings included), noise
 *  (the rings: levels at the reference's noise), lowest (the lowest relative MSE drawn as a
 *  number)}. */
export function renderLiveCharts(dom, live) {
  const wait = live.reference.status === 'ready' || live.reference.status === 'none'
    ? 'The curves start with the first pass measured against the reference.'
    : 'The curves wait for the reference (its progress is shown above); the images converge meanwhile.';
  return {
    spp: chart('live-spp', dom.spp, live, 'spp', wait),
    seconds: chart('live-seconds', dom.seconds, live, 'seconds', wait),
  };
}
