// The playground's one state object: a store (getState, subscribe, dispatch), the reducer that
// is the only code changing the state, and the pure helpers that put the comparison in the URL
// and read it back. No DOM, no workers: web/test/state.test.mjs runs it under Node.
import { applyLevel, ladder, mergeResults, progressOf, samplesSummary } from './series.js';
import { RACE_DEFAULTS, sceneTolerance } from './race.js';

/** Bounds of the core (docs/scene-format.md) and of the page's first run. */
export const LIMITS = Object.freeze({
  nMin: 1,
  nMax: 2 ** 36,
  repsMin: 2,
  repsMax: 100000,
  firstRunNMax: 65536, // the scene's own n_max, capped for a fast first run
  exprLength: 2000,
});

/** Bounds of render studies: the render C API's spp and replicates (src/render_api), and the
 *  resolution the page allows (small images: the study renders every one reps x levels times). */
export const RENDER_LIMITS = Object.freeze({
  sppMax: 2 ** 20,
  repsMax: 1024,
  sizeMin: 16,
  sizeMax: 256,
  firstRunSppMax: 1024, // the scene's own spp_max, capped for a fast first run
});

/** The two kinds of problem: integrals (src/api) and render scenes (src/render_api). */
export const KIND = Object.freeze({ INTEGRAL: 'integral', RENDER: 'render' });

/** The kind of a scene summary (a sceneInfo, a manifest entry): 'render' or 'integral'. */
export function kindOf(info) {
  return info && info.kind === KIND.RENDER ? KIND.RENDER : KIND.INTEGRAL;
}

/** Defaults of the comparison when neither the URL nor the scene says otherwise. */
export const DEFAULTS = Object.freeze({
  scene: null,       // the first scene of the manifest
  estimators: null,  // null = all of the scene's estimators
  n_min: 16,
  n_max: 65536,
  reps: 32,
  seed: 1,
  f: '',
  p: '',
  exact: '',
});

export const CUSTOM = 'custom';
/** The scene id of a glTF file the reader opened in the page (never in a link: the file is theirs). */
export const USER_GLTF = 'gltf-file';

/** The URL keys, in the order stateToQuery writes them (width and height: render scenes). */
export const QUERY_KEYS = Object.freeze(['scene', 'estimators', 'n_min', 'n_max', 'reps', 'seed', 'width', 'height', 'f', 'p', 'exact']);

const NAME_RE = /^[A-Za-z0-9_.-]{1,100}$/;

/** Parses a whole decimal number in [lo, hi]; anything else (1.5, 1e3, -2, '') gives null. */
export function parseWhole(text, lo, hi) {
  if (typeof text === 'number') text = String(text);
  if (typeof text !== 'string' || !/^\s*\d{1,16}\s*$/.test(text)) return null;
  const v = Number(text.trim());
  return Number.isSafeInteger(v) && v >= lo && v <= hi ? v : null;
}

const PARAM_RULES = Object.freeze({
  n_min: [LIMITS.nMin, LIMITS.nMax],
  n_max: [LIMITS.nMin, LIMITS.nMax],
  reps: [LIMITS.repsMin, LIMITS.repsMax],
  seed: [0, Number.MAX_SAFE_INTEGER],
});

const RENDER_PARAM_RULES = Object.freeze({
  n_min: [1, RENDER_LIMITS.sppMax],
  n_max: [1, RENDER_LIMITS.sppMax],
  reps: [LIMITS.repsMin, RENDER_LIMITS.repsMax],
  seed: [0, Number.MAX_SAFE_INTEGER],
  width: [RENDER_LIMITS.sizeMin, RENDER_LIMITS.sizeMax],
  height: [RENDER_LIMITS.sizeMin, RENDER_LIMITS.sizeMax],
});

/** The numeric settings of a kind of problem and their ranges: {key: [lo, hi]}. */
export function paramRules(kind = KIND.INTEGRAL) {
  return kind === KIND.RENDER ? RENDER_PARAM_RULES : PARAM_RULES;
}

/** The name a setting has in messages: render scenes call N spp. */
function paramLabel(key, kind) {
  if (kind !== KIND.RENDER) return key;
  return { n_min: 'spp_min', n_max: 'spp_max' }[key] || key;
}

/** The message for an invalid value of a numeric setting, or '' when it is valid. */
export function paramError(key, value, kind = KIND.INTEGRAL) {
  const rule = paramRules(kind)[key];
  if (!rule) return `${key} is not a setting of ${kind === KIND.RENDER ? 'render scenes' : 'integrals'}`;
  const [lo, hi] = rule;
  if (parseWhole(value, lo, hi) !== null) return '';
  return `${paramLabel(key, kind)} must be a whole number in ${lo}..${hi}`;
}

/** True when at least one power of two lies in [nMin, nMax] (the core's N ladder). */
export function hasLadder(nMin, nMax) {
  return ladder(nMin, nMax).length > 0;
}

// encodeURIComponent, leaving the characters that are safe in a query value readable.
function enc(value) {
  return encodeURIComponent(value).replace(/%2C/g, ',').replace(/%5E/g, '^').replace(/%2F/g, '/');
}

/**
 * The comparison of a state as a query string ('?scene=...&estimators=a,b&n_min=...').
 * `state` is either the store's state or a plain {scene, estimators, n_min, n_max, reps, seed,
 * width?, height?, f, p}; the custom problem's f (and p) are written only for the custom scene,
 * the image's width and height only for render scenes (for a plain object: when given).
 */
