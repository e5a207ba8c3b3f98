// Tests of web/src/state.js: the comparison in the URL and back, defaults, bad values, the
// reducer, custom scenes. Pure functions under Node's test runner: node --test web/test/
import { test } from 'node:test';
import assert from 'node:assert/strict';

import {
  stateToQuery, queryToState, sceneDefaults, parseWhole, paramError, reducer, initialState,
  createStore, runBlocker, statusText, buildCustomScene, customError, debugSnapshot, DEFAULTS, CUSTOM,
  KIND, kindOf, normalizeInfo, runSettings, studyOptions, studyNames, RENDER_LIMITS, raceResult, parseExact, urlProblems,
} from '../src/state.js';

const SCENE_DEFAULTS = { scene: 'disk_quarter', estimators: null, n_min: 16, n_max: 65536, reps: 32, seed: 1 };

test('a comparison survives the round trip through the URL', () => {
  const c = {
    scene: 'disk_third', estimators: ['uniform', 'stratified_polar'], n_min: 32, n_max: 4096, reps: 64,
    seed: 12345678901, f: '', p: '', exact: '',
  };
  const q = stateToQuery(c);
  assert.equal(q, '?scene=disk_third&estimators=uniform,stratified_polar&n_min=32&n_max=4096&reps=64&seed=12345678901');
  assert.deepEqual(queryToState(q, SCENE_DEFAULTS), c);
});

