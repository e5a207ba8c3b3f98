// Tests of web/src/plot/coincide.js: curves that would hide each other on the f/p overlay and
// the weight histograms are found, so that the later one is drawn dashed and named.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { sameCurve, coincidences, COINCIDE_DASHES } from '../src/plot/coincide.js';

test('the same curve: equal where finite, within a share of the scale', () => {
  assert.equal(sameCurve([1, 1, 1], [1, 1, 1]), true);
  assert.equal(sameCurve([1, 2, null], [1, 2.0005, null], 1e-3), true);
  assert.equal(sameCurve([1, 2, 3], [1, 2.1, 3], 1e-3), false);
  assert.equal(sameCurve([1, null], [1, 2]), false, 'finite at different places');
  assert.equal(sameCurve([null, null], [null, null]), false, 'nothing drawn: nothing hidden');
  assert.equal(sameCurve([1, 2], [1, 2, 3]), false);
  // against the plot's height: 0.05 apart on a plot 20 high is less than a line's width
  assert.equal(sameCurve([1, 2], [1.05, 2], 0.004, 20), true);
  assert.equal(sameCurve([1, 2], [1.05, 2], 0.004), false);
});

test('groups: the first curve is solid, the ones equal to it come after it, ranked', () => {
  // exp_1d's overlay: f, uniform (p = 1), stratified (p = 1), importance, stratified_importance (same p)
  const f = [0.58, 0.8, 1.1, 1.58];
  const p = [0.6, 0.8, 1.1, 1.5];
  const one = [1, 1, 1, 1];
  const got = coincidences([{ name: 'f', y: f }, { name: 'uniform', y: one }, { name: 'stratified', y: one },
    { name: 'importance', y: p }, { name: 'stratified_importance', y: p }, { name: 'latin_hypercube', y: one }]);
  assert.deepEqual(got.map((c) => [c.name, c.of, c.rank]), [
    ['f', null, 0], ['uniform', null, 0], ['stratified', 'uniform', 1], ['importance', null, 0],
    ['stratified_importance', 'importance', 1], ['latin_hypercube', 'uniform', 2]]);
  assert.deepEqual(COINCIDE_DASHES[0], [], 'rank 0 is solid');
  assert.ok(COINCIDE_DASHES[1].length && COINCIDE_DASHES[2].length, 'the others dashed');
  // a density equal to f / ∫|f| is named after it
  const matched = coincidences([{ name: 'f / ∫|f|', y: p }, { name: 'importance_matched', y: p.map((v) => v * 1.0001) }]);
  assert.equal(matched[1].of, 'f / ∫|f|');
});