export function stateToQuery(state) {
  const c = comparisonOf(state);
  const parts = [];
  const add = (k, v) => { if (v !== null && v !== undefined && v !== '') parts.push(`${k}=${enc(String(v))}`); };
  if (c.scene === USER_GLTF) return ''; // a link cannot carry the reader's file
  add('scene', c.scene);
  if (Array.isArray(c.estimators)) add('estimators', c.estimators.join(','));
  for (const k of ['n_min', 'n_max', 'reps', 'seed', 'width', 'height']) add(k, c[k]);
  if (c.scene === CUSTOM) {
    add('f', c.f);
    add('p', c.p);
    add('exact', c.exact);
  }
  return parts.length ? `?${parts.join('&')}` : '';
}

// {scene, estimators, n_min, ...} of the store's state or of a plain comparison object.
function comparisonOf(state) {
  if (state && state.params && 'sceneId' in state) {
    const render = kindOf(state.sceneInfo) === KIND.RENDER;
    return {
      scene: state.sceneId,
      estimators: state.selected,
      ...state.params,
      width: render ? state.params.width : null,
      height: render ? state.params.height : null,
      f: state.custom.applied ? state.custom.applied.f : state.custom.f,
      p: state.custom.applied ? state.custom.applied.p : state.custom.p,
      exact: state.custom.applied ? state.custom.applied.exact ?? '' : state.custom.exact,
    };
  }
  return { ...DEFAULTS, ...state };
}

/**
 * Reads a comparison from a query string. Every value that is missing, malformed or out of the
 * core's range is replaced by its default, so any URL gives a usable comparison:
 * `defaults` is {scene, estimators, n_min, n_max, reps, seed, f, p} (missing keys from
 * DEFAULTS; for render scenes also width and height). An f in the URL selects the custom
 * scene; n_min > n_max, or a range holding no power of two, falls back to the default range.
 * Estimator names are only checked for their spelling here: the scene decides which exist.
 * `kind` gives the ranges (paramRules): a render scene's spp, replicates and image size; width
 * and height are read for render scenes only.
 */
export function queryToState(search, defaults = {}, kind = KIND.INTEGRAL) {
  const d = { ...DEFAULTS, ...defaults };
  const out = { ...d };
  let q;
  try {
    q = new URLSearchParams(typeof search === 'string' ? search : '');
  } catch {
    return out;
  }
  const get = (k) => {
    const v = q.get(k);
    return v === null ? null : v;
  };

  const scene = get('scene');
  if (scene !== null && NAME_RE.test(scene)) out.scene = scene;

  const est = get('estimators');
  if (est !== null) {
    const names = [...new Set(est.split(',').map((s) => s.trim()).filter((s) => NAME_RE.test(s)))];
    if (names.length) out.estimators = names;
  }

  const rules = paramRules(kind);
  for (const k of ['n_min', 'n_max', 'reps', 'seed', ...(kind === KIND.RENDER ? ['width', 'height'] : [])]) {
    const raw = get(k);
    if (raw === null) continue;
    const [lo, hi] = rules[k];
    const v = parseWhole(raw, lo, hi);
    if (v !== null) out[k] = v;
  }
  if (out.n_min > out.n_max || !hasLadder(out.n_min, out.n_max)) {
    out.n_min = d.n_min;
    out.n_max = d.n_max;
  }

  for (const k of ['f', 'p']) {
    const raw = get(k);
    if (raw !== null && raw.length <= LIMITS.exprLength && !raw.includes('\0')) out[k] = raw.trim();
  }
  const exact = get('exact');
  if (exact !== null && parseExact(exact) !== null) out.exact = exact.trim();
  if (out.f) out.scene = CUSTOM;
  else if (out.scene === CUSTOM) out.scene = d.scene === CUSTOM ? null : d.scene;
  return out;
}

/** The custom problem's exact value from its text: a finite number, or null ('' or anything
 *  else; the page says why for a non-empty text that is not one). */
export function parseExact(text) {
  if (typeof text !== 'string') return null;
  const t = text.trim();
  if (!/^[+-]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i.test(t)) return null;
  const v = Number(t);
  return Number.isFinite(v) ? v : null;
}

/**
 * What a link asked for that cannot be used, one message per value, for a notice (queryToState
 * replaces each by its default): numbers that are not whole or out of range, an N range without
 * a power of two, estimator names the scene does not have (`available`), an exact value that is
 * not a number. Unknown keys (a tracker's, say) are not the page's and are not reported.
 */
export function urlProblems(search, available = null, kind = KIND.INTEGRAL) {
  let q;
  try {
    q = new URLSearchParams(typeof search === 'string' ? search : '');
  } catch {
    return ['the link could not be read'];
  }
  const out = [];
  const rules = paramRules(kind);
  const shown = (v) => (v.length > 24 ? `${v.slice(0, 24)}…` : v);
  for (const k of ['n_min', 'n_max', 'reps', 'seed', ...(kind === KIND.RENDER ? ['width', 'height'] : [])]) {
    const raw = q.get(k);
    if (raw === null) continue;
    const [lo, hi] = rules[k];
    if (parseWhole(raw, lo, hi) === null) out.push(`${paramLabel(k, kind)}=${shown(raw)} is not a whole number in ${lo}..${hi}`);
  }
  const a = parseWhole(q.get('n_min') ?? '', ...rules.n_min);
  const b = parseWhole(q.get('n_max') ?? '', ...rules.n_max);
  if (a !== null && b !== null && (a > b || !hasLadder(a, b))) {
    out.push(`n_min=${a} and n_max=${b} hold no power of two`);
  }
  const est = q.get('estimators');
  if (est !== null && Array.isArray(available)) {
    const unknown = est.split(',').map((n) => n.trim()).filter((n) => n && !available.includes(n));
    if (unknown.length) out.push(`${unknown.map((n) => `'${shown(n)}'`).join(', ')} ${unknown.length > 1 ? 'are not estimators' : 'is not an estimator'} of this scene`);
  }
  const exact = q.get('exact');
  if (exact !== null && exact.trim() && parseExact(exact) === null) out.push(`exact=${shown(exact)} is not a number`);
  return out;
}

