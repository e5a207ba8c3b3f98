// Tests of the estimators a scene starts with selected: the tour's quasi-Monte Carlo stops
// select their Sobol', Halton and lattice points (which the scene files do not list), from the
// first moment the scene is shown (scene/request) to the core's answer (scene/loaded).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { reducer, initialState, defaultSelection, normalizeInfo } from '../src/state.js';
import { orderByTour, manifestEntry } from '../tools/build-site.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const QMC = ['sobol', 'halton', 'lattice'];

function manifest() {
  const files = fs.readdirSync(path.join(ROOT, 'scenes')).filter((f) => f.endsWith('.json'));
  const entries = files.map((f) => manifestEntry(f, JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', f), 'utf8'))));
  return orderByTour(entries, JSON.parse(fs.readFileSync(path.join(ROOT, 'web', 'tour.json'), 'utf8')));
}

test('the tour\'s quasi-Monte Carlo stops select randomized QMC points; the others select none they do not list', () => {
  const m = manifest();
  const qmcStops = m.filter((e) => /Quasi-Monte Carlo/.test(e.group || ''));
  assert.ok(qmcStops.length >= 3);
  for (const e of qmcStops) {
    const starts = Array.isArray(e.select) ? e.select : e.estimators;
    // a stop about QMC starts with QMC points selected (the Walsh-bound scene lists sobol itself)
    if (/genz_gaussian|genz_oscillatory|walsh/.test(e.name)) {
      assert.ok(starts.some((n) => QMC.includes(n) || /^sobol/.test(n)), `${e.name} starts with ${starts}`);
    }
  }
  for (const e of m.filter((x) => Array.isArray(x.select))) {
    assert.ok(e.select.length, e.name);
    for (const n of e.estimators) assert.ok(e.select.includes(n), `${e.name}: its own ${n} is not selected`);
  }
});

test('a tour selection: shown at once, kept through the core\'s answer; other scenes select their own', () => {
  const entry = { name: 'genz_gaussian_32d', file: 'genz_gaussian_32d.json', kind: 'integral', dimension: 32,
    estimators: ['uniform', 'stratified', 'latin_hypercube'], n_min: 16, n_max: 16384,
    select: ['uniform', 'stratified', 'latin_hypercube', 'sobol', 'halton', 'lattice'] };
  const plain = { name: 'exp_1d', file: 'exp_1d.json', kind: 'integral', dimension: 1, estimators: ['uniform', 'stratified'], n_min: 16, n_max: 65536 };
  let s = reducer({ ...initialState(), version: '1' }, { type: 'scenes/loaded', payload: { scenes: [plain, entry] } });
  s = reducer(s, { type: 'scene/request', payload: { sceneId: 'genz_gaussian_32d' } });
  assert.deepEqual(s.selected, entry.select, 'selected before the core answers');
  const info = normalizeInfo({ name: entry.name, estimators: entry.estimators, dimension: 32, n_min: 16, n_max: 16384,
    more_estimators: ['sobol', 'halton', 'lattice', 'sobol_walsh', 'vegas', 'miser'] });
  const loaded = reducer(s, { type: 'scene/loaded', payload: { sceneId: entry.name, scene: {}, info } });
  assert.deepEqual(loaded.selected, entry.select);
  // loaded straight (a link without estimators): the same selection
  const direct = reducer({ ...initialState(), version: '1', scenes: [plain, entry] },
    { type: 'scene/loaded', payload: { sceneId: entry.name, scene: {}, info } });
  assert.deepEqual(direct.selected, entry.select);
  // a scene without a selection in the tour: its own estimators, not the presets it does not list
  const expInfo = normalizeInfo({ name: 'exp_1d', estimators: ['uniform', 'stratified'], dimension: 1, more_estimators: ['sobol'] });
  const exp = reducer(loaded, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info: expInfo } });
  assert.deepEqual(exp.selected, ['uniform', 'stratified']);
});

test('defaultSelection: the tour\'s names the scene offers, in the scene\'s order, else its own', () => {
  const available = ['uniform', 'stratified', 'sobol', 'halton'];
  assert.deepEqual(defaultSelection(available, null, { select: ['halton', 'uniform', 'nonesuch'] }), ['uniform', 'halton']);
  assert.deepEqual(defaultSelection(available, { defaultSelected: ['uniform', 'stratified'] }, { select: ['nonesuch'] }), ['uniform', 'stratified']);
  assert.deepEqual(defaultSelection(available, null, null), available);
});
