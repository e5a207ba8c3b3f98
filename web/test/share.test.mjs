// Tests of web/src/share.js: the link "Copy link" gives carries the view of the plots (hidden
// estimators, the z histogram's N, the sample view's points, the images' view, the race inputs)
// and run=1, and the page reads back what it wrote.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { viewToQuery, queryToView, shareQuery, defaultView, hasView } from '../src/share.js';
import { queryToState, reducer, initialState } from '../src/state.js';

const VIEW = {
  hidden: ['stratified', 'importance'], calibration: 1024, points: 1024, imageView: 'both',
  race: { relTol: '1e-4', absTol: '', runs: '20', maxSeconds: '0.5' }, run: true,
};

test('a view survives the round trip through the link', () => {
  const q = viewToQuery(VIEW);
  assert.equal(q, 'hide=stratified,importance&cal=1024&points=1024&image_view=both&race_rel=1e-4&race_runs=20&race_seconds=0.5&run=1');
  // the race input left at its default is not written, and reads back as not given
  const back = queryToView(`?${q}`);
  assert.deepEqual(back, { ...VIEW, race: { relTol: '1e-4', runs: '20', maxSeconds: '0.5' } });
});

test('the default view writes nothing, and a link without a view reads as the default', () => {
  assert.equal(viewToQuery(defaultView()), '');
  assert.equal(viewToQuery({}), '');
  assert.deepEqual(queryToView('?scene=exp_1d&n_max=1024'), defaultView());
  assert.equal(hasView('?scene=exp_1d&n_max=1024'), false);
  assert.equal(hasView('?scene=exp_1d&hide=uniform'), true);
  assert.equal(hasView('?scene=exp_1d&run=1'), true);
});

test('a cleared race tolerance is written empty and read back empty', () => {
  const q = viewToQuery({ race: { relTol: '', absTol: '1e-6', runs: '10', maxSeconds: '2' } });
  assert.equal(q, 'race_rel=&race_abs=1e-6');
  assert.deepEqual(queryToView(`?${q}`).race, { relTol: '', absTol: '1e-6' });
});

test('unusable view values fall back to the defaults', () => {
  const v = queryToView('?hide=a<b>,ok,ok&cal=1000&points=300&image_view=sepia&race_rel=1e-3;alert(1)&run=yes');
  assert.deepEqual(v.hidden, ['ok']);
  assert.equal(v.calibration, 'all', '1000 is no power of two');
  assert.equal(v.points, 256);
  assert.equal(v.imageView, 'image');
  assert.deepEqual(v.race, {});
  assert.equal(v.run, false);
  assert.equal(queryToView('?cal=0').calibration, 'all');
  assert.equal(queryToView(`?cal=${2 ** 40}`).calibration, 'all', 'beyond the core\'s N');
  assert.equal(queryToView(`?cal=${2 ** 36}`).calibration, 2 ** 36);
});

test('the shared link: the comparison of the state, then its view; the comparison reads back too', () => {
  let s = reducer(initialState(), { type: 'scenes/loaded', payload: { scenes: [] } });
  const info = { name: 'exp_1d', estimators: ['uniform', 'stratified', 'importance'], n_min: 16, n_max: 1024, dimension: 1 };
  s = reducer(s, { type: 'scene/loaded', payload: { sceneId: 'exp_1d', scene: {}, info, selected: ['uniform', 'stratified'],
    params: { n_min: 16, n_max: 1024, reps: 8, seed: 3 } } });
  const q = shareQuery(s, { hidden: ['stratified'], calibration: 256, run: true });
  assert.equal(q, '?scene=exp_1d&estimators=uniform,stratified&n_min=16&n_max=1024&reps=8&seed=3&hide=stratified&cal=256&run=1');
  const c = queryToState(q, { scene: 'exp_1d' });
  assert.deepEqual([c.scene, c.estimators, c.n_min, c.n_max, c.reps, c.seed], ['exp_1d', ['uniform', 'stratified'], 16, 1024, 8, 3]);
  assert.deepEqual(queryToView(q), { ...defaultView(), hidden: ['stratified'], calibration: 256, run: true });
  // a reader's own glTF file cannot be in a link: no link
  const gltf = { ...s, sceneId: 'gltf-file' };
  assert.equal(shareQuery(gltf, { run: true }), '');
});