/** The scene's own N range, n_max capped for a fast first run (the issue's defaults); for a
 *  render scene its spp range (spp_max capped), replicates and image size (clamped to the
 *  page's limits). */
export function sceneDefaults(info) {
  if (kindOf(info) === KIND.RENDER) return renderDefaults(info);
  const nMin = info && Number.isSafeInteger(info.n_min) ? info.n_min : DEFAULTS.n_min;
  let nMax = info && Number.isSafeInteger(info.n_max) ? info.n_max : DEFAULTS.n_max;
  nMax = Math.min(nMax, LIMITS.firstRunNMax);
  const ok = nMin <= nMax && hasLadder(nMin, nMax);
  return {
    n_min: ok ? nMin : DEFAULTS.n_min,
    n_max: ok ? nMax : DEFAULTS.n_max,
    reps: DEFAULTS.reps,
    seed: DEFAULTS.seed,
  };
}

function renderDefaults(info) {
  const whole = (v, lo, hi, fallback) => (Number.isSafeInteger(v) && v >= lo && v <= hi ? v : fallback);
  const clamp = (v, fallback) => (Number.isSafeInteger(v)
    ? Math.min(RENDER_LIMITS.sizeMax, Math.max(RENDER_LIMITS.sizeMin, v)) : fallback);
  const nMin = whole(info.n_min, 1, RENDER_LIMITS.sppMax, 1);
  const nMax = Math.min(whole(info.n_max, 1, RENDER_LIMITS.sppMax, 64), RENDER_LIMITS.firstRunSppMax);
  const ok = nMin <= nMax;
  return {
    n_min: ok ? nMin : 1,
    n_max: ok ? nMax : 64,
    reps: whole(info.reps, LIMITS.repsMin, RENDER_LIMITS.repsMax, 4),
    seed: DEFAULTS.seed,
    width: clamp(info.width, 64),
    height: clamp(info.height, 64),
  };
}

/**
 * The page's summary of a render scene from the render core's sceneInfo (mcp_render_scene_info):
 * estimators as names (the objects kept in estimatorDetails), the spp range, replicates and
 * seed as n_min, n_max, reps, seed (what the controls show), the names of N and of the error
 * (settings.n_name, settings.error_name). An integration scene's info is returned unchanged.
 */
export function normalizeInfo(info) {
  if (!info) return info;
  if (info.kind !== KIND.RENDER) {
    // An integration scene: its own estimators (selected at first), then the uniform-density
    // presets it does not list (sobol, halton, lattice, ...), offered unselected.
    const own = Array.isArray(info.estimators) ? info.estimators : [];
    const more = Array.isArray(info.more_estimators) ? info.more_estimators.filter((n) => !own.includes(n)) : [];
    return { ...info, estimators: [...own, ...more], defaultSelected: own.slice() };
  }
  const details = Array.isArray(info.estimators) ? info.estimators : [];
  const st = info.settings || {};
  return {
    ...info,
    kind: KIND.RENDER,
    dimension: null,
    exact: null,
    estimators: details.map((e) => (typeof e === 'string' ? e : e.name)),
    estimatorDetails: details,
    n_min: st.n_min,
    n_max: st.n_max,
    reps: st.reps,
    seed: st.seed,
    n_name: st.n_name || 'spp',
    error_name: st.error_name || 'relative_mse',
  };
}

/**
 * The settings of a run from the state: {n_min, n_max, reps, seed}, and for a render scene
 * also {width, height}.
 */
export function runSettings(state) {
  const { n_min, n_max, reps, seed, width, height } = state.params;
  return kindOf(state.sceneInfo) === KIND.RENDER ? { n_min, n_max, reps, seed, width, height } : { n_min, n_max, reps, seed };
}

/**
 * The options of one worker's study: the settings of runSettings and its estimators. A render
 * study takes spp_min / spp_max for N, the image size, and previews (the PNGs of each level's
 * image and its error, and of the reference).
 */
export function studyOptions(kind, settings, estimators) {
  if (kind !== KIND.RENDER) {
    const { n_min, n_max, reps, seed } = settings;
    return { n_min, n_max, reps, seed, estimators };
  }
  return {
    estimators,
    spp_min: settings.n_min,
    spp_max: settings.n_max,
    reps: settings.reps,
    seed: settings.seed,
    width: settings.width,
    height: settings.height,
    previews: true,
  };
}

/** What N and the error are called in a kind's plots and tables. */
export function studyNames(kind, exactKnown = false) {
  return kind === KIND.RENDER
    ? { nName: 'spp', errorName: 'relative_mse' }
    : { nName: 'N', errorName: exactKnown ? 'mse' : 'variance' };
}

