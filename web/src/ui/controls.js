// The form controls: scene, estimators, N range, replicates, seed (and a render scene's image
// size), Run / Cancel, progress and status. Events only dispatch actions; sync(state) writes the
// state back into the controls (never into an input the user is typing in), and shows the
// panels of the kind of problem chosen: render scenes hide the custom problem and the sample
// points, and show the image size and the images.
import { CUSTOM, KIND, USER_GLTF, kindOf, paramRules, referenceText, runBlocker, statusText } from '../state.js';
import { colorAt } from '../palette.js';
import { fmt } from '../series.js';
import { renderFacts } from '../report.js';
import { sceneOptionLabel } from '../scene_title.js';

const $ = (id) => document.getElementById(id);

const PARAM_INPUTS = { n_min: 'n-min', n_max: 'n-max', reps: 'reps', seed: 'seed', width: 'width', height: 'height' };

export function mountControls(store) {
  const { dispatch } = store;
  $('gltf-file').addEventListener('change', (e) => {
    const files = [...(e.target.files || [])];
    if (files.length) dispatch({ type: 'gltf/open', payload: { files } });
    e.target.value = ''; // the same files may be chosen again
  });
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
  // The page's first focusable element: one Tab and Enter reach Run (Cancel while a run goes on).
  $('skip-to-run').addEventListener('click', (e) => {
    e.preventDefault();
    if ($('study-view').hidden) $('tab-study').click(); // from the sampler lab: back to the study
    const target = !$('run').disabled ? $('run') : !$('cancel').disabled ? $('cancel') : $('run');
    target.scrollIntoView({ block: 'nearest' });
    target.focus();
  });
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
let kindShown = null;

/** Shows the controls and panels of a kind of problem (once per change of kind). */
function showKind(kind) {
  if (kind === kindShown) return;
  kindShown = kind;
  const render = kind === KIND.RENDER;
  for (const e of document.querySelectorAll('.render-only')) e.hidden = !render;
  const hide = (id, yes) => { const e = $(id); if (e) e.hidden = yes; };
  hide('custom', render);
  hide('samples-section', render);
  hide('render-images-section', !render);
  $('n-min-label').textContent = render ? 'spp_min [samples per pixel]' : 'n_min [samples]';
  $('n-max-label').textContent = render ? 'spp_max [samples per pixel]' : 'n_max [samples]';
  $('ladder-note').textContent = render
    ? 'spp runs over the powers of two in [spp_min, spp_max]: each estimator renders “replicates” images of width × height pixels at each spp, compared with a reference image at many more spp (the site ships its scenes\' references; another image size renders its own first).'
    : 'N runs over the powers of two in [n_min, n_max].';
  const calLabel = document.querySelector('label[for="calibration-level"]');
  if (calLabel) calLabel.textContent = render ? 'spp' : 'N';
  const rules = paramRules(kind);
  for (const [key, id] of Object.entries(PARAM_INPUTS)) {
    const [lo, hi] = rules[key] || [];
    if (lo !== undefined) $(id).min = String(lo);
    if (hi !== undefined && hi <= Number.MAX_SAFE_INTEGER && key !== 'seed') $(id).max = String(hi);
  }
}

function sceneFacts(info) {
  if (!info) return '';
  const render = info.kind === KIND.RENDER;
  if (info.provisional) {
    return render ? `render scene · ${info.width}×${info.height} px · loading…` : `dimension ${info.dimension ?? '?'} · loading…`;
  }
  if (render) {
    const ref = info.reference || {};
    const refEst = ref.estimator ? ref.estimator.strategy : '?';
    return [`render scene ${info.width}×${info.height} px`, `${info.triangles} triangles`, `${info.lights} emitting triangles`,
      info.accel ? `accelerator ${info.accel.kind}` : null, `scene's spp: ${info.n_min}..${info.n_max}, ${info.reps} replicates`,
      `reference: ${refEst} at ${ref.spp} spp`,
      info.warnings && info.warnings.length ? `${info.warnings.length} loader warning(s): ${info.warnings.map((w) => w.message || w).join('; ')}` : null,
    ].filter(Boolean).join(' · ');
  }
  return [`dimension ${info.dimension}`, `domain ${info.domain}`,
    info.exact === null || info.exact === undefined ? 'exact value unknown' : `exact ${fmt(info.exact, 10)}`,
    `scene's N: ${info.n_min}..${info.n_max}`].join(' · ');
}

function option(value, text) {
  const o = document.createElement('option');
  o.value = value;
  o.textContent = text;
  return o;
}

/** The scene list: one group per stop of the teaching path (the manifest's `group`, in its
 *  order), then the custom problem; a manifest without groups is split by kind. */
function sceneOptions(scenes, userGltf) {
  const optgroup = (label, items) => {
    const g = document.createElement('optgroup');
    g.label = label;
    g.append(...items);
    return g;
  };
  // the readable title (the identifier is shown under the list, #scene-id)
  const label = (s) => sceneOptionLabel({ ...s, kind: kindOf(s) });
  const groups = new Map();
  // A warp without an integrand (kind 'warp') has no study: the sampler lab tests it.
  for (const s of scenes.filter((e) => e.kind !== 'warp')) {
    const title = s.group || (kindOf(s) === KIND.RENDER ? 'Render scenes (glTF)' : s.warp ? 'Warps (importance sampling)' : 'Integrals');
    if (!groups.has(title)) groups.set(title, []);
    groups.get(title).push(option(s.name, label(s)));
  }
  return [...[...groups].map(([title, items]) => optgroup(title, items)),
    optgroup('Your own integral', [option(CUSTOM, 'custom: f and p typed below')]),
    ...(userGltf ? [optgroup('Your own glTF scene', [option(USER_GLTF, `your file: ${userGltf}`)])] : [])];
}

/** The identifier of the scene shown, as the CLI takes it (#scene-id), under its title. */
function sceneIdentifier(state) {
  const entry = state.scenes.find((sc) => sc.name === state.sceneId);
  const box = $('scene-id');
  if (!box) return;
  let parts;
  if (entry) {
    parts = ['identifier ', ['code', entry.name], ' · in the CLI: ', ['code', `mcplay run scenes/${entry.file || `${entry.name}.json`}`]];
  } else if (state.sceneId === CUSTOM) {
    parts = ['identifier ', ['code', CUSTOM], ': the integral typed below'];
  } else if (state.sceneId === USER_GLTF && state.userGltf.name) {
    parts = ['your file ', ['code', state.userGltf.name]];
  } else {
    parts = [];
  }
  const sig = JSON.stringify(parts);
  if (box.dataset.sig === sig) return;
  box.dataset.sig = sig;
  box.replaceChildren(...parts.map((p) => {
    if (typeof p === 'string') return document.createTextNode(p);
    const c = document.createElement(p[0]);
    c.textContent = p[1];
    return c;
  }));
}

export function syncControls(state) {
  const sn = $('samples-n');
  if (sn && Number(sn.value) !== state.samples.n) sn.value = String(state.samples.n);
  // Scenes
  const sSig = JSON.stringify([state.scenes.map((s) => s.name), state.userGltf.name]);
  const select = $('scene');
  if (sSig !== scenesSig) {
    scenesSig = sSig;
    select.replaceChildren(...sceneOptions(state.scenes, state.userGltf.name));
  }
  $('gltf-error').textContent = state.userGltf.error || '';
  if (state.sceneId && select.value !== state.sceneId) select.value = state.sceneId;

  const info = state.sceneInfo;
  const kind = kindOf(info);
  showKind(kind);
  $('scene-description').textContent = info ? info.description || '' : '';
  sceneIdentifier(state);
  // The custom problem's form opens when it is the problem shown or holds an error.
  if ((state.sceneId === CUSTOM || state.custom.error) && !$('custom').open) $('custom').open = true;
  const entry = state.scenes.find((sc) => sc.name === state.sceneId);
  $('scene-look').textContent = entry && entry.look ? entry.look : '';
  $('scene-look-block').hidden = !(entry && entry.look);
  $('scene-facts').textContent = sceneFacts(info);

  // Estimators
  const names = info ? info.estimators : [];
  const details = info && Array.isArray(info.estimatorDetails) ? info.estimatorDetails : [];
  const eSig = JSON.stringify([state.sceneId, names, details]);
  const list = $('estimator-list');
  if (eSig !== estimatorsSig) {
    estimatorsSig = eSig;
    // the presets the scene does not list (normalizeInfo: after its own) under a heading
    const own = info && Array.isArray(info.defaultSelected) ? info.defaultSelected : names;
    const firstMore = names.findIndex((n) => !own.includes(n));
    const moreHead = document.createElement('p');
    moreHead.className = 'more-head small muted';
    moreHead.textContent = 'also offered (not in the scene file):';
    list.replaceChildren(...names.flatMap((name, i) => {
      const box = document.createElement('input');
      box.type = 'checkbox';
      box.id = `est-${i}`;
      box.dataset.estimator = name;
      const label = document.createElement('label');
      label.htmlFor = box.id;
      const d = details.find((e) => e && e.name === name);
      if (d) label.title = renderFacts(d);
      const sw = document.createElement('span');
      sw.className = 'swatch';
      sw.style.background = colorAt(i);
      label.append(box, sw, name);
      return i === firstMore && firstMore > 0 ? [moreHead, label] : [label];
    }));
  }
  const selected = new Set(state.selected);
  for (const box of list.querySelectorAll('input[data-estimator]')) box.checked = selected.has(box.dataset.estimator);

  // Numbers (not the one being edited, nor one holding an invalid text)
  for (const [key, id] of Object.entries(PARAM_INPUTS)) {
    const input = $(id);
    const invalid = Boolean(state.paramErrors[key]);
    input.setAttribute('aria-invalid', String(invalid));
    const value = state.params[key];
    if (!invalid && document.activeElement !== input && value !== null && value !== undefined && input.value !== String(value)) {
      input.value = String(value);
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
    if (run.settings && run.kind === KIND.RENDER) {
      info2 += ` · spp ${run.settings.n_min}..${run.settings.n_max}, ${run.settings.width}×${run.settings.height} px, ${run.settings.reps} reps, seed ${run.settings.seed}`;
      if (run.status === 'running' && !run.order.some((n) => run.records[n])) info2 += ` · ${referenceText(run)}`;
    } else if (run.settings) {
      info2 += ` · N ${run.settings.n_min}..${run.settings.n_max}, ${run.settings.reps} reps, seed ${run.settings.seed}`;
    }
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
