// Tests of web/src/plot/axes.js: the tick labels of the log axes (10^k, N as plain numbers or
// 2^k, thinned to what fits), the log10 y ranges in whole decades, short durations and the axis
// texts of integration and render runs. Pure functions under Node's test runner.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  sup, decadeLabel, nTickLabels, lg, lgAll, log10Range, log10Ticks, shortSeconds, runLabels, isRender,
  fitAxisTitle,
} from '../src/plot/axes.js';

test('superscripts and decade labels', () => {
  assert.equal(sup(-12), '⁻¹²');
  assert.equal(sup(7), '⁷');
  assert.equal(decadeLabel(1), '1');
  assert.equal(decadeLabel(10), '10');
  assert.equal(decadeLabel(1e-3), '10⁻³');
  assert.equal(decadeLabel(1e20), '10²⁰');
  // minor ticks (2..9 x 10^k) and non-positive values get no label
  for (const v of [2e-3, 50, 0, -10, null, '10']) assert.equal(decadeLabel(v), '');
});

test('N ticks: plain numbers up to 6 digits, 2^k beyond, every label on a wide axis', () => {
  const small = [16, 32, 64, 128, 256];
  assert.deepEqual(nTickLabels(1000, small), ['16', '32', '64', '128', '256']);
  const large = [2 ** 16, 2 ** 18, 2 ** 20];
  assert.deepEqual(nTickLabels(1000, large), ['2¹⁶', '2¹⁸', '2²⁰']);
  // 999999 still plain: the notation changes only past six digits
  assert.deepEqual(nTickLabels(1000, [2 ** 19]), ['524288']);
  // a split that is not a power of two, or not positive, gets no label
  assert.deepEqual(nTickLabels(1000, [0, 16, 24, 32]), ['', '16', '', '32']);
});

test('N ticks are thinned from the last one when they do not fit side by side', () => {
  const splits = Array.from({ length: 13 }, (_, k) => 2 ** (k + 4)); // 16 .. 65536
  const labels = nTickLabels(300, splits);
  // 65536 needs about 52 px; 300 px for 12 gaps of 25 px: every 4th label, counted from the last
  assert.equal(labels[labels.length - 1], '65536');
  labels.forEach((l, i) => assert.equal(l !== '', (splits.length - 1 - i) % 4 === 0, `${splits[i]}: '${l}'`));
});

test('log10 values and ranges in whole decades', () => {
  assert.equal(lg(1000), 3);
  assert.equal(lg(null), null);
  assert.equal(lg(undefined), null);
  assert.deepEqual(lgAll([1, 0.01, null]), [0, -2, null]);
  assert.deepEqual(log10Range([3e-5, 2e-2]), [-5, -1]);
  assert.deepEqual(log10Range([1e-3]), [-4, -2]); // one decade each side of an exact power
  assert.deepEqual(log10Range([]), [-6, 0]); // decadeRange's fallback
  // far below uPlot's own log scale (1e-32): the reason the y values are log10
  assert.deepEqual(log10Range([1e-40, 1e-35]), [-40, -35]);
  assert.deepEqual(log10Ticks(null, [-3, -2.5, 0, 1]), ['10⁻³', '', '1', '10']);
});

test('short durations', () => {
  assert.equal(shortSeconds(1.5), '1.5 s');
  assert.equal(shortSeconds(0.0123), '12 ms');
  assert.equal(shortSeconds(1e-4), '100 µs');
  assert.equal(shortSeconds(2.5e-5), '25 µs');
});

test('axis texts of an integration run and of a render run', () => {
  const integral = runLabels({ kind: 'integral' });
  assert.equal(integral.n, 'N');
  assert.equal(integral.nAxis, 'N [samples]');
  assert.equal(integral.error, 'variance');
  assert.equal(integral.errorAxis, null);
  assert.equal(integral.timeAxis, 'wall time per estimate [seconds]');
  const render = runLabels({ kind: 'render', nName: 'spp', errorName: 'relative_mse' });
  assert.equal(render.nAxis, 'spp [samples per pixel]');
  assert.equal(render.error, 'relative MSE');
  assert.equal(render.errorAxis, 'relative MSE against the reference');
  assert.equal(render.rootAxis, 'relative RMSE (√ relative MSE)');
  assert.equal(render.timeAxis, 'wall time per image [seconds]');
  assert.equal(runLabels({ errorName: 'mean_abs_error' }).error, 'mean abs error');
  assert.equal(isRender({ kind: 'render' }), true);
  assert.equal(isRender({ kind: 'integral' }), false);
});

test('axis titles fit their axis: whole where they fit, else without asides, else cut with an ellipsis', () => {
  const width = (t) => t.length * 7; // a font of 7 px a character
  const fitsIn = (px) => (t) => width(t) <= px;
  const title = 'seconds per image (its bands\' seconds / workers)';
  assert.equal(fitAxisTitle(title, fitsIn(1000)), title);
  assert.equal(fitAxisTitle(title, fitsIn(200)), 'seconds per image');
  assert.equal(fitAxisTitle('spp [samples per pixel]', fitsIn(100)), 'spp');
  const cut = fitAxisTitle(title, fitsIn(70));
  assert.equal(cut, 'seconds…');
  assert.ok(width(cut) <= 70);
  // every result fits, down to a single character and an ellipsis
  for (const px of [7, 14, 50, 90, 130, 400]) {
    const t = fitAxisTitle(title, fitsIn(px));
    assert.ok(width(t) <= Math.max(px, 14), `${px}: ${t}`);
  }
});