// ---------------------------------------------------------------------------------------------
// Custom problems

/**
 * The scene of a typed problem: f over the unit interval (dimension 1) or the unit cube of
 * `dimension` (what the core infers from f's highest variable), compared by uniform,
 * stratified and Latin hypercube sampling, plus importance sampling (plain and stratified)
 * from a density proportional to p when p is given. Nothing is evaluated here: the core parses
 * both expressions when it validates the scene.
 */
export function buildCustomScene(f, p = '', dimension = 1, exact = null) {
  const d = Number.isSafeInteger(dimension) && dimension >= 1 ? dimension : 1;
  const fx = String(f).trim();
  const px = String(p || '').trim();
  const scene = {
    name: CUSTOM,
    description: px ? `f = ${fx}, importance sampling from p proportional to ${px}` : `f = ${fx}`,
    f: fx,
    domain: d === 1 ? { type: 'interval', lower: 0, upper: 1 } : { type: 'box', dim: d },
    estimators: ['uniform', 'stratified', 'latin_hypercube'],
  };
  if (px) scene.estimators.push({ name: 'importance', pdf: px }, { name: 'stratified_importance', pdf: px });
  // A typed exact value gives the problem MSE, bias and coverage (the core checks it is finite).
  if (typeof exact === 'number' && Number.isFinite(exact)) scene.exact = exact;
  return scene;
}

/**
 * Which input a core error about a custom scene concerns: 'p' for a pdf
 * ("scene.estimators[3].pdf.shape: at position 2: ..."), else 'f'; with the 1-based position.
 */
export function customError(payload) {
  const message = payload && payload.message ? payload.message : String(payload);
  const path = payload && payload.field ? payload.field : (/^([\w.[\]]+):/.exec(message) || [])[1] || '';
  let position = payload && Number.isSafeInteger(payload.position) ? payload.position : null;
  if (position === null) {
    const m = /: at position (\d+): /.exec(message);
    if (m) position = Number(m[1]);
  }
  const field = /^scene\.estimators\[\d+\]\.pdf/.test(path) ? 'p' : /^scene\.exact/.test(path) ? 'exact' : 'f';
  return { field, message, position };
}

// ---------------------------------------------------------------------------------------------
// Store

/** A store around `reducer`. Actions dispatched while subscribers run are queued, so every
 *  subscriber sees every action once, in order, with the state right after it. */
export function createStore(reducer, initial) {
  let state = initial;
  const subscribers = new Set();
  const queue = [];
  let busy = false;
  return {
    getState: () => state,
    subscribe(fn) {
      subscribers.add(fn);
      return () => subscribers.delete(fn);
    },
    dispatch(action) {
      queue.push(action);
      if (busy) return;
      busy = true;
      try {
        while (queue.length) {
          const a = queue.shift();
          state = reducer(state, a);
          for (const fn of [...subscribers]) fn(state, a);
        }
      } finally {
        busy = false;
      }
    },
  };
}

export function initialState() {
  return {
    version: null,          // the core's version once a worker has loaded it
    scenes: [],             // scenes/manifest.json
    sceneId: null,          // a manifest name or CUSTOM
    scene: null,            // the scene object that is run (file content or the built custom scene)
    sceneInfo: null,        // core.sceneInfo(scene): name, description, dimension, exact, estimators, ...
    selected: [],           // selected estimator names, in the scene's order
    // width, height: the image of a render scene (null until one is chosen)
    params: { n_min: DEFAULTS.n_min, n_max: DEFAULTS.n_max, reps: DEFAULTS.reps, seed: DEFAULTS.seed, width: null, height: null },
    paramErrors: {},        // key -> message for an input that holds no valid value
    custom: { f: '', p: '', exact: '', error: null, pending: false, applied: null },
    userGltf: { name: null, error: null }, // a glTF file opened in the page (its file name), or why not
    clockStep: null,        // ms: the step performance.now() rounds to in a run worker (times under 20 steps are not fitted)
    isolated: null,         // the run worker's crossOriginIsolated (null until it has answered)
    calibration: 'all',     // the histogram's level: 'all' (pooled) or an N
    notice: '',             // last export / scene-loading message
    run: emptyRun('loading'),
    samples: emptySamples(256),
    // render scenes: a quick image of the scene ({key, status, png, spp, estimator, message})
    scenePreview: null,
    race: emptyRace({ ...RACE_DEFAULTS }),
    // a finished run kept for comparison: drawn dashed beside the next runs of the same scene
    kept: null,
  };
}

/** The race to a requested accuracy (race.js): the card's inputs (text, as typed) and the
 *  stopping result of each estimator as its worker answers (one request per estimator). */
function emptyRace(inputs, id = 0) {
  return {
    inputs,
    id,
    status: 'idle',         // idle | running | done | cancelled | error
    message: '',
    order: [],              // estimator names raced, in the scene's order
    parts: {},              // name -> the estimator of its stopping result
    stopping: null,         // the tolerance and budget the core used (result.stopping)
    options: null,          // {rel_tol?, abs_tol?, reps, max_seconds} sent
    sceneName: null,
    exact: null,
    startedAt: null,
    elapsed: null,
  };
}

/** The race's parts as one stopping result (the C API's shape, estimators in the scene's order). */
export function raceResult(race) {
  return {
    kind: 'stopping',
    stopping: race.stopping,
    estimators: race.order.filter((n) => race.parts[n]).map((n) => race.parts[n]),
  };
}

