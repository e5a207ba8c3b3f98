// Tests of web/src/plot/sample_panels.js without a canvas: the sentence each sample card gives
// about its point set's structure (strata, Latin hypercube, randomized QMC, VEGAS, MISER).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { strataText } from '../src/plot/sample_panels.js';

test('strata, and the grids too fine to draw', () => {
  assert.equal(strataText({ strata: [8, 8] }, 2), 'strata 8 × 8 cells');
  assert.equal(strataText({ strata: [4, 4], samples_per_stratum: 2 }, 2), 'strata 4 × 4 cells, 2 points per stratum');
  assert.equal(strataText({ strata: [128] }, 1), 'strata 128 cells (too fine to draw)');
  // d > 2: the two axes shown, of all
  assert.equal(strataText({ strata: [2, 2, 2] }, 3), 'strata 2 × 2 (of 2 × 2 × 2) cells');
});

test('sets without strata', () => {
  assert.equal(strataText({ strata: [], sampler: 'latin_hypercube' }, 2), 'Latin hypercube: one point per row and column');
  assert.equal(strataText({ strata: [], sampler: 'uniform' }, 2), 'no strata');
  const u = [Array(64).fill(0.5)];
  assert.equal(strataText({ u, randomizations: 4, randomization: 'owen' }, 2), '4 randomizations (owen randomization) of 16 points each');
  assert.equal(strataText({ u, randomizations: 1, randomization: 'none' }, 2), 'one point set (unrandomized)');
});

test('adaptive estimators: VEGAS map and MISER boxes', () => {
  const edges = (k) => Array.from({ length: k + 1 }, (_, i) => i / k);
  assert.match(strataText({ map_edges: [edges(50), edges(50)] }, 2), /^VEGAS map: 50 increments per axis \(brown lines\);/);
  assert.match(strataText({ map_edges: [edges(1000)] }, 1), /^VEGAS map: 1000 increments per axis \(brown lines: every 16th edge\);/);
  assert.match(strataText({ boxes: { lo: [[0, 0], [0.5, 0]], hi: [[0.5, 1], [1, 1]] } }, 2), /^MISER: 2 leaf regions \(brown boxes\);/);
});
