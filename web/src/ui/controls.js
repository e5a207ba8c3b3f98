// The form controls: scene, estimators, N range, replicates, seed, Run / Cancel, progress and
// status. Events only dispatch actions; sync(state) writes the state back into the controls
// (never into an input the user is typing in).
import { CUSTOM, runBlocker, statusText } from '../state.js';
import { colorAt } from '../palette.js';
import { fmt } from '../series.js';

const $ = (id) => document.getElementById(id);

const PARAM_INPUTS = { n_min: 'n-min', n_max: 'n-max', reps: 'reps', seed: 'seed' };

export function mountControls(store) {
  const { dispatch } = store;
  $('scene').addEventListener('change', (e) => {
    dispatch({ type: 'scene/request', payload: { sceneId: e.target.value } });
  });
  $('estimator-list').addEventListener('change', (e) => {
    const name = e.target.dataset.estimator;
    if (name) dispatch({ type: 'estimator/set', payload: { name, checked: e.target.checked } });
  });
  $('estimators-all').addEventListener('click', () => dispatch({ type: 'estimators/all', payload: { checked: true } }));
  $('estimators-none').addEventListener('click', () => dispatch({ type: 'estimators/all', payload: { checked: false } }));
  for (const [key, id] of Object.entries(PARAM_INPUTS)) {
    const onEdit = (e) => dispatch({ type: 'param/set', payload: { key, value: e.target.value } });
    $(id).addEventListener('input', onEdit);
    $(id).addEventListener('change', onEdit);
  }
  $('controls').addEventListener('submit', (e) => {
    e.preventDefault();
    dispatch({ type: 'run/request' });
  });
  $('cancel').addEventListener('click', () => dispatch({ type: 'run/cancel', payload: { now: performance.now() } }));
  $('samples-n').addEventListener('change', (e) => {
    dispatch({ type: 'samples/n', payload: { n: Number(e.target.value) } });
  });
  $('calibration-level').addEventListener('change', (e) => {
    dispatch({ type: 'calibration/set', payload: { value: e.target.value } });
  });
}

let scenesSig = null;
let estimatorsSig = null;
let calibrationSig = null;

function option(value, text) {
  const o = document.createElement('option');
  o.value = value;
  o.textContent = text;
  return o;
}

export function syncControls(state) {
  const sn = $('samples-n');
  if (sn && Number(sn.value) !== state.samples.n) sn.value = String(state.samples.n);
  // Scenes
  const sSig = JSON.stringify(state.scenes.map((s) => s.name));
  const select = $('scene');
  if (sSig !== scenesSig) {
    scenesSig = sSig;
    select.replaceChildren(...state.scenes.map((s) => option(s.name, `${s.name}  (${s.dimension ?? '?'}D)`)),
      option(CUSTOM, 'custom: f and p typed below'));
  }
  if (state.sceneId && select.value !== state.sceneId) select.value = state.sceneId;

  const info = state.sceneInfo;
  $('scene-description').textContent = info ? info.description || '' : '';
  $('scene-facts').textContent = info && info.provisional
    ? `dimension ${info.dimension ?? '?'} · loading…`
    : info
    ? [`dimension ${info.dimension}`, `domain ${info.domain}`,
      info.exact === null || info.exact === undefined ? 'exact value unknown' : `exact ${fmt(info.exact, 10)}`,
      `scene's N: ${info.n_min}..${info.n_max}`].join(' · ')
    : '';

  // Estimators
  const names = info ? info.estimators : [];
  const eSig = JSON.stringify([state.sceneId, names]);
  const list = $('estimator-list');
  if (eSig !== estimatorsSig) {
    estimatorsSig = eSig;
    list.replaceChildren(...names.map((name, i) => {
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.id = `est-${i}`;
      box.dataset.estimator = name;
      const label = document.createElement('label');
      label.htmlFor = box.id;
      const sw = document.createElement('span');
      sw.className = 'swatch';
      sw.style.background = colorAt(i);
      label.append(box, sw, name);
      return label;
    }));
  }
  const selected = new Set(state.selected);
  for (const box of list.querySelectorAll('input[data-estimator]')) box.checked = selected.has(box.dataset.estimator);

  // Numbers (not the one being edited, nor one holding an invalid text)
  for (const [key, id] of Object.entries(PARAM_INPUTS)) {
    const input = $(id);
    const invalid = Boolean(state.paramErrors[key]);
    input.setAttribute('aria-invalid', String(invalid));
    if (!invalid && document.activeElement !== input && input.value !== String(state.params[key])) {
      input.value = String(state.params[key]);
    }
  }

  // Run state
  const run = state.run;
  const running = run.status === 'running';
  const blocker = runBlocker(state);
  $('run').disabled = running || Boolean(blocker);
  $('cancel').disabled = !running;
  $('progress').value = run.progress;
  $('status').textContent = statusText(state);
  $('param-error').textContent = run.status === 'loading' ? '' : blocker;
  $('core-version').textContent = state.version ? `core ${state.version} (wasm)` : '';
  let info2 = '';
  if (run.workers) {
    const secs = run.elapsed !== null ? ` in ${(run.elapsed / 1000).toFixed(2)} s` : '';
    info2 = `${run.order.length} estimator${run.order.length === 1 ? '' : 's'} on ${run.workers} worker${run.workers === 1 ? '' : 's'}${secs}`;
    if (run.settings) info2 += ` · N ${run.settings.n_min}..${run.settings.n_max}, ${run.settings.reps} reps, seed ${run.settings.seed}`;
  }
  $('run-info').textContent = info2;
  $('notice').textContent = state.notice;

  // Calibration level choice: the N reached so far
  const done = new Set();
  for (const n of run.order) for (const l of (run.records[n] ? run.records[n].levels : [])) done.add(l.n);
  const ns = [...done].sort((a, b) => a - b);
  const cSig = JSON.stringify([run.id, ns]);
  const cal = $('calibration-level');
  if (cSig !== calibrationSig) {
    calibrationSig = cSig;
    cal.replaceChildren(option('all', 'all (pooled)'), ...ns.map((n) => option(String(n), String(n))));
  }
  const want = String(state.calibration);
  if (cal.value !== want && [...cal.options].some((o) => o.value === want)) cal.value = want;
}
