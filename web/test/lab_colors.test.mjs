// Tests of the sampler lab's display mappings (web/src/lab/colors.js, web/src/lab/series.js):
// heat-map layout, colour scales, residual colours, spectrum brightness, the plots' series.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  heatGrid, gridPixels, sequentialColor, residualColor, RESIDUAL_SCALE, residuals, sharedMax, spectrumBrightness,
  spectrumPixels, NO_VALUE,
} from '../src/lab/colors.js';
import { curveSeries, radialSeries, density1d, binCentres } from '../src/lab/series.js';

test('heatGrid: the first coordinate varies fastest; row 0 is drawn at the bottom', () => {
  const g = heatGrid([1, 2, 3, 4, 5, 6], [3, 2]);
  assert.equal(g.nx, 3);
  assert.equal(g.ny, 2);
  assert.equal(g.at(0, 0), 1);
  assert.equal(g.at(2, 0), 3);
  assert.equal(g.at(0, 1), 4);
  assert.throws(() => heatGrid([1, 2, 3], [2, 2]), /3 values for 2 x 2 bins/);
  assert.equal(heatGrid([1, 2], [2]).ny, 1);
  // pixels: the top image row is j = 1
  const px = gridPixels(g, (v) => [v, 0, 0]);
  assert.equal(px.length, 3 * 2 * 4);
  assert.deepEqual([...px.slice(0, 4)], [4, 0, 0, 255]);
  assert.deepEqual([...px.slice(12, 16)], [1, 0, 0, 255]);
});

test('colour scales: viridis from dark to yellow, residuals blue-white-red, clipped, grey for no value', () => {
  assert.deepEqual(sequentialColor(0), [68, 1, 84]);
  assert.deepEqual(sequentialColor(1), [253, 231, 37]);
  assert.deepEqual(sequentialColor(2), [253, 231, 37]);
  assert.deepEqual(sequentialColor(NaN), [...NO_VALUE]);
  assert.deepEqual(residualColor(0), [247, 247, 247]);
  const [r, , b] = residualColor(3);
  assert.ok(r > b, 'positive residuals are red');
  const [r2, , b2] = residualColor(-3);
  assert.ok(b2 > r2, 'negative residuals are blue');
  assert.deepEqual(residualColor(null), [...NO_VALUE]);
});

test('residual colours on a fixed scale: noise pale, +-5 and beyond saturated, whatever the map\'s largest', () => {
  assert.equal(RESIDUAL_SCALE, 5);
  // structure saturates at the scale: 5 and 500 standard residuals are the same full red (blue)
  assert.deepEqual(residualColor(5), [178, 24, 43]);
  assert.deepEqual(residualColor(500), residualColor(5));
  assert.deepEqual(residualColor(-5), [33, 102, 172]);
  assert.deepEqual(residualColor(-500), residualColor(-5));
  // noise stays pale: |r| <= 1 (68% of a right warp's bins) keeps every channel above 215,
  // |r| = 2 above 190; 3 is already strong
  for (const v of [-1, -0.5, 0.5, 1]) assert.ok(Math.min(...residualColor(v)) > 215, `${v}: ${residualColor(v)}`);
  for (const v of [-2, 2]) assert.ok(Math.min(...residualColor(v)) > 190, `${v}: ${residualColor(v)}`);
  assert.ok(Math.min(...residualColor(3)) < 160, `3: ${residualColor(3)}`);
  // a bin's colour does not depend on the other bins (the old scale followed the largest |r|)
  const quiet = gridPixels(heatGrid([2, 3], [2]), residualColor);
  const wild = gridPixels(heatGrid([2, 80], [2]), residualColor);
  assert.deepEqual([...quiet.slice(0, 4)], [...wild.slice(0, 4)]);
  assert.equal(sharedMax([1, 5, NaN], [7, null]), 7);
});

test('residuals: (o - e)/sqrt(e) per bin, null where nothing is expected; the core\'s own when it gives them', () => {
  assert.deepEqual(residuals({ observed: [110, 90, 3], expected: [100, 100, 0] }), [1, -1, null]);
  assert.deepEqual(residuals({ observed: [1], expected: [1], residuals: [0.25] }), [0.25]);
});

test('spectrum brightness: P = 1 is mid-grey, 0.1 black, 10 white, clipped beyond', () => {
  assert.equal(spectrumBrightness(1), 0.5);
  assert.equal(spectrumBrightness(0.1), 0);
  assert.equal(spectrumBrightness(10), 1);
  assert.equal(spectrumBrightness(1e-9), 0);
  assert.equal(spectrumBrightness(1e9), 1);
  assert.equal(spectrumBrightness(0), 0);
  const px = spectrumPixels([1, 1, 10, 0.1], 2); // rows ky = -1 (j = 0) then ky = 0 (j = 1)
  assert.deepEqual([...px.slice(0, 4)], [255, 255, 255, 255], 'top-left: the row j = 1, column 0');
  assert.deepEqual([...px.slice(8, 12)], [128, 128, 128, 255]);
  assert.throws(() => spectrumPixels([1, 2, 3], 2), /3 values for 2 x 2/);
});

test('curveSeries: one line per sampler, errors apart, reference slopes through the highest first point', () => {
  const s = curveSeries({
    curves: [
      { sampler: 'independent', n: [16, 64], l2_star_discrepancy: [0.1, 0.05], rms_error: [0.2, 0.1] },
      { sampler: 'sobol', n: [16, 64], l2_star_discrepancy: [0.04, 0], rms_error: [0.01, 0.001] },
    ],
  });
  assert.deepEqual(s.x, [16, 64]);
  assert.deepEqual(s.series.map((c) => c.y), [[0.1, 0.05], [0.04, null]]);
  assert.deepEqual(s.errors.map((c) => c.label), ['independent RMS error', 'sobol RMS error']);
  assert.deepEqual(s.refs.map((r) => r.label), ['N^-1/2', 'N^-1']);
  assert.deepEqual(s.refs[0].y, [0.1, 0.05]);
  assert.deepEqual(s.refs[1].y, [0.1, 0.025]);
  assert.deepEqual(curveSeries({ curves: [{ sampler: 'sobol', n: [16], l2_star_discrepancy: [0.1] }] }).errors, []);
});

test('radialSeries and the 1-D densities', () => {
  const r = radialSeries({ radial: { frequency: [0, 1, 2], power: [0, 0.5, 1.5], count: [0, 4, 8] } });
  assert.deepEqual(r, { x: [1, 2], y: [0.5, 1.5], one: [1, 1] });
  assert.deepEqual(binCentres({ bins: [4] }), [0.125, 0.375, 0.625, 0.875]);
  assert.deepEqual(binCentres({ bins: [2], edges: [[0, 1, 3]] }), [0.5, 2]);
  assert.deepEqual(density1d({ bins: [2], observed: [3, 5], expected: [4, 4] }), { x: [0.25, 0.75], observed: [3, 5], expected: [4, 4] });
});

test('mapCounts: 2-D results as they are, 3-D ones summed over the third coordinate', async () => {
  const { mapCounts } = await import('../src/lab/colors.js');
  const two = { bins: [2, 1], observed: [1, 2], expected: [1.5, 1.5] };
  assert.deepEqual(mapCounts(two), { bins: [2, 1], observed: [1, 2], expected: [1.5, 1.5], summed: false });
  const three = { bins: [2, 1, 2], observed: [1, 2, 3, 4], expected: [1, 1, 2, 2] };
  assert.deepEqual(mapCounts(three), { bins: [2, 1], observed: [4, 6], expected: [3, 3], summed: true });
});