test('custom f and p survive the round trip, whatever characters they hold', () => {
  const c = {
    scene: CUSTOM, estimators: ['uniform', 'importance'], n_min: 16, n_max: 1024, reps: 8, seed: 0,
    f: 'exp(-(x-0.5)^2/0.01) + pow(x, 2)*1e-3 & #?=%', p: 'abs(x - 1/2)^-0.5 + 0.05', exact: '-1.5e-3',
  };
  const q = stateToQuery(c);
  assert.doesNotMatch(q, /[ #]/, 'spaces and # are escaped');
  assert.match(q, /\^/, 'the caret stays readable');
  assert.deepEqual(queryToState(q, SCENE_DEFAULTS), c);
  // f and p are written for the custom scene only
  assert.doesNotMatch(stateToQuery({ ...c, scene: 'exp_1d' }), /[&?]f=/);
});

test('the store state maps to the same query as its comparison', () => {
  let s = initialState();
  s = reducer(s, { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, {
    type: 'scene/loaded',
    payload: { sceneId: 'exp_1d', scene: {}, info: { estimators: ['uniform', 'stratified', 'importance'], n_min: 16, n_max: 1 << 20 } },
  });
  s = reducer(s, { type: 'estimator/set', payload: { name: 'stratified', checked: false } });
  s = reducer(s, { type: 'param/set', payload: { key: 'seed', value: '7' } });
  assert.equal(stateToQuery(s), '?scene=exp_1d&estimators=uniform,importance&n_min=16&n_max=65536&reps=32&seed=7');
});

test('an empty or foreign query gives the defaults', () => {
  assert.deepEqual(queryToState('', SCENE_DEFAULTS), { ...DEFAULTS, ...SCENE_DEFAULTS });
  assert.deepEqual(queryToState('?utm_source=x&foo=bar', SCENE_DEFAULTS), { ...DEFAULTS, ...SCENE_DEFAULTS });
  assert.deepEqual(queryToState(undefined, SCENE_DEFAULTS), { ...DEFAULTS, ...SCENE_DEFAULTS });
  assert.equal(queryToState('').n_max, 65536);
});

test('bad values are ignored one by one, the good ones kept', () => {
  const q = queryToState('?scene=exp_1d&n_min=abc&n_max=4096&reps=1&seed=-3', SCENE_DEFAULTS);
  assert.deepEqual(q, { ...DEFAULTS, ...SCENE_DEFAULTS, scene: 'exp_1d', n_max: 4096 });
  for (const [key, bad] of [
    ['n_min', '0'], ['n_min', '1.5'], ['n_min', '1e3'], ['n_min', ''], ['n_max', String(2 ** 36 + 1)],
    ['reps', '100001'], ['reps', '2.0'], ['seed', '9007199254740993'], ['seed', '0x10'], ['reps', ' 4 4'],
  ]) {
    assert.equal(queryToState(`?${key}=${encodeURIComponent(bad)}`, SCENE_DEFAULTS)[key], SCENE_DEFAULTS[key], `${key}=${bad}`);
  }
  // the extremes that are allowed
  assert.equal(queryToState(`?n_max=${2 ** 36}`, SCENE_DEFAULTS).n_max, 2 ** 36);
  assert.equal(queryToState('?reps=100000&seed=0', SCENE_DEFAULTS).reps, 100000);
  assert.equal(queryToState('?seed=0', SCENE_DEFAULTS).seed, 0);
});

test('an N range that is reversed or holds no power of two falls back to the default range', () => {
  assert.deepEqual(pick(queryToState('?n_min=4096&n_max=64', SCENE_DEFAULTS)), [16, 65536]);
  assert.deepEqual(pick(queryToState('?n_min=17&n_max=31', SCENE_DEFAULTS)), [16, 65536]);
  // n_max alone below the default n_min
  assert.deepEqual(pick(queryToState('?n_max=8', SCENE_DEFAULTS)), [16, 65536]);
  assert.deepEqual(pick(queryToState('?n_min=1&n_max=8', SCENE_DEFAULTS)), [1, 8]);
  function pick(q) {
    return [q.n_min, q.n_max];
  }
});

test('scene and estimator names are checked for their spelling, f selects the custom scene', () => {
  assert.equal(queryToState('?scene=../../etc/passwd', SCENE_DEFAULTS).scene, 'disk_quarter');
  assert.equal(queryToState('?scene=<script>', SCENE_DEFAULTS).scene, 'disk_quarter');
  assert.equal(queryToState('?scene=singular_power_0.5', SCENE_DEFAULTS).scene, 'singular_power_0.5');
  assert.deepEqual(queryToState('?estimators=uniform,,a b,uniform,stratified', SCENE_DEFAULTS).estimators, ['uniform', 'stratified']);
  assert.equal(queryToState('?estimators=,,', SCENE_DEFAULTS).estimators, null);
  assert.equal(queryToState('?scene=exp_1d&f=x%5E2', SCENE_DEFAULTS).scene, CUSTOM);
  assert.equal(queryToState('?scene=custom', SCENE_DEFAULTS).scene, 'disk_quarter', 'custom without f');
  assert.equal(queryToState(`?f=${'x+'.repeat(1001)}x`, SCENE_DEFAULTS).scene, 'disk_quarter', 'too long an f');
});

test('parseWhole and paramError accept whole numbers in range only', () => {
  assert.equal(parseWhole('42', 1, 100), 42);
  assert.equal(parseWhole(' 42 ', 1, 100), 42);
  assert.equal(parseWhole(42, 1, 100), 42);
  for (const bad of ['', '4.2', '-1', '1e2', 'abc', '101', null, undefined, {}]) assert.equal(parseWhole(bad, 1, 100), null, String(bad));
  assert.equal(paramError('reps', '32'), '');
  assert.match(paramError('reps', '1'), /reps must be a whole number in 2\.\.100000/);
});

test('sceneDefaults: the scene\'s own range with n_max capped at 65536, reps 32, seed 1', () => {
  assert.deepEqual(sceneDefaults({ n_min: 16, n_max: 1 << 20, reps: 64, seed: 9 }), { n_min: 16, n_max: 65536, reps: 32, seed: 1 });
  assert.deepEqual(sceneDefaults({ n_min: 4, n_max: 16384 }), { n_min: 4, n_max: 16384, reps: 32, seed: 1 });
  assert.deepEqual(sceneDefaults({ n_min: 1 << 17, n_max: 1 << 20 }), { n_min: 16, n_max: 65536, reps: 32, seed: 1 });
  assert.deepEqual(sceneDefaults(null), { n_min: 16, n_max: 65536, reps: 32, seed: 1 });
});

test('loading a scene selects all its estimators unless the URL named some', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  const info = { estimators: ['uniform', 'stratified_polar', 'latin_hypercube'], n_min: 16, n_max: 65536, exact: 0.25 };
  const all = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'disk_quarter', scene: {}, info } });
  assert.deepEqual(all.selected, info.estimators);
  const some = reducer(s, {
    type: 'scene/loaded',
    payload: { sceneId: 'disk_quarter', scene: {}, info, selected: ['latin_hypercube', 'nope', 'uniform'], params: { n_max: 1024 } },
  });
  assert.deepEqual(some.selected, ['uniform', 'latin_hypercube'], 'scene order, unknown names dropped');
  assert.equal(some.params.n_max, 1024);
  const none = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'disk_quarter', scene: {}, info, selected: ['nope'] } });
  assert.deepEqual(none.selected, info.estimators, 'no known name: all of them');
  s = reducer(all, { type: 'estimators/all', payload: { checked: false } });
  assert.deepEqual(s.selected, []);
  assert.equal(runBlocker(s), 'select at least one estimator');
});

