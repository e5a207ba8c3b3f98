// Tests of web/src/plot/legend.js without a DOM: an estimator keeps its scene's colour in every
// plot, and the legend shows a level's error or warning flag once, unless the estimator's own
// warnings already say it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { colorOf, sceneColor, levelFlags, hidesLabel, hiddenEstimators } from '../src/plot/legend.js';
import { colorAt } from '../src/palette.js';

test('colours follow the estimator, not its place in the run', () => {
  const run = { order: ['stratified', 'uniform'], colors: { uniform: 0, stratified: 3 } };
  assert.equal(colorOf(run, 'uniform'), colorAt(0));
  assert.equal(colorOf(run, 'stratified'), colorAt(3));
  // without run.colors: the place in the run
  assert.equal(colorOf({ order: ['a', 'b'] }, 'b'), colorAt(1));
  const state = { sceneInfo: { estimators: ['uniform', 'importance', 'vegas'] } };
  assert.equal(sceneColor(state, 'vegas'), colorAt(2));
  assert.equal(sceneColor(state, 'unknown'), colorAt(0));
  assert.equal(sceneColor({ sceneInfo: null }, 'vegas'), colorAt(0));
});

test('level flags: errors before warnings, one per code, none that the estimator already says', () => {
  const r = {
    warnings: [{ code: 'heavy_tail', severity: 'warning' }],
    levels: [
      { n: 16, warnings: [{ code: 'few_samples', severity: 'warning' }, { code: 'heavy_tail', severity: 'warning' }] },
      { n: 32, warnings: [{ code: 'few_samples', severity: 'warning' }, { code: 'nan_values', severity: 'error' }, { code: 'note', severity: 'info' }] },
      { n: 64, warnings: [{ code: 'no_severity' }] }, // a flag without a severity counts as a warning
    ],
  };
  assert.deepEqual(levelFlags(r).map((w) => w.code), ['nan_values', 'few_samples', 'no_severity']);
  assert.deepEqual(levelFlags({ levels: [] }), []);
  assert.deepEqual(levelFlags({}), []);
});

test('nothing is hidden before a legend click', () => {
  assert.deepEqual(hiddenEstimators(), []);
  assert.equal(hidesLabel('uniform 95% high'), false);
});