/** Points drawn of the selected estimators (core.samples): `data` the scatter's n points,
 *  `weights` the n = 4096 weights of the histograms; each answer is kept only when its key is
 *  the latest requested one (scene, estimators, seed, n). */
export const SAMPLE_SIZES = Object.freeze([64, 256, 1024]);
export const WEIGHT_SAMPLES = 4096;

function emptySamples(n) {
  return { n, status: 'idle', key: null, weightsKey: null, data: null, weights: null, message: '' };
}

function emptyRun(status) {
  return {
    id: 0,
    status,                 // loading | ready | running | done | cancelled | error
    message: '',
    progress: 0,
    workers: 0,             // results the run waits for (one per estimator group)
    threads: 0,             // workers it runs on (more when an estimator is split by replicate)
    startedAt: null,
    elapsed: null,
    settings: null,         // {n_min, n_max, reps, seed} (+ {width, height} for render scenes)
    kind: KIND.INTEGRAL,    // of the scene studied: 'integral' or 'render'
    nName: 'N',             // what N is called (settings.n_name: 'spp' for render studies)
    errorName: 'variance',  // what the plotted error is (settings.error_name: 'relative_mse')
    referencePng: null,     // render studies: the reference image (base64 PNG), once known
    referenceShipped: false, // render studies: the site's own reference was given to the study
    referenceRows: null,    // render studies rendering their reference: {done, rows} so far
    exact: null,            // the scene's exact value (MSE instead of variance when known)
    sceneName: null,
    colors: null,           // name -> palette index (its position in the scene)
    order: [],              // estimator names of the run, in the scene's order
    ladder: [],
    records: {},            // name -> estimator record (levels streamed so far, fit, warnings)
    partials: [],           // complete results of the workers done so far
    result: null,           // the merged result once every worker is done
  };
}

function orderedSelection(available, names) {
  const want = new Set(names);
  return available.filter((n) => want.has(n));
}

/**
 * The estimators a scene starts with selected, in the scene's order: those its stop of the tour
 * names (manifest entry.select: a quasi-Monte Carlo stop selects sobol, halton and lattice,
 * which the scene file does not list) that the scene offers, else the scene's own
 * (info.defaultSelected), else every one of `available`.
 */
export function defaultSelection(available, info = null, entry = null) {
  if (entry && Array.isArray(entry.select)) {
    const chosen = orderedSelection(available, entry.select);
    if (chosen.length) return chosen;
  }
  return orderedSelection(available, info && Array.isArray(info.defaultSelected) ? info.defaultSelected : available);
}