test('choosing a scene shows its estimators at once; the core\'s answer keeps the edits made meanwhile', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, {
    type: 'scenes/loaded',
    payload: { scenes: [{ file: 'exp_1d.json', name: 'exp_1d', description: 'd', dimension: 1, estimators: ['uniform', 'stratified', 'importance'], n_min: 16, n_max: 1 << 20 }] },
  });
  s = reducer(s, { type: 'run/start', payload: { id: 1, workers: 1, settings: { n_min: 16, n_max: 32, reps: 2, seed: 1 }, order: ['x'], startedAt: 0 } });
  s = reducer(s, { type: 'scene/request', payload: { sceneId: 'exp_1d' } });
  assert.equal(s.sceneId, 'exp_1d');
  assert.deepEqual(s.selected, ['uniform', 'stratified', 'importance']);
  assert.equal(s.params.n_max, 65536);
  assert.equal(s.run.status, 'ready', 'the previous run is gone');
  assert.equal(runBlocker(s), 'loading the scene');
  s = reducer(s, { type: 'estimator/set', payload: { name: 'importance', checked: false } });
  s = reducer(s, { type: 'param/set', payload: { key: 'n_max', value: '1024' } });
  const info = { name: 'exp_1d', estimators: ['uniform', 'stratified', 'importance'], n_min: 16, n_max: 1 << 20, exact: Math.E - 1 };
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: { name: 'exp_1d' }, info } });
  assert.deepEqual(s.selected, ['uniform', 'stratified']);
  assert.equal(s.params.n_max, 1024);
  assert.equal(s.sceneInfo.exact, Math.E - 1);
  assert.equal(runBlocker(s), '');
  // an unknown scene name changes nothing but the notice
  assert.equal(reducer(s, { type: 'scene/request', payload: { sceneId: 'nope' } }).sceneId, 'exp_1d');
});

test('an invalid input is remembered as an error and blocks Run, the last good value kept', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'x', scene: {}, info: { estimators: ['uniform'] } } });
  assert.equal(runBlocker(s), '');
  s = reducer(s, { type: 'param/set', payload: { key: 'reps', value: '1' } });
  assert.equal(s.params.reps, 32);
  assert.match(runBlocker(s), /reps/);
  s = reducer(s, { type: 'param/set', payload: { key: 'reps', value: '8' } });
  assert.equal(s.params.reps, 8);
  assert.equal(runBlocker(s), '');
  s = reducer(s, { type: 'param/set', payload: { key: 'n_min', value: '100000' } });
  assert.match(runBlocker(s), /n_max \(65536\) must be >= n_min \(100000\)/);
  s = reducer(s, { type: 'param/set', payload: { key: 'n_min', value: '40000' } });
  s = reducer(s, { type: 'param/set', payload: { key: 'n_max', value: '60000' } });
  assert.match(runBlocker(s), /no power of two/);
});

test('a run streams levels, merges the workers\' parts and ends done; stale messages are ignored', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  assert.equal(statusText(s), 'ready');
  const settings = { n_min: 16, n_max: 32, reps: 2, seed: 1 };
  s = reducer(s, { type: 'run/start', payload: { id: 1, workers: 2, settings, order: ['a', 'b'], exact: 1, sceneName: 'x', startedAt: 0 } });
  assert.equal(statusText(s), 'running');
  const level = (name, n) => ({ name, sampler: 'independent', warnings: [], fit: { valid: false }, level: { n, variance: 1 / n } });
  s = reducer(s, { type: 'run/level', payload: { id: 1, level: { n: 16, estimators: [level('a', 16)] } } });
  s = reducer(s, { type: 'run/level', payload: { id: 0, level: { n: 16, estimators: [level('b', 16)] } } });
  assert.deepEqual(Object.keys(s.run.records), ['a']);
  assert.ok(Math.abs(s.run.progress - 16 / 96) < 1e-12);
  const part = (names) => ({
    version: 1, mcplay: '0.1.0', scene: { name: 'x' }, settings: { ...settings, threads: 1 }, cancelled: false, wall_time_s: 0.1,
    estimators: names.map((name) => ({ name, levels: [{ n: 16 }, { n: 32 }], fit: { valid: true, order: -1 } })),
  });
  s = reducer(s, { type: 'run/partial', payload: { id: 1, result: part(['b']), now: 5 } });
  assert.equal(s.run.status, 'running');
  s = reducer(s, { type: 'run/partial', payload: { id: 1, result: part(['a']), now: 10 } });
  assert.equal(statusText(s), 'done');
  assert.equal(s.run.progress, 1);
  assert.equal(s.run.elapsed, 10);
  assert.deepEqual(s.run.result.estimators.map((e) => e.name), ['a', 'b']);
  const snap = debugSnapshot(s);
  assert.deepEqual(structuredClone(snap), snap);
  assert.deepEqual(snap.estimators.map((e) => e.name), ['a', 'b']);
  assert.equal(snap.estimators[0].fit.order, -1);
});

