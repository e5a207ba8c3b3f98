// Tests of web/src/explain.js: every method the core names has an explanation, and the orders
// follow the dimension where they depend on it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { explainEstimator, EXPLAINED } from '../src/explain.js';

// The methods the core's estimator kinds name (src/estimators/registry.h estimator_method).
const CORE_METHODS = ['uniform', 'importance', 'stratified', 'stratified_importance', 'latin_hypercube', 'rqmc',
  'rqmc_walsh', 'qmc', 'vegas', 'vegas_plus', 'miser', 'mis', 'control_variates', 'antithetic', 'ris'];

test('every method the core names is explained, with a formula, an order and what to look for', () => {
  assert.deepEqual([...EXPLAINED].sort(), [...CORE_METHODS].sort());
  for (const method of CORE_METHODS) {
    const x = explainEstimator({ name: 'e', method, pdf: 'uniform' }, 2);
    assert.ok(x.title && x.formula && x.order && x.look, method);
    assert.match(x.formula, /I_N|map|bisect|VEGAS/, `${method}: ${x.formula}`);
  }
});

test('stratified orders follow the dimension: N^-(1+2/d) smooth, N^-(1+1/d) across an edge', () => {
  assert.match(explainEstimator({ method: 'stratified' }, 1).order, /N\^−3 for smooth f, N\^−2 across/);
  assert.match(explainEstimator({ method: 'stratified' }, 2).order, /N\^−2 for smooth f, N\^−1\.5 across/);
  assert.match(explainEstimator({ method: 'stratified_importance' }, 4).order, /N\^−1\.5 for smooth f, N\^−1\.25 across/);
  assert.match(explainEstimator({ method: 'stratified' }, null).order, /1\+2\/d/);
});

test('an unknown method gets a generic text, not an exception', () => {
  const x = explainEstimator({ name: 'x', method: 'teleport', pdf: 'p' });
  assert.equal(x.title, 'teleport');
  assert.equal(x.density, 'p');
  assert.equal(explainEstimator(null).title, 'Estimator');
});

test('a method without a text here shows the summary the core gives its kind', () => {
  const x = explainEstimator({ name: 'a', method: 'tempered', summary: 'a new kind, in one line', pdf: 'uniform' }, 1);
  assert.equal(x.title, 'tempered');
  assert.equal(x.look, 'a new kind, in one line');
  assert.equal(x.order, 'depends on the integrand');
});