/** The reducer: (state, action) -> new state, never mutating its input. */
export function reducer(state, action) {
  const p = action.payload || {};
  switch (action.type) {
    case 'core/ready':
      return {
        ...state,
        version: p.version,
        run: state.run.status === 'loading' ? { ...state.run, status: 'ready' } : state.run,
      };
    case 'core/failed':
      return { ...state, run: { ...state.run, status: 'error', message: p.message } };
    case 'scenes/loaded':
      return { ...state, scenes: p.scenes };
    case 'scene/request': {
      // A scene of the manifest is shown at once (its estimators all selected, its own capped
      // range), from what the manifest says of it; core.sceneInfo completes it (scene/loaded)
      // and Run waits for that. Edits made meanwhile are kept.
      const entry = p.sceneId === CUSTOM ? null : state.scenes.find((sc) => sc.name === p.sceneId);
      if (!entry) return { ...state, notice: '', userGltf: { ...state.userGltf, error: null } };
      // the tour's selection may name presets the scene does not list (offered after its own)
      const extra = Array.isArray(entry.select) ? entry.select.filter((n) => !entry.estimators.includes(n)) : [];
      const info = {
        name: entry.name, description: entry.description, dimension: entry.dimension,
        estimators: [...entry.estimators, ...extra], n_min: entry.n_min, n_max: entry.n_max, provisional: true,
        ...(kindOf(entry) === KIND.RENDER
          ? { kind: KIND.RENDER, reps: entry.reps, width: entry.width, height: entry.height } : {}),
      };
      return {
        ...state,
        sceneId: entry.name,
        scene: null,
        sceneInfo: info,
        selected: defaultSelection(info.estimators, null, entry),
        params: { ...state.params, ...sceneDefaults(info) },
        paramErrors: {},
        custom: { ...state.custom, error: null, pending: false },
        notice: '',
        run: state.version ? { ...emptyRun('ready'), id: state.run.id } : state.run,
        samples: emptySamples(state.samples.n),
        scenePreview: null,
        race: emptyRace(state.race.inputs, state.race.id),
      };
    }
    case 'scene/loaded': {
      // {sceneId, scene, info, selected?, params?}: selected/params come from the URL, else all
      // estimators and the scene's own (capped) range.
      const available = p.info.estimators || [];
      // the answer to a scene/request keeps what was chosen since
      const keep = !p.selected && !p.params && state.sceneId === p.sceneId && state.sceneInfo && state.sceneInfo.provisional;
      const byDefault = defaultSelection(available, p.info, state.scenes.find((sc) => sc.name === p.sceneId));
      let selected = keep ? state.selected : p.selected ? p.selected : byDefault;
      selected = orderedSelection(available, selected);
      if (!selected.length && !keep) selected = byDefault.slice();
      let params;
      // "Use this problem" keeps the N range, replicates and seed chosen (from an integral)
      const keepSettings = p.sceneId === CUSTOM && state.sceneInfo && kindOf(state.sceneInfo) !== KIND.RENDER
        && hasLadder(state.params.n_min, state.params.n_max) && state.params.n_min <= state.params.n_max;
      if (keep) params = state.params;
      else if (p.params) params = { ...state.params, ...p.params };
      else if (keepSettings) params = state.params;
      else params = { ...state.params, ...sceneDefaults(p.info) };
      const custom = p.sceneId === CUSTOM
        ? { ...state.custom, error: null, pending: false, applied: p.custom || state.custom.applied }
        : { ...state.custom, error: null, pending: false };
      return {
        ...state,
        sceneId: p.sceneId,
        scene: p.scene,
        sceneInfo: p.info,
        userGltf: p.sceneId === USER_GLTF ? { name: p.fileName || state.userGltf.name, error: null } : { ...state.userGltf, error: null },
        selected,
        params,
        paramErrors: keep ? state.paramErrors : {},
        custom,
        notice: '',
        // a new problem clears the plots of the previous one (and stops its run)
        run: state.version && !keep ? { ...emptyRun('ready'), id: state.run.id } : state.run,
        samples: keep ? state.samples : emptySamples(state.samples.n),
        scenePreview: null,
        race: keep ? state.race : emptyRace(raceInputsFor(state.race.inputs, p.scene), state.race.id),
      };
    }
    case 'clock/measured':
      return { ...state, clockStep: p.ms > 0 ? p.ms : null, isolated: typeof p.isolated === 'boolean' ? p.isolated : null };
    case 'gltf/error':
      return { ...state, userGltf: { ...state.userGltf, error: p.message } };
    case 'scene/failed':
      return { ...state, notice: p.message, custom: { ...state.custom, pending: false } };
    case 'estimator/set': {
      const available = state.sceneInfo ? state.sceneInfo.estimators : [];
      const set = new Set(state.selected);
      if (p.checked) set.add(p.name);
      else set.delete(p.name);
      return { ...state, selected: orderedSelection(available, [...set]) };
    }
    case 'estimators/all': {
      const available = state.sceneInfo ? state.sceneInfo.estimators : [];
      return { ...state, selected: p.checked ? available.slice() : [] };
    }
    case 'param/set': {
      // {key, value: the input's text}
      const kind = kindOf(state.sceneInfo);
      const err = paramError(p.key, p.value, kind);
      const paramErrors = { ...state.paramErrors };
      if (err) {
        paramErrors[p.key] = err;
        return { ...state, paramErrors };
      }
      delete paramErrors[p.key];
      const [lo, hi] = paramRules(kind)[p.key];
      return { ...state, params: { ...state.params, [p.key]: parseWhole(p.value, lo, hi) }, paramErrors };
    }
    case 'custom/edit':
      return { ...state, custom: { ...state.custom, [p.field]: p.value } };
    case 'custom/apply':
      return { ...state, custom: { ...state.custom, pending: true, error: null } };
    case 'custom/error':
      // {field: 'f' | 'p', message, position}
      return { ...state, custom: { ...state.custom, pending: false, error: { ...p } } };
    case 'calibration/set':
      return { ...state, calibration: p.value === 'all' ? 'all' : Number(p.value) };
    case 'notice':
      return { ...state, notice: p.message };

    case 'samples/n':
      if (!SAMPLE_SIZES.includes(Number(p.n))) return state;
      return { ...state, samples: { ...state.samples, n: Number(p.n) } };
    case 'samples/request':
      // {key, weightsKey?}: weightsKey only when the weights are asked for again
      return {
        ...state,
        samples: {
          ...state.samples, status: p.points === false ? state.samples.status : 'loading', key: p.key, message: '',
          ...(p.weightsKey ? { weightsKey: p.weightsKey } : {}),
        },
      };
    case 'samples/loaded':
      if (p.key !== state.samples.key) return state;
      return { ...state, samples: { ...state.samples, status: 'ready', data: p.samples, message: '' } };
    case 'samples/weights':
      if (p.key !== state.samples.weightsKey) return state;
      return { ...state, samples: { ...state.samples, weights: p.samples } };
    case 'samples/failed':
      if (p.key !== state.samples.key && p.key !== state.samples.weightsKey) return state;
      return { ...state, samples: { ...state.samples, status: 'error', message: p.message } };

    case 'preview/request':
      return { ...state, scenePreview: { key: p.key, status: 'loading', png: null, message: '' } };
    case 'preview/loaded':
      if (!state.scenePreview || p.key !== state.scenePreview.key) return state;
      return { ...state, scenePreview: { ...state.scenePreview, status: 'ready', png: p.png, spp: p.spp, estimator: p.estimator, seconds: p.seconds } };
    case 'preview/failed':
      if (!state.scenePreview || p.key !== state.scenePreview.key) return state;
      return { ...state, scenePreview: { ...state.scenePreview, status: 'error', message: p.message } };

    case 'compare/keep': {
      // {label}: the current run, finished, kept with what it was run with
      const r = state.run;
      if (r.status !== 'done' || !r.order.some((n) => r.records[n])) return state;
      return {
        ...state,
        kept: {
          sceneId: state.sceneId, label: p.label || keptLabel(r), order: r.order.slice(),
          records: r.records, ladder: r.ladder.slice(), exact: r.exact, kind: r.kind,
        },
      };
    }
    case 'compare/clear':
      return { ...state, kept: null };
    case 'race/edit':
      if (!Object.prototype.hasOwnProperty.call(RACE_DEFAULTS, p.field)) return state;
      return { ...state, race: { ...state.race, inputs: { ...state.race.inputs, [p.field]: String(p.value) } } };
    case 'race/request':
      return state;
    case 'race/start':
      // {id, order, options, sceneName, exact, startedAt}
      return {
        ...state,
        race: {
          ...emptyRace(state.race.inputs, p.id),
          status: 'running',
          order: p.order.slice(),
          options: p.options,
          sceneName: p.sceneName,
          exact: p.exact ?? null,
          startedAt: p.startedAt,
        },
      };
    case 'race/part': {
      // {id, result: a stopping result of one estimator, now}
      const r = state.race;
      if (p.id !== r.id || r.status !== 'running') return state;
      const parts = { ...r.parts };
      for (const e of p.result.estimators || []) parts[e.name] = e;
      const done = r.order.every((n) => parts[n]);
      return {
        ...state,
        race: {
          ...r, parts, stopping: r.stopping || p.result.stopping || null,
          ...(done ? { status: 'done', elapsed: p.now - r.startedAt } : {}),
        },
      };
    }
    case 'race/cancel':
      if (state.race.status !== 'running') return state;
      return { ...state, race: { ...state.race, status: 'cancelled', elapsed: p.now - state.race.startedAt } };
    case 'race/error':
      if (p.id !== state.race.id) return state;
      return { ...state, race: { ...state.race, status: 'error', message: p.message } };
    case 'run/request':
      return state;
    case 'run/start': {
      // {id, workers (results expected), threads? (workers running), settings, order, exact,
      // sceneName, startedAt, kind?}
      const kind = p.kind === KIND.RENDER ? KIND.RENDER : KIND.INTEGRAL;
      const names = studyNames(kind, p.exact !== null && p.exact !== undefined);
      return {
        ...state,
        calibration: 'all',
        // a shared link's offer to run is done with; what it said about its values stays
        notice: state.notice.replace(/\s*Press Run to draw this link's plots\.$/, ''),
        run: {
          ...emptyRun('running'),
          id: p.id,
          workers: p.workers,
          threads: p.threads || p.workers,
          startedAt: p.startedAt,
          settings: p.settings,
          exact: p.exact,
          sceneName: p.sceneName,
          colors: p.colors || null,
          order: p.order,
          ladder: ladder(p.settings.n_min, p.settings.n_max),
          kind,
          nName: names.nName,
          errorName: names.errorName,
          referenceShipped: Boolean(p.referenceShipped),
        },
      };
    }
    case 'run/level': {
      if (p.id !== state.run.id || state.run.status !== 'running') return state;
      if (p.level && p.level.kind === 'render_reference') {
        // Rows of the reference rendered so far (every worker renders the same one): the
        // progress bar shows them until the first level arrives.
        const done = Math.max(p.level.rows_done, state.run.referenceRows ? state.run.referenceRows.done : 0);
        const rows = p.level.rows;
        const levelsDone = state.run.order.some((n) => state.run.records[n]);
        return {
          ...state,
          run: {
            ...state.run,
            referenceRows: { done, rows },
            progress: levelsDone ? state.run.progress : Math.min(1, done / Math.max(1, rows)),
          },
        };
      }
      const records = applyLevel(state.run.records, p.level);
      return {
        ...state,
        run: {
          ...state.run,
          records,
          progress: progressOf(records, state.run.order, state.run.ladder),
          referencePng: (p.level && p.level.reference_png) || state.run.referencePng,
        },
      };
    }
    case 'run/reference-unavailable': {
      // the shipped reference could not be fetched: the study renders its own
      if (p.id !== state.run.id || state.run.status !== 'running') return state;
      return { ...state, run: { ...state.run, referenceShipped: false } };
    }
    case 'run/partial': {
      // one worker's complete result: its records become the result's estimators
      if (p.id !== state.run.id || state.run.status !== 'running') return state;
      const records = { ...state.run.records };
      for (const e of p.result.estimators) records[e.name] = e;
      const partials = [...state.run.partials, p.result];
      const st = p.result.settings || {};
      const run = {
        ...state.run,
        records,
        partials,
        progress: progressOf(records, state.run.order, state.run.ladder),
        referencePng: state.run.referencePng || p.result.reference_png || null,
        nName: st.n_name || state.run.nName,
        errorName: st.error_name || state.run.errorName,
      };
      if (partials.length === state.run.workers) {
        run.result = mergeResults(partials, state.run.order);
        run.status = run.result.cancelled ? 'cancelled' : 'done';
        run.progress = 1;
        run.elapsed = p.now - state.run.startedAt;
      }
      return { ...state, run };
    }
    case 'run/cancel':
      if (state.run.status !== 'running') return state;
      return { ...state, run: { ...state.run, status: 'cancelled', elapsed: p.now - state.run.startedAt } };
    case 'run/error':
      if (p.id !== undefined && p.id !== state.run.id) return state;
      return { ...state, run: { ...state.run, status: 'error', message: p.message } };
    default:
      return state;
  }
}

/** The race's inputs for a newly loaded scene: the scene's own rel_tol / abs_tol when it has
 *  them (a scene that asks for stopping), else the inputs as they were. */
function raceInputsFor(inputs, scene) {
  const t = sceneTolerance(scene);
  return t.relTol || t.absTol ? { ...inputs, ...t } : inputs;
}

/** How a kept run is named: its settings, e.g. "N 16..65536, 32 reps, seed 1". */
export function keptLabel(run) {
  const st = run.settings || {};
  return `${run.kind === KIND.RENDER ? 'spp' : 'N'} ${st.n_min}..${st.n_max}, ${st.reps} reps, seed ${st.seed}`;
}

/** The kept run, when it belongs to the scene shown (a kept run of another problem is not drawn). */
export function keptFor(state) {
  return state.kept && state.kept.sceneId === state.sceneId ? state.kept : null;
}

/** What a render study does before its first level: the reference, shipped or being rendered. */
export function referenceText(run) {
  if (run.referenceShipped) return 'the reference ships with the site';
  const rows = run.referenceRows;
  if (!rows) return 'rendering the reference first…';
  return `rendering the reference: ${Math.floor((100 * rows.done) / Math.max(1, rows.rows))}% of its rows`;
}

/** The #status text of a state. */
export function statusText(state) {
  const r = state.run;
  if (r.status === 'error') return `error: ${r.message}`;
  return r.status;
}

/** True when the inputs make a runnable comparison; otherwise the reason. */
export function runBlocker(state) {
  if (!state.version) return 'the core is loading';
  if (!state.scene) return state.sceneInfo ? 'loading the scene' : 'no scene';
  if (!state.selected.length) return 'select at least one estimator';
  const keys = Object.keys(state.paramErrors);
  if (keys.length) return state.paramErrors[keys[0]];
  const kind = kindOf(state.sceneInfo);
  const [lo, hi] = [paramLabel('n_min', kind), paramLabel('n_max', kind)];
  const { n_min: a, n_max: b } = state.params;
  if (a > b) return `${hi} (${b}) must be >= ${lo} (${a})`;
  if (!hasLadder(a, b)) return `no power of two lies between ${lo} = ${a} and ${hi} = ${b}`;
  if (kind === KIND.RENDER) {
    const rules = paramRules(kind);
    for (const k of ['n_min', 'n_max', 'reps', 'width', 'height']) {
      const v = state.params[k];
      if (!(Number.isSafeInteger(v) && v >= rules[k][0] && v <= rules[k][1])) return paramError(k, String(v), kind);
    }
  }
  return '';
}

/** A structured-cloneable snapshot for window.mcplayDebug.state(). */
export function debugSnapshot(state) {
  const r = state.run;
  return {
    status: statusText(state),
    version: state.version,
    clockStep: state.clockStep ?? null, // ms

    scene: state.sceneId,
    sceneInfo: state.sceneInfo,
    selected: state.selected.slice(),
    params: { ...state.params },
    query: stateToQuery(state),
    custom: { f: state.custom.f, p: state.custom.p, exact: state.custom.exact, error: state.custom.error },
    kind: kindOf(state.sceneInfo),
    scenePreview: state.scenePreview ? { status: state.scenePreview.status, spp: state.scenePreview.spp, message: state.scenePreview.message } : null,
    run: {
      id: r.id, status: r.status, progress: r.progress, workers: r.workers, threads: r.threads, settings: r.settings, exact: r.exact,
      kind: r.kind, nName: r.nName, errorName: r.errorName,
      referenceShipped: r.referenceShipped, referenceRows: r.referenceRows,
      referenceSource: (r.result && r.result.scene && r.result.scene.reference && r.result.scene.reference.source) || null,
    },
    // render runs: which images the page has (the reference; per estimator its preview and error image)
    images: r.kind === KIND.RENDER ? {
      reference: Boolean(r.referencePng),
      estimators: Object.fromEntries(r.order.filter((n) => r.records[n]).map((n) => [n, {
        preview: Boolean(r.records[n].preview_png), error: Boolean(r.records[n].error_png),
        n: r.records[n].levels.length ? r.records[n].levels[r.records[n].levels.length - 1].n : null,
      }])),
    } : null,
    // per estimator of the run: its levels so far ({n, variance, mse, error, ...}), fit, warnings
    // (render runs: without their PNGs, which `images` summarises)
    estimators: r.order.filter((n) => r.records[n]).map((n) => {
      const { preview_png: _p, error_png: _e, ...rest } = r.records[n];
      return rest;
    }),
    result: r.result,
    // the race to a requested accuracy: its status and the stopping result so far
    clock: { step: state.clockStep, isolated: state.isolated },
    kept: state.kept ? { sceneId: state.kept.sceneId, label: state.kept.label, order: state.kept.order.slice() } : null,
    race: { status: state.race.status, message: state.race.message, inputs: { ...state.race.inputs },
      order: state.race.order.slice(), result: raceResult(state.race) },
    // the sample points drawn: per estimator the number of points, its strata; weights: n, zeros
    samples: samplesDebug(state.samples),
  };
}

function samplesDebug(smp) {
  const summary = samplesSummary(smp.data);
  return {
    status: smp.status,
    n: smp.n,
    message: smp.message,
    ...(summary || { estimators: [] }),
    points: Object.fromEntries((summary ? summary.estimators : []).map((e) => [e.name, e.points])),
    weights: smp.weights ? Object.fromEntries(smp.weights.estimators.map((e) => [e.name, {
      n: e.weight.length, zeros: e.weight.filter((w) => w === 0).length,
    }])) : null,
  };
}