test('cancel and errors set the status', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'run/start', payload: { id: 3, workers: 1, settings: { n_min: 16, n_max: 64, reps: 2, seed: 1 }, order: ['a'], startedAt: 100 } });
  const c = reducer(s, { type: 'run/cancel', payload: { now: 150 } });
  assert.equal(statusText(c), 'cancelled');
  assert.equal(c.run.elapsed, 50);
  assert.equal(reducer(c, { type: 'run/cancel', payload: { now: 200 } }), c, 'nothing to cancel');
  const e = reducer(s, { type: 'run/error', payload: { id: 3, message: 'settings: bad' } });
  assert.equal(statusText(e), 'error: settings: bad');
  assert.equal(reducer(s, { type: 'run/error', payload: { id: 2, message: 'old' } }), s, 'an old run\'s error');
});

test('the store queues actions dispatched by subscribers', () => {
  const store = createStore((st, a) => [...st, a.type], []);
  const seen = [];
  store.subscribe((st, a) => {
    seen.push([a.type, st.length]);
    if (a.type === 'first') store.dispatch({ type: 'second' });
  });
  store.dispatch({ type: 'first' });
  assert.deepEqual(seen, [['first', 1], ['second', 2]]);
  assert.deepEqual(store.getState(), ['first', 'second']);
});

test('custom scenes: interval in 1D, box beyond, importance only with p', () => {
  assert.deepEqual(buildCustomScene(' x^2 ', '', 1), {
    name: 'custom', description: 'f = x^2', f: 'x^2',
    domain: { type: 'interval', lower: 0, upper: 1 }, estimators: ['uniform', 'stratified', 'latin_hypercube'],
  });
  const s = buildCustomScene('x*y', 'x + y', 2);
  assert.deepEqual(s.domain, { type: 'box', dim: 2 });
  assert.deepEqual(s.estimators.slice(3), [{ name: 'importance', pdf: 'x + y' }, { name: 'stratified_importance', pdf: 'x + y' }]);
  assert.deepEqual(buildCustomScene('x', '', 0).domain, { type: 'interval', lower: 0, upper: 1 });
});

test('customError names the field and position of the core\'s message', () => {
  assert.deepEqual(customError({ message: "scene.f: at position 7: unknown function 'sinn'", field: 'scene.f', position: 7 }),
    { field: 'f', message: "scene.f: at position 7: unknown function 'sinn'", position: 7 });
  assert.deepEqual(customError({ message: 'scene.estimators[3].pdf.shape: at position 2: expected an expression' }),
    { field: 'p', message: 'scene.estimators[3].pdf.shape: at position 2: expected an expression', position: 2 });
  assert.deepEqual(customError(new Error('scene: something else')), { field: 'f', message: 'scene: something else', position: null });
});

// ---------------------------------------------------------------------------------------------
// Render scenes

// What the render core's sceneInfo says of a scene (mcp_render_scene_info), trimmed.
const RENDER_INFO_RAW = {
  name: 'quad_light_floor', description: 'floor', kind: 'render', width: 48, height: 48, triangles: 4, lights: 2,
  accel: { kind: 'brute_force' }, warnings: [],
  estimators: [
    { name: 'bsdf', strategy: 'bsdf', light_selection: 'power', light_sampling: 'solid_angle', pixel_sampler: 'stratified' },
    { name: 'light_area', strategy: 'light_area', light_selection: 'power', light_sampling: 'solid_angle', pixel_sampler: 'stratified' },
  ],
  settings: { n_min: 1, n_max: 64, reps: 4, seed: 1, threads: 1, n_name: 'spp', error_name: 'relative_mse' },
  reference: { estimator: { strategy: 'mis_power' }, spp: 1024 },
};
const RENDER_ENTRY = {
  file: 'quad_light_floor.json', name: 'quad_light_floor', description: 'floor', kind: 'render', dimension: null,
  estimators: ['bsdf', 'light_area'], n_min: 1, n_max: 64, reps: 4, width: 48, height: 48,
};

function renderState() {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'scenes/loaded', payload: { scenes: [RENDER_ENTRY] } });
  return reducer(s, { type: 'scene/loaded', payload: { sceneId: 'quad_light_floor', scene: { render: {} }, info: normalizeInfo(RENDER_INFO_RAW) } });
}

test('normalizeInfo: a render scene\'s info as the controls read it; integration info lists more presets', () => {
  const info = normalizeInfo(RENDER_INFO_RAW);
  assert.equal(kindOf(info), KIND.RENDER);
  assert.deepEqual(info.estimators, ['bsdf', 'light_area']);
  assert.equal(info.estimatorDetails[1].strategy, 'light_area');
  assert.deepEqual([info.n_min, info.n_max, info.reps, info.n_name, info.error_name], [1, 64, 4, 'spp', 'relative_mse']);
  assert.equal(info.exact, null);
  const integral = { name: 'exp_1d', estimators: ['uniform'], n_min: 16, n_max: 1024 };
  assert.deepEqual(normalizeInfo(integral), { ...integral, defaultSelected: ['uniform'] });
  assert.equal(kindOf(integral), KIND.INTEGRAL);
  // The presets the scene does not list come after its own, unselected at first.
  const more = normalizeInfo({ ...integral, more_estimators: ['uniform', 'sobol', 'lattice'] });
  assert.deepEqual(more.estimators, ['uniform', 'sobol', 'lattice']);
  assert.deepEqual(more.defaultSelected, ['uniform']);
  const loaded = reducer(initialState(), { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info: more } });
  assert.deepEqual(loaded.selected, ['uniform']);
  assert.equal(kindOf(null), KIND.INTEGRAL);
});

test('render defaults: the scene\'s spp range (capped), replicates and size clamped to the page\'s limits', () => {
  assert.deepEqual(sceneDefaults(normalizeInfo(RENDER_INFO_RAW)), { n_min: 1, n_max: 64, reps: 4, seed: 1, width: 48, height: 48 });
  assert.deepEqual(sceneDefaults({ kind: 'render', n_min: 1, n_max: 1 << 16, reps: 2000, width: 4096, height: 8 }),
    { n_min: 1, n_max: RENDER_LIMITS.firstRunSppMax, reps: 4, seed: 1, width: 256, height: 16 });
  assert.deepEqual(sceneDefaults({ kind: 'render' }), { n_min: 1, n_max: 64, reps: 4, seed: 1, width: 64, height: 64 });
});

test('a render comparison survives the URL; width and height only for render scenes, in their range', () => {
  const c = { scene: 'quad_light_floor', estimators: ['bsdf'], n_min: 1, n_max: 8, reps: 4, seed: 3, width: 16, height: 32, f: '', p: '', exact: '' };
  const q = stateToQuery(c);
  assert.equal(q, '?scene=quad_light_floor&estimators=bsdf&n_min=1&n_max=8&reps=4&seed=3&width=16&height=32');
  const d = { scene: 'quad_light_floor', estimators: null, n_min: 1, n_max: 64, reps: 4, seed: 1, width: 48, height: 48 };
  assert.deepEqual(queryToState(q, d, KIND.RENDER), c);
  // the render ranges: spp up to 2^20, replicates up to 1024, 16..256 pixels
  const bad = queryToState(`?n_max=${2 ** 20 + 1}&reps=1025&width=15&height=257`, d, KIND.RENDER);
  assert.deepEqual([bad.n_max, bad.reps, bad.width, bad.height], [64, 4, 48, 48]);
  const good = queryToState(`?n_min=2&n_max=${2 ** 20}&reps=1024&width=256&height=16`, d, KIND.RENDER);
  assert.deepEqual([good.n_min, good.n_max, good.reps, good.width, good.height], [2, 2 ** 20, 1024, 256, 16]);
  // an integral's URL ignores a size, and its ranges are its own
  const integral = queryToState('?width=16&n_max=4194304', SCENE_DEFAULTS);
  assert.equal(integral.width, undefined);
  assert.equal(integral.n_max, 4194304);

  // the store: width and height in the URL for the render scene only
  let s = renderState();
  assert.equal(stateToQuery(s), '?scene=quad_light_floor&estimators=bsdf,light_area&n_min=1&n_max=64&reps=4&seed=1&width=48&height=48');
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info: { estimators: ['uniform'], n_min: 16, n_max: 1024 } } });
  assert.doesNotMatch(stateToQuery(s), /width|height/);
});

test('render settings are checked against the render ranges, with spp in the messages', () => {
  assert.equal(paramError('width', '64', KIND.RENDER), '');
  assert.match(paramError('width', '300', KIND.RENDER), /width must be a whole number in 16\.\.256/);
  assert.match(paramError('n_max', String(2 ** 21), KIND.RENDER), /spp_max must be a whole number in 1\.\.1048576/);
  assert.match(paramError('reps', '2000', KIND.RENDER), /reps must be a whole number in 2\.\.1024/);
  assert.equal(paramError('reps', '2000'), '', 'integrals allow more replicates');
  let s = renderState();
  assert.equal(runBlocker(s), '');
  s = reducer(s, { type: 'param/set', payload: { key: 'height', value: '8' } });
  assert.match(runBlocker(s), /height must be a whole number in 16\.\.256/);
  assert.equal(s.params.height, 48, 'the last good value is kept');
  s = reducer(s, { type: 'param/set', payload: { key: 'height', value: '24' } });
  s = reducer(s, { type: 'param/set', payload: { key: 'n_min', value: '128' } });
  assert.match(runBlocker(s), /spp_max \(64\) must be >= spp_min \(128\)/);
});

test('a render run: its settings and options, spp and relative MSE as names, images as levels come in', () => {
  let s = renderState();
  s = reducer(s, { type: 'param/set', payload: { key: 'width', value: '16' } });
  const settings = runSettings(s);
  assert.deepEqual(settings, { n_min: 1, n_max: 64, reps: 4, seed: 1, width: 16, height: 48 });
  assert.deepEqual(studyOptions(KIND.RENDER, settings, ['bsdf']),
    { estimators: ['bsdf'], spp_min: 1, spp_max: 64, reps: 4, seed: 1, width: 16, height: 48, previews: true });
  assert.deepEqual(studyOptions(KIND.INTEGRAL, { n_min: 16, n_max: 32, reps: 2, seed: 1, width: 9 }, ['uniform']),
    { n_min: 16, n_max: 32, reps: 2, seed: 1, estimators: ['uniform'] });
  assert.deepEqual(studyNames(KIND.RENDER), { nName: 'spp', errorName: 'relative_mse' });
  assert.deepEqual(studyNames(KIND.INTEGRAL, true), { nName: 'N', errorName: 'mse' });

  s = reducer(s, { type: 'run/start', payload: { id: 1, kind: KIND.RENDER, workers: 2, settings: { ...settings, n_max: 2 }, order: ['bsdf', 'light_area'], exact: null, sceneName: 'quad_light_floor', startedAt: 0 } });
  assert.deepEqual([s.run.kind, s.run.nName, s.run.errorName], ['render', 'spp', 'relative_mse']);
  const est = (name, n, png) => ({
    name, strategy: name, warnings: [], fit: { valid: false }, preview_png: `${png}-image`, error_png: `${png}-error`,
    level: { n, variance: 1 / n, mse: 1 / n, warnings: [] },
  });
  s = reducer(s, { type: 'run/level', payload: { id: 1, level: { kind: 'render', level_index: 0, n: 1, estimators: [est('bsdf', 1, 'b1')] } } });
  assert.equal(s.run.records.bsdf.preview_png, 'b1-image');
  s = reducer(s, { type: 'run/level', payload: { id: 1, level: { kind: 'render', level_index: 1, n: 2, estimators: [est('bsdf', 2, 'b2')] } } });
  assert.deepEqual([s.run.records.bsdf.preview_png, s.run.records.bsdf.error_png], ['b2-image', 'b2-error'], 'the latest level\'s images');
  assert.equal(s.run.referencePng, null, 'the progress lines carry no reference');
  let snap = debugSnapshot(s);
  assert.deepEqual(snap.images, { reference: false, estimators: { bsdf: { preview: true, error: true, n: 2 } } });
  assert.equal(snap.estimators[0].preview_png, undefined, 'the snapshot leaves the PNGs out');

  const part = (names, seconds) => ({
    version: 1, kind: 'render', mcplay: '0.1.0', reference_png: 'REF',
    scene: { name: 'quad_light_floor', exact: 0.5, reference: { spp: 1024, seconds, mean_luminance: 0.5 } },
    settings: { n_min: 1, n_max: 2, reps: 4, seed: 1, threads: 1, n_name: 'spp', error_name: 'relative_mse' },
    cancelled: false, wall_time_s: 0.2,
    estimators: names.map((name) => ({ name, preview_png: `${name}-final`, levels: [{ n: 1 }, { n: 2 }], fit: { valid: true, order: -1 } })),
  });
  s = reducer(s, { type: 'run/partial', payload: { id: 1, result: part(['light_area'], 0.31), now: 5 } });
  assert.equal(s.run.referencePng, 'REF');
  s = reducer(s, { type: 'run/partial', payload: { id: 1, result: part(['bsdf'], 0.29), now: 9 } });
  assert.equal(statusText(s), 'done', 'parts whose reference took different times merge');
  assert.equal(s.run.records.bsdf.preview_png, 'bsdf-final');
  snap = debugSnapshot(s);
  assert.equal(snap.images.reference, true);
  assert.deepEqual(structuredClone(snap), snap);
});

test('choosing a render scene shows it at once from the manifest, with its size', () => {
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'scenes/loaded', payload: { scenes: [RENDER_ENTRY] } });
  s = reducer(s, { type: 'scene/request', payload: { sceneId: 'quad_light_floor' } });
  assert.equal(kindOf(s.sceneInfo), KIND.RENDER);
  assert.deepEqual(s.selected, ['bsdf', 'light_area']);
  assert.deepEqual(s.params, { n_min: 1, n_max: 64, reps: 4, seed: 1, width: 48, height: 48 });
  s = reducer(s, { type: 'param/set', payload: { key: 'width', value: '32' } });
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'quad_light_floor', scene: { render: {} }, info: normalizeInfo(RENDER_INFO_RAW) } });
  assert.equal(s.params.width, 32, 'an edit made while the scene loads is kept');
  // the quick image of the scene: only the latest request's answer is kept
  s = reducer(s, { type: 'preview/request', payload: { key: 1 } });
  s = reducer(s, { type: 'preview/request', payload: { key: 2 } });
  assert.equal(reducer(s, { type: 'preview/loaded', payload: { key: 1, png: 'old' } }), s);
  s = reducer(s, { type: 'preview/loaded', payload: { key: 2, png: 'P', spp: 16, estimator: 'bsdf' } });
  assert.deepEqual([s.scenePreview.status, s.scenePreview.png], ['ready', 'P']);
});

test('the race: inputs, one part per estimator, done when all are in; a new scene clears it', () => {
  let s = initialState();
  s = reducer(s, { type: 'core/ready', payload: { version: '0.1.0' } });
  const info = { estimators: ['uniform', 'stratified'], n_min: 16, n_max: 4096 };
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info } });
  assert.equal(s.race.inputs.relTol, '1e-3');
  s = reducer(s, { type: 'race/edit', payload: { field: 'relTol', value: '1e-2' } });
  assert.equal(s.race.inputs.relTol, '1e-2');
  assert.equal(reducer(s, { type: 'race/edit', payload: { field: 'bogus', value: 1 } }), s, 'unknown fields are refused');

  s = reducer(s, { type: 'race/start', payload: { id: 1, order: ['uniform', 'stratified'], options: { rel_tol: 0.01, reps: 2, max_seconds: 1 }, sceneName: 'exp_1d', exact: 1.7, startedAt: 0 } });
  assert.equal(s.race.status, 'running');
  const part = (name) => ({ kind: 'stopping', stopping: { rel_tol: 0.01 }, estimators: [{ name, runs: [] }] });
  assert.equal(reducer(s, { type: 'race/part', payload: { id: 0, result: part('uniform'), now: 5 } }), s, 'an older race is ignored');
  s = reducer(s, { type: 'race/part', payload: { id: 1, result: part('stratified'), now: 5 } });
  assert.equal(s.race.status, 'running');
  assert.deepEqual(raceResult(s.race).estimators.map((e) => e.name), ['stratified']);
  s = reducer(s, { type: 'race/part', payload: { id: 1, result: part('uniform'), now: 9 } });
  assert.equal(s.race.status, 'done');
  assert.equal(s.race.elapsed, 9);
  assert.deepEqual(raceResult(s.race).estimators.map((e) => e.name), ['uniform', 'stratified'], 'in the scene order');
  assert.equal(debugSnapshot(s).race.status, 'done');

  // a scene that asks for stopping fills the tolerance; the race's result is gone
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'other', scene: { abs_tol: 1e-4 }, info } });
  assert.equal(s.race.status, 'idle');
  assert.deepEqual(s.race.order, []);
  assert.equal(s.race.inputs.absTol, '0.0001');
  assert.equal(s.race.inputs.relTol, '');
});

test('the custom problem: an exact value goes into the scene and the URL; "Use this problem" keeps the settings', () => {
  assert.equal(parseExact(' 0.25 '), 0.25);
  assert.equal(parseExact('-1e-3'), -1e-3);
  for (const bad of ['', 'pi', '1/3', '1e999', 'NaN']) assert.equal(parseExact(bad), null, bad);
  assert.equal(buildCustomScene('x', '', 1, 0.5).exact, 0.5);
  assert.equal('exact' in buildCustomScene('x', '', 1, null), false);
  // a bad exact value in a link is dropped, not used
  assert.equal(queryToState('?f=x&exact=abc', SCENE_DEFAULTS).exact, '');
  assert.equal(customError({ message: 'scene.exact: expected a number, got a string' }).field, 'exact');

  let s = initialState();
  s = reducer(s, { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info: { estimators: ['uniform'], n_min: 16, n_max: 4096 } } });
  s = reducer(s, { type: 'param/set', payload: { key: 'n_max', value: '1024' } });
  s = reducer(s, { type: 'param/set', payload: { key: 'reps', value: '8' } });
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: CUSTOM, scene: { f: 'x', exact: 0.5 }, info: { estimators: ['uniform'], n_min: 16, n_max: 65536, exact: 0.5 }, custom: { f: 'x', p: '', exact: '0.5' } } });
  assert.equal(s.params.n_max, 1024, 'n_max kept');
  assert.equal(s.params.reps, 8, 'reps kept');
  assert.match(stateToQuery(s), /&f=x&exact=0\.5$/);
});

test('urlProblems names every value of a link that cannot be used, and nothing else', () => {
  const available = ['uniform', 'stratified'];
  assert.deepEqual(urlProblems('?scene=exp_1d&n_min=16&n_max=1024&reps=8&estimators=uniform', available), []);
  assert.deepEqual(urlProblems('?scene=exp_1d&utm_source=x', available), [], 'foreign keys are not the page\'s');
  const p = urlProblems('?n_min=abc&reps=1&estimators=uniform,bogus&exact=pi', available);
  assert.deepEqual(p, [
    'n_min=abc is not a whole number in 1..68719476736',
    'reps=1 is not a whole number in 2..100000',
    "'bogus' is not an estimator of this scene",
    'exact=pi is not a number',
  ]);
  assert.deepEqual(urlProblems('?n_min=17&n_max=31'), ['n_min=17 and n_max=31 hold no power of two']);
  assert.deepEqual(urlProblems('?n_max=2048&width=9', null, KIND.RENDER), ['width=9 is not a whole number in 16..256']);
});

test('a finished run kept for comparison belongs to its scene', async () => {
  const { keptFor, keptLabel } = await import('../src/state.js');
  let s = initialState();
  s = reducer(s, { type: 'core/ready', payload: { version: '0.1.0' } });
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info: { estimators: ['uniform'], n_min: 16, n_max: 64 } } });
  s = reducer(s, { type: 'run/start', payload: { id: 1, workers: 1, settings: { n_min: 16, n_max: 64, reps: 4, seed: 1 }, order: ['uniform'], exact: 1, sceneName: 'exp_1d', startedAt: 0 } });
  assert.equal(reducer(s, { type: 'compare/keep', payload: {} }), s, 'a running study cannot be kept');
  s = reducer(s, { type: 'run/partial', payload: { id: 1, now: 5, result: { estimators: [{ name: 'uniform', levels: [{ n: 16 }], warnings: [] }] } } });
  assert.equal(s.run.status, 'done');
  s = reducer(s, { type: 'compare/keep', payload: {} });
  assert.equal(keptFor(s).label, 'N 16..64, 4 reps, seed 1');
  assert.equal(keptLabel(s.run), 'N 16..64, 4 reps, seed 1');
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'disk_third', scene: {}, info: { estimators: ['uniform'], n_min: 16, n_max: 64 } } });
  assert.equal(keptFor(s), null, 'not drawn on another scene');
  s = reducer(s, { type: 'compare/clear' });
  assert.equal(s.kept, null);
});

test('a shipped reference that cannot be fetched is no longer announced as shipped', async () => {
  const { referenceText } = await import('../src/state.js');
  let s = reducer(initialState(), { type: 'core/ready', payload: { version: '0.1.0' } });
  const start = { id: 2, kind: KIND.RENDER, referenceShipped: true, workers: 1, settings: { n_min: 1, n_max: 4, reps: 2, seed: 1 }, order: ['mis'], startedAt: 0 };
  s = reducer(s, { type: 'run/start', payload: start });
  assert.equal(referenceText(s.run), 'the reference ships with the site');
  assert.equal(reducer(s, { type: 'run/reference-unavailable', payload: { id: 1 } }), s, 'another run\'s message is ignored');
  s = reducer(s, { type: 'run/reference-unavailable', payload: { id: 2 } });
  assert.equal(s.run.referenceShipped, false);
  assert.equal(referenceText(s.run), 'rendering the reference first…');
  s = reducer(s, { type: 'run/level', payload: { id: 2, level: { kind: 'render_reference', rows_done: 30, rows: 120 } } });
  assert.equal(referenceText(s.run), 'rendering the reference: 25% of its rows');
});
