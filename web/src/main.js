// Wiring: the store, the workers and the views. Effects (loading scenes, validating custom
// problems, running studies, exporting) react to the actions the UI dispatches; the views
// re-render from the state (plots and tables once per animation frame).
//
// Workers (all of them Web Workers; none is a browser Service Worker): one helper worker
// (`service` below) validates scenes and formats results (so it answers during a run), and up
// to navigator.hardwareConcurrency run workers each study a subset of the selected estimators
// (options.estimators); every estimator has its own random streams, so the split changes no
// number, and the parts are merged (series.mergeResults). Cancel terminates the run workers and
// starts new ones.
//
// Render scenes (a "render" object; state.kindOf) go the same way: the workers hand them to the
// render core, which they import only then (so a page showing integrals never downloads
// mcplay_render_web.wasm); each run worker renders the same reference, its estimators' images
// and their PNGs (options.previews), shown by images.js as the levels come in. With fewer
// estimators than cores, each estimator's replicates are split over several workers
// (series.splitRenderWork; options.part / parts), and the helper worker merges the parts'
// levels and results (MSG.MERGE, the render core's mergeParts) into what one worker would give.
import {
  createStore, reducer, initialState, queryToState, stateToQuery, sceneDefaults, runBlocker,
  debugSnapshot, buildCustomScene, customError, parseExact, CUSTOM, WEIGHT_SAMPLES, KIND, kindOf, normalizeInfo,
  runSettings, studyOptions, urlProblems, USER_GLTF,
} from './state.js';
import { splitEstimators, splitRenderWork, splitCollector, partialResult, samplesCsv } from './series.js';
import { CoreWorker } from './client.js';
import { MSG } from './protocol.js';
import { initPlots, renderPlots, plotPng, lastPngLegend, hiddenEstimators, setHidden, guideLabels } from './plot.js';
import { renderReport } from './report.js';
import { mountImages, renderImages, imageView, setImageView } from './images.js';
import { shareQuery, queryToView, hasView } from './share.js';
import { sceneTitle } from './scene_title.js';
import { base64Of, checkGltfBytes, sceneFromFiles } from './gltf_files.js';
import { renderExplain } from './ui/explain.js';
import { mountControls, syncControls } from './ui/controls.js';
import { mountCustom, syncCustom } from './ui/custom.js';
import { mountExports, syncExports } from './ui/exports.js';
import { mountRace, syncRace } from './ui/race.js';
import { syncClock } from './ui/clock.js';
import { mountLargeText, onTextSize } from './ui/text_size.js';
import { raceOptions, withoutStopping } from './race.js';
import { startLab } from './lab/wiring.js';
import { labSnapshot } from './lab/model.js';
import { startLive } from './live/wiring.js';

const WORKER_URL = new URL('./worker.js', import.meta.url);
const MAX_WORKERS = 16;
const CORES = Math.max(1, Math.min(MAX_WORKERS, navigator.hardwareConcurrency || 2));

const $ = (id) => document.getElementById(id);
const store = createStore(reducer, initialState());
const { dispatch } = store;

let service = null;   // validation and formatting
let studyToRun = null; // a scene the lab opened: run when it has loaded
const runners = [];   // run workers, reused between runs
let activeRun = null; // id of the run in progress
let sceneToken = 0;   // the latest scene request (older answers are dropped)
let urlReady = false; // the URL is written only once the first scene is in

// ---------------------------------------------------------------------------------------------
// Views

const reportDom = { diagnostics: $('diagnostics'), diagnosticsEmpty: $('diagnostics-empty'), levels: $('levels'), summary: $('diagnostics-summary') };
const imagesDom = { images: $('render-images') };
mountImages(imagesDom, (image, as) => dispatch({ type: 'export/request', payload: { format: 'image', image, as } }));
initPlots({
  variance: $('plot-variance'), time: $('plot-time'), calibration: $('plot-calibration'), coverage: $('plot-coverage'),
  'legend-variance': $('legend-variance'), 'legend-time': $('legend-time'),
  'legend-calibration': $('legend-calibration'), 'legend-coverage': $('legend-coverage'),
  samples: $('plot-samples'), overlay: $('plot-overlay'), weights: $('plot-weights'),
  misweights: $('plot-misweights'), misweightsBlock: $('misweights-block'),
  'legend-misweights': $('legend-misweights'),
  'legend-overlay': $('legend-overlay'), 'legend-weights': $('legend-weights'),
  samplesNote: $('samples-note'), overlayNote: $('overlay-note'), weightsNote: $('weights-note'),
});
// The large-text mode (a projector): remembered, and every plot and strip redrawn in it
mountLargeText($('large-text'));
onTextSize(() => {
  renderHeavy();
  syncRace(store.getState());
});
mountControls(store);
mountCustom(store);
mountExports(store);
mountRace(store);
// The sampler lab (src/lab/): its own store and view, the same helper worker; its inputs go
// in the URL instead of the study's while it is shown.
const lab = startLab({
  service: () => service,
  scenes: () => store.getState().scenes,
  fetchScene: (entry) => fetchScene(entry),
  onChange: () => writeUrl(store.getState()),
  openStudy: (name) => {
    studyToRun = name; // run once loaded (the lab's "Open its study")
    dispatch({ type: 'scene/request', payload: { sceneId: name } });
  },
}, window.location.search);

// The live view of render scenes (src/live/): the study's scene, its own pool of workers, the
// site's reference at the default live size (manifest entry.live_reference).
const liveReferences = new Map();
const live = startLive({
  study: () => {
    const s = store.getState();
    return { scene: s.scene, info: s.sceneInfo, sceneId: s.sceneId, entry: s.scenes.find((e) => e.name === s.sceneId) || null };
  },
  liveReference: (entry) => {
    if (!entry || typeof entry.live_reference !== 'string') return Promise.resolve(null);
    if (!liveReferences.has(entry.name)) {
      liveReferences.set(entry.name, fetch(entry.live_reference)
        .then((r) => (r.ok ? r.arrayBuffer() : null))
        .then((buf) => (buf ? base64Of(new Uint8Array(buf)) : null))
        .catch(() => null));
    }
    return liveReferences.get(entry.name);
  },
  runStudy: () => {
    dispatch({ type: 'run/request' });
    document.getElementById('plot-variance').closest('figure').scrollIntoView({ block: 'start' });
  },
  workerUrl: WORKER_URL,
  cores: navigator.hardwareConcurrency || 2,
  workers: Number(new URLSearchParams(window.location.search).get('live_workers')) || null,
});

// Plots and tables are drawn in an animation frame, and at most every RUNNING_RENDER_MS while
// a study runs: on a machine whose cores all run workers, the page's drawing takes time from
// them, and so from the timings they measure.
const RUNNING_RENDER_MS = 100;
let pending = false;
let lastRender = -Infinity;
function renderHeavy() {
  pending = false;
  lastRender = performance.now();
  const s = store.getState();
  try {
    renderPlots(s);
    renderReport(s, reportDom);
    renderImages(s, imagesDom);
    renderExplain(s);
  } catch (e) {
    console.error('render failed', e);
  }
}
function scheduleHeavy() {
  if (pending) return;
  pending = true;
  const running = store.getState().run.status === 'running';
  const wait = running ? Math.max(0, lastRender + RUNNING_RENDER_MS - performance.now()) : 0;
  setTimeout(() => requestAnimationFrame(renderHeavy), wait);
}

/** The comparison into the address bar (replaceState: no history entry per keystroke). */
function writeUrl(state) {
  if (!urlReady) return;
  const labQuery = lab.query();
  if (!labQuery && !state.sceneId) return;
  const q = labQuery || stateToQuery(state);
  if (q !== window.location.search) window.history.replaceState(null, '', `${window.location.pathname}${q}`);
}

let lastStatus = null;
store.subscribe((state) => {
  syncControls(state);
  syncCustom(state);
  syncExports(state);
  syncRace(state);
  syncClock(state);
  // When a run ends, its final plots and fitted orders are drawn before anything else happens,
  // so that whatever reads "done" in #status also finds the final numbers; otherwise later.
  const ended = lastStatus === 'running' && state.run.status !== 'running';
  lastStatus = state.run.status;
  if (ended) renderHeavy();
  else scheduleHeavy();
  writeUrl(state);
  if (state.run.status !== 'running') activeRun = null;
});

// ---------------------------------------------------------------------------------------------
// Effects

store.subscribe((state, action) => {
  const p = action.payload || {};
  switch (action.type) {
    case 'scene/request':
      if (p.sceneId !== CUSTOM) stopRunners(); // the plots of the previous problem are gone
      if (p.sceneId === CUSTOM) {
        dispatch({ type: 'custom/apply' });
      } else {
        loadScene(p.sceneId);
      }
      break;
    case 'custom/apply':
      applyCustom();
      break;
    case 'gltf/open':
      openGltf(p.files);
      break;
    case 'scene/loaded':
      if (state.run.status !== 'running') stopRunners(); // a run of the previous problem, if any
      live.sceneChanged();
      if (studyToRun !== null && p.sceneId === studyToRun) queueMicrotask(runOpenedStudy);
      studyToRun = null;
      break;
    case 'scene/failed':
      studyToRun = null;
      break;
    case 'run/request':
      // the study measures time: a live view running beside it would take its cores
      if (live.store.getState().status === 'running') live.store.dispatch({ type: 'live/pause', payload: {} });
      startRun();
      break;
    case 'run/cancel':
      if (!p.stopped) stopRunners();
      break;
    case 'race/request':
      startRace();
      break;
    case 'race/cancel':
      if (!p.stopped) stopRunners();
      break;
    case 'export/request':
      exportResult(p).catch((e) => dispatch({ type: 'notice', payload: { message: `export failed: ${e.message}` } }));
      break;
    case 'link/copy':
      copyLink();
      break;
    default:
  }
});

/** A study opened from the lab runs at once, its first plot scrolled into view. */
function runOpenedStudy() {
  if (runBlocker(store.getState())) return;
  dispatch({ type: 'run/request' });
  document.getElementById('plot-variance').closest('figure').scrollIntoView({ block: 'start' });
}

// ---------------------------------------------------------------------------------------------
// Sample points: core.samples in the helper worker (a study's replicate 0 at N = n, same seed),
// asked for SAMPLES_DEBOUNCE_MS after the scene, the estimators, the seed or n last changed, and
// at once when Run is pressed; the weight histograms get a second call with n = WEIGHT_SAMPLES.

const SAMPLES_DEBOUNCE_MS = 250;
// Adaptive estimators in the sample view learn from a run of this many calls (VEGAS's ten
// training iterations then see a quarter of it), and show n of its estimate's points.
const ADAPTIVE_RUN_N = 65536;
let sceneSerial = 0;     // counts scenes loaded (a key of the samples)
let samplesTimer = null;

function samplesKeys(state) {
  if (!state.scene || !state.selected.length || state.paramErrors.seed) return null;
  if (kindOf(state.sceneInfo) === KIND.RENDER) return null; // no sample points of a render
  const base = [sceneSerial, state.selected, state.params.seed];
  return { key: JSON.stringify([...base, state.samples.n]), weightsKey: JSON.stringify(base) };
}

function requestSamples() {
  clearTimeout(samplesTimer);
  samplesTimer = null;
  const s = store.getState();
  const keys = samplesKeys(s);
  if (!keys || !service) return;
  const wantPoints = keys.key !== s.samples.key;
  const wantWeights = keys.weightsKey !== s.samples.weightsKey;
  if (!wantPoints && !wantWeights) return;
  const scene = s.scene;
  const estimators = s.selected.slice();
  const seed = s.params.seed;
  dispatch({ type: 'samples/request', payload: { key: keys.key, weightsKey: wantWeights ? keys.weightsKey : null, points: wantPoints || s.samples.status === 'error' } });
  const fail = (key) => (e) => dispatch({ type: 'samples/failed', payload: { key, message: e && e.message ? e.message : String(e) } });
  if (wantPoints || s.samples.status === 'error') {
    service.request(MSG.SAMPLES, { scene, options: { estimators, n: s.samples.n, seed, adaptive_n: ADAPTIVE_RUN_N } })
      .then(({ samples }) => dispatch({ type: 'samples/loaded', payload: { key: keys.key, samples } }))
      .catch(fail(keys.key));
  }
  if (wantWeights) {
    service.request(MSG.SAMPLES, { scene, options: { estimators, n: WEIGHT_SAMPLES, seed }, fields: ['weight'] })
      .then(({ samples }) => dispatch({ type: 'samples/weights', payload: { key: keys.weightsKey, samples } }))
      .catch(fail(keys.weightsKey));
  }
}

store.subscribe((state, action) => {
  if (action.type === 'scene/loaded') sceneSerial++;
  if (action.type.startsWith('samples/') && action.type !== 'samples/n') return;
  if (action.type === 'run/request') {
    requestSamples();
    return;
  }
  const keys = samplesKeys(state);
  if (!keys || (keys.key === state.samples.key && keys.weightsKey === state.samples.weightsKey)) return;
  clearTimeout(samplesTimer);
  samplesTimer = setTimeout(requestSamples, SAMPLES_DEBOUNCE_MS);
});

function runnersFor(k) {
  while (runners.length < k) runners.push(new CoreWorker(WORKER_URL));
  return runners.slice(0, k);
}

/** Terminates the run workers that are busy (a study cannot be interrupted otherwise). */
function stopRunners() {
  activeRun = null;
  for (const w of runners) if (w.busy) w.restart();
}

// The site's own render scenes come with their reference, rendered when the site was built
// (manifest entry.reference, refs/<name>.mcref): fetched once per scene, base64 for the C API's
// options.reference_data. The core uses it only if it was made from the very scene and image
// size of the study; otherwise the study renders its own and says so.
const shippedReferences = new Map();


/** The shipped reference of a manifest entry (a promise of base64, or null without one). */
function shippedReference(entry) {
  if (!entry || typeof entry.reference !== 'string') return Promise.resolve(null);
  if (!shippedReferences.has(entry.name)) {
    shippedReferences.set(entry.name, fetch(entry.reference)
      .then((r) => (r.ok ? r.arrayBuffer() : null))
      .then((buf) => (buf ? base64Of(new Uint8Array(buf)) : null))
      .catch(() => null));
  }
  return shippedReferences.get(entry.name);
}

async function fetchScene(entry) {
  const res = await fetch(`scenes/${encodeURIComponent(entry.file)}`);
  if (!res.ok) throw new Error(`scenes/${entry.file}: HTTP ${res.status}`);
  return res.json();
}

// A glTF scene the reader opened (web/src/gltf_files.js): kept here, shown as "your file" in
// the scene list; its reference is rendered by the study (the progress bar follows its rows).
let userScene = null;

/** Reads the chosen files, builds their scene and loads it; errors go to #gltf-error. */
async function openGltf(files) {
  const token = ++sceneToken;
  try {
    checkGltfBytes(files.reduce((sum, f) => sum + f.size, 0)); // before anything is read
    const read = await Promise.all(files.map(async (f) => ({ name: f.name, bytes: new Uint8Array(await f.arrayBuffer()) })));
    const scene = sceneFromFiles(read);
    const info = normalizeInfo((await service.request(MSG.VALIDATE, { scene })).info);
    if (token !== sceneToken) return;
    userScene = { scene, info, fileName: files.find((f) => /\.(gltf|glb)$/i.test(f.name)).name };
    stopRunners();
    dispatch({ type: 'scene/loaded', payload: { sceneId: USER_GLTF, ...userScene } });
  } catch (e) {
    if (token === sceneToken) dispatch({ type: 'gltf/error', payload: { message: e && e.message ? e.message : String(e) } });
  }
}

/** Loads a scene of the manifest; `fromUrl` (first load) gives its estimators and settings. */
async function loadScene(sceneId, fromUrl = null) {
  if (sceneId === USER_GLTF && userScene) {
    ++sceneToken;
    dispatch({ type: 'scene/loaded', payload: { sceneId: USER_GLTF, ...userScene } });
    return true;
  }
  const token = ++sceneToken;
  const { scenes } = store.getState();
  const entry = scenes.find((s) => s.name === sceneId) || scenes[0];
  if (!entry) {
    dispatch({ type: 'scene/failed', payload: { message: 'scenes/manifest.json lists no scene' } });
    return false;
  }
  try {
    const scene = await fetchScene(entry);
    shippedReference(entry); // fetched while the reader looks at the scene
    const info = normalizeInfo((await service.request(MSG.VALIDATE, { scene })).info);
    if (token !== sceneToken) return false;
    dispatch({
      type: 'scene/loaded',
      payload: { sceneId: entry.name, scene, info, ...(fromUrl ? paramsFromUrl(fromUrl, info) : {}) },
    });
    return true;
  } catch (e) {
    if (token === sceneToken) dispatch({ type: 'scene/failed', payload: { message: `scene ${entry.name}: ${e.message}` } });
    return false;
  }
}

function paramsFromUrl(fromUrl, info) {
  // The URL's values where it had them, else the scene's own (capped) range.
  const base = sceneDefaults(info);
  const kind = kindOf(info);
  const q = queryToState(fromUrl.search, { ...base, estimators: null }, kind);
  return {
    selected: q.estimators,
    params: {
      n_min: q.n_min, n_max: q.n_max, reps: q.reps, seed: q.seed,
      ...(kind === KIND.RENDER ? { width: q.width, height: q.height } : {}),
    },
  };
}

// ---------------------------------------------------------------------------------------------
// Render scenes: a quick image of the scene once it is loaded (the helper worker, the first
// estimator at a few spp and the chosen size), and the run workers import the render module
// while the reader looks at it.

const PREVIEW_SPP = 16;
let previewSerial = 0;

function requestScenePreview(state) {
  if (kindOf(state.sceneInfo) !== KIND.RENDER || !state.scene || !service) return;
  const key = ++previewSerial;
  // The estimator the scene's reference is rendered with (the least noisy of its kind).
  const ref = state.sceneInfo.reference && state.sceneInfo.reference.estimator;
  const estimator = ref && typeof ref === 'object' ? ref : state.sceneInfo.estimators[0];
  const label = ref && typeof ref === 'object' ? `${ref.strategy} (the reference's estimator)` : String(estimator || '');
  const { width, height } = state.params;
  const options = { spp: PREVIEW_SPP, outputs: ['png'], ...(estimator ? { estimator } : {}),
    ...(Number.isSafeInteger(width) ? { width } : {}), ...(Number.isSafeInteger(height) ? { height } : {}) };
  dispatch({ type: 'preview/request', payload: { key } });
  service.request(MSG.IMAGE, { scene: state.scene, options })
    .then(({ image }) => dispatch({ type: 'preview/loaded', payload: { key, png: image.images.png, spp: PREVIEW_SPP, estimator: label, seconds: image.seconds } }))
    .catch((e) => dispatch({ type: 'preview/failed', payload: { key, message: e && e.message ? e.message : String(e) } }));
  const k = Math.min(CORES, state.sceneInfo.estimators.length || 1);
  for (const w of runnersFor(k)) w.request(MSG.VALIDATE, { scene: state.scene }).catch(() => {});
}

store.subscribe((state, action) => {
  if (action.type === 'scene/loaded') requestScenePreview(state);
});

/** Builds the custom scene from f and p and has the core validate it (in the worker). */
async function applyCustom(fromUrl = null) {
  const token = ++sceneToken;
  const { f, p, exact: exactText } = store.getState().custom;
  const exact = parseExact(exactText);
  if (exactText.trim() && exact === null) {
    dispatch({ type: 'custom/error', payload: { field: 'exact', message: `exact value: '${exactText.trim()}' is not a number (leave it empty if unknown)`, position: null } });
    return false;
  }
  if (!f.trim()) {
    dispatch({ type: 'custom/error', payload: { field: 'f', message: 'scene.f: type an expression for f (then press "Use this problem")', position: null } });
    $('custom-f').focus();
    return false;
  }
  try {
    // The dimension f implies (the unit cube of its highest variable), then the whole scene.
    const first = await service.request(MSG.VALIDATE, { scene: { f } });
    const scene = buildCustomScene(f, p, first.info.dimension, exact);
    const info = normalizeInfo((await service.request(MSG.VALIDATE, { scene })).info);
    if (token !== sceneToken) return false;
    dispatch({
      type: 'scene/loaded',
      payload: { sceneId: CUSTOM, scene, info, custom: { f, p, exact: exactText.trim() }, ...(fromUrl ? paramsFromUrl(fromUrl, info) : {}) },
    });
    return true;
  } catch (e) {
    if (token === sceneToken) dispatch({ type: 'custom/error', payload: customError(e) });
    return false;
  }
}

function startRun() {
  const s = store.getState();
  const blocker = runBlocker(s);
  if (blocker) {
    dispatch({ type: 'notice', payload: { message: blocker } });
    return;
  }
  if (activeRun !== null) stopRunners();
  if (s.race.status === 'running') {
    stopRunners(); // the runners are shared: a run ends a race
    dispatch({ type: 'race/cancel', payload: { now: performance.now(), stopped: true } });
  }
  const names = s.selected.slice();
  const kind = kindOf(s.sceneInfo);
  const settings = runSettings(s);
  // Render studies of fewer estimators than cores split each estimator's replicates.
  const groups = kind === KIND.RENDER
    ? splitRenderWork(names, CORES, settings.reps)
    : splitEstimators(names, CORES).map((estimators) => ({ estimators, part: 0, parts: 1 }));
  const workers = runnersFor(groups.length);
  const results = groups.filter((g) => g.part === 0).length;
  const id = s.run.id + 1;
  const entry = kind === KIND.RENDER ? s.scenes.find((e) => e.name === s.sceneId) : null;
  const shipped = Boolean(entry && entry.reference && settings.width === entry.width && settings.height === entry.height);
  dispatch({
    type: 'run/start',
    payload: {
      id,
      kind,
      referenceShipped: shipped,
      workers: results,
      threads: groups.length,
      settings,
      order: names,
      exact: kind === KIND.RENDER ? null : s.sceneInfo.exact ?? null,
      sceneName: s.sceneInfo.name,
      colors: Object.fromEntries(s.sceneInfo.estimators.map((n, i) => [n, i])),
      startedAt: performance.now(),
    },
  });
  activeRun = id;
  // Draw the run's empty plots before the workers start, so that creating the charts does not
  // compete with the first, shortest levels, whose timings are the most fragile.
  renderHeavy();
  // On a phone the plots are below the controls: bring the first one into view.
  if (window.matchMedia && window.matchMedia('(max-width: 699px)').matches) {
    document.getElementById('plot-variance').closest('figure').scrollIntoView({ block: 'start' });
  }
  (shipped ? shippedReference(entry) : Promise.resolve(null)).then((referenceData) => {
    if (activeRun !== id) return;
    if (shipped && !referenceData) dispatch({ type: 'run/reference-unavailable', payload: { id } });
    const collectors = new Map(); // one per estimator split by replicate
    groups.forEach((group, i) => {
      const options = studyOptions(kind, settings, group.estimators);
      if (referenceData) options.reference_data = referenceData;
      if (group.parts === 1) {
        startPart(workers[i], id, s.scene, options);
        return;
      }
      const key = group.estimators.join('\n');
      if (!collectors.has(key)) collectors.set(key, splitRun(id, group.parts));
      startSplitPart(workers[i], id, s.scene, { ...options, part: group.part, parts: group.parts }, collectors.get(key), group.part);
    });
  });
}

/** The collector of one estimator split over `parts` workers: merged levels and result go to
 *  the store as an unsplit worker's would (the merges run in the helper worker). */
function splitRun(id, parts) {
  const live = () => activeRun === id;
  return splitCollector({
    parts,
    merge: (results) => service.request(MSG.MERGE, { parts: results }).then(({ result }) => result),
    onLevel: (level) => {
      if (live()) dispatch({ type: 'run/level', payload: { id, level } });
    },
    onResult: (result) => {
      if (live()) dispatch({ type: 'run/partial', payload: { id, result, now: performance.now() } });
    },
    onError: (e) => {
      if (!live()) return;
      stopRunners();
      dispatch({ type: 'run/error', payload: { id, message: e && e.message ? e.message : String(e) } });
    },
  });
}

/** One part of a split estimator's study: its lines and result go to the collector. */
function startSplitPart(worker, id, scene, options, collector, part) {
  worker.request(MSG.RUN, { scene: withoutStopping(scene), options, warmup: true }, (type, payload) => {
    if (type !== MSG.LEVEL) return;
    if (payload.level && payload.level.kind === 'render_reference') {
      if (part === 0) dispatch({ type: 'run/level', payload: { id, level: payload.level } });
      return;
    }
    collector.level(part, payload.level);
  }).then(({ result }) => {
    collector.result(part, result);
  }).catch((e) => {
    if (e && e.cancelled) return;
    if (activeRun === id) stopRunners();
    dispatch({ type: 'run/error', payload: { id, message: e && e.message ? e.message : String(e) } });
  });
}

/** One worker's part of run `id`: its estimators' study, each level sent on as it ends. */
function startPart(worker, id, scene, options) {
  // A scene's own rel_tol / abs_tol (stopping) belong to the race: the run is an N ladder.
  worker.request(MSG.RUN, { scene: withoutStopping(scene), options, warmup: true }, (type, payload) => {
    if (type === MSG.LEVEL) dispatch({ type: 'run/level', payload: { id, level: payload.level } });
  }).then(({ result }) => {
    dispatch({ type: 'run/partial', payload: { id, result, now: performance.now() } });
  }).catch((e) => {
    if (e && e.cancelled) return;
    if (activeRun === id) stopRunners();
    dispatch({ type: 'run/error', payload: { id, message: e && e.message ? e.message : String(e) } });
  });
}

/**
 * The race to a requested accuracy: one stopping study per selected estimator (its runs one
 * after another on one worker, so their seconds are their own), spread over the run workers;
 * each answer is shown as it comes. The runners are shared with the N-ladder run, which a race
 * ends (and the reverse).
 */
function startRace() {
  const s = store.getState();
  const blocker = runBlocker(s);
  if (blocker) {
    dispatch({ type: 'notice', payload: { message: blocker } });
    return;
  }
  if (kindOf(s.sceneInfo) === KIND.RENDER) return; // the card is hidden for render scenes
  const parsed = raceOptions(s.race.inputs);
  if (!parsed.ok) return; // the card shows why
  if (s.run.status === 'running') {
    stopRunners();
    dispatch({ type: 'run/cancel', payload: { now: performance.now(), stopped: true } });
  } else if (s.race.status === 'running') {
    stopRunners();
  }
  const names = s.selected.slice();
  const workers = runnersFor(Math.min(CORES, names.length));
  const id = s.race.id + 1;
  dispatch({
    type: 'race/start',
    payload: { id, order: names, options: parsed.options, sceneName: s.sceneInfo.name,
      exact: s.sceneInfo.exact ?? null, startedAt: performance.now() },
  });
  const scene = withoutStopping(s.scene);
  names.forEach((name, i) => {
    const options = { ...parsed.options, n_min: s.params.n_min, seed: s.params.seed, estimators: [name] };
    workers[i % workers.length].request(MSG.RUN, { scene, options, warmup: true })
      .then(({ result }) => dispatch({ type: 'race/part', payload: { id, result, now: performance.now() } }))
      .catch((e) => {
        if (e && e.cancelled) return;
        if (store.getState().race.id === id) stopRunners();
        dispatch({ type: 'race/error', payload: { id, message: `${name}: ${e && e.message ? e.message : String(e)}` } });
      });
  });
}

function download(name, href) {
  const a = document.createElement('a');
  a.href = href;
  a.download = name;
  document.body.append(a);
  a.click();
  a.remove();
}

function downloadText(name, text, type) {
  const url = URL.createObjectURL(new Blob([text], { type }));
  download(name, url);
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

function fileStem(s) {
  const r = s.run;
  const st = r.settings || s.params;
  const scene = String(r.sceneName || s.sceneId || 'scene').replace(/[^\w.-]+/g, '_');
  if (r.kind === KIND.RENDER) {
    return `mcplay-${scene}-spp${st.n_min}-${st.n_max}-R${st.reps}-seed${st.seed}-${st.width}x${st.height}`;
  }
  return `mcplay-${scene}-N${st.n_min}-${st.n_max}-R${st.reps}-seed${st.seed}`;
}

/** Base64 to a blob URL of `type`. */
function blobUrlOf(base64, type) {
  const bin = atob(base64);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  return URL.createObjectURL(new Blob([bytes], { type }));
}

/**
 * A render study's image as a file: `image` is an estimator of the run or 'reference'; `as` is
 * png (the picture shown), error (its relative-error picture) or hdr (linear Radiance, from the
 * core: the same replicate-0 image again, or the reference the study used).
 */
async function exportImage(s, image, as) {
  const r = s.run;
  const last = image === 'reference' ? null : r.records[image] && r.records[image].levels.at(-1);
  const ref = r.result && r.result.scene && r.result.scene.reference;
  const name = image === 'reference' ? `reference-spp${ref && ref.spp ? ref.spp : ''}` : `${image}-spp${last ? last.n : ''}`;
  const stem = `${fileStem(s)}-${name.replace(/[^\w.-]+/g, '_')}`;
  const save = (base64, ext, type) => {
    const url = blobUrlOf(base64, type);
    download(`${stem}.${ext}`, url);
    setTimeout(() => URL.revokeObjectURL(url), 10000);
  };
  if (as === 'png' || as === 'error') {
    const png = image === 'reference' ? r.referencePng : r.records[image] && (as === 'png' ? r.records[image].preview_png : r.records[image].error_png);
    if (!png) throw new Error(`no ${image} image yet`);
    save(png, as === 'png' ? 'png' : 'error.png', 'image/png');
    return;
  }
  const st = r.settings;
  const options = { seed: st.seed, width: st.width, height: st.height };
  if (image === 'reference') {
    options.outputs = ['reference_hdr'];
    const entry = s.scenes.find((e) => e.name === s.sceneId);
    const data = r.referenceShipped ? await shippedReference(entry) : null;
    if (data) options.reference_data = data;
  } else {
    if (!last) throw new Error(`no ${image} image yet`);
    Object.assign(options, { estimator: image, spp: last.n, outputs: ['hdr'] });
  }
  const { image: out } = await service.request(MSG.IMAGE, { scene: s.scene, options });
  save(out.images[image === 'reference' ? 'reference_hdr' : 'hdr'], 'hdr', 'image/vnd.radiance');
}

async function exportResult({ format, plot, image, as }) {
  const s = store.getState();
  if (format === 'image') {
    await exportImage(s, image, as);
    return;
  }
  if (format === 'samples') {
    const text = samplesCsv(s.samples.data);
    if (!text) throw new Error('no sample points yet');
    const scene = String(s.sceneInfo && s.sceneInfo.name ? s.sceneInfo.name : s.sceneId || 'scene').replace(/[^\w.-]+/g, '_');
    downloadText(`mcplay-${scene}-samples-n${s.samples.n}-seed${s.params.seed}.csv`, text, 'text/csv');
    return;
  }
  if (format === 'png') {
    const id = s.run.sceneName || s.sceneId;
    const title = sceneTitle(id);
    const url = await plotPng(plot, `${title && title !== id ? `${title} (${id})` : id}: ${s.run.order.filter((n) => !hiddenEstimators().includes(n)).join(', ')}`);
    if (!url) throw new Error(`the ${plot} plot is empty`);
    download(`${fileStem(s)}-${plot}.png`, url);
    return;
  }
  const result = s.run.result || partialResult(s.run, s.sceneInfo, s.version);
  if (!result.estimators.length) throw new Error('no results yet');
  if (format === 'json') {
    downloadText(`${fileStem(s)}.json`, `${JSON.stringify(result, null, 2)}\n`, 'application/json');
  } else {
    const { text } = await service.request(MSG.FORMAT, { result, format });
    downloadText(`${fileStem(s)}.${format}`, text, format === 'csv' ? 'text/csv' : 'text/plain');
  }
  dispatch({ type: 'notice', payload: { message: `exported ${format.toUpperCase()}${result.cancelled ? ' (partial: the run did not finish)' : ''}` } });
}

/** How the plots are being looked at, for a shared link (share.js): run=1 when there are plots. */
function currentView(s) {
  const r = s.run;
  const plotted = r.status !== 'running' && r.order.some((n) => r.records[n] && r.records[n].levels.length);
  return { hidden: hiddenEstimators(), calibration: s.calibration, points: s.samples.n, imageView: imageView(),
    race: s.race.inputs, run: plotted };
}

/** The link of the comparison and its view (a reader's glTF file cannot be in a link). */
function shareUrl(s) {
  const q = shareQuery(s, currentView(s));
  return q ? `${window.location.origin}${window.location.pathname}${q}` : window.location.href;
}

/** A shared link's view once its scene is in: hidden estimators, the sample view's points,
 *  the images' view and the race inputs now; the histogram's N once its run has started. */
function applyView(view) {
  if (view.hidden.length) setHidden(view.hidden);
  if (view.points !== store.getState().samples.n) dispatch({ type: 'samples/n', payload: { n: view.points } });
  setImageView(view.imageView);
  for (const [field, value] of Object.entries(view.race)) dispatch({ type: 'race/edit', payload: { field, value } });
}

async function copyLink() {
  const url = shareUrl(store.getState());
  try {
    await navigator.clipboard.writeText(url);
    dispatch({ type: 'notice', payload: { message: 'link copied' } });
  } catch {
    dispatch({ type: 'notice', payload: { message: `link: ${url}` } });
  }
}

// ---------------------------------------------------------------------------------------------
// Start-up: the core, the manifest, then the scene the URL names (or the first one).

async function start() {
  service = new CoreWorker(WORKER_URL);
  const manifest = fetch('scenes/manifest.json').then((r) => {
    if (!r.ok) throw new Error(`scenes/manifest.json: HTTP ${r.status}`);
    return r.json();
  });
  let version;
  try {
    ({ version } = await service.loaded);
  } catch (e) {
    dispatch({ type: 'core/failed', payload: { message: `the wasm core did not load: ${e.message}` } });
    return;
  }
  dispatch({ type: 'core/ready', payload: { version } });
  runnersFor(1); // warm one run worker while the scene loads
  // The clock where the timings are taken: the run worker measures its own step and tells
  // whether the page is cross-origin isolated (claims/clock.js says what that allows).
  const clockKnown = loadedReply(runners[0]).then(
    ({ clockStepMs, isolated }) => dispatch({ type: 'clock/measured', payload: { ms: clockStepMs, isolated } }),
    () => {});

  let scenes;
  try {
    scenes = await manifest;
  } catch (e) {
    dispatch({ type: 'core/failed', payload: { message: e.message } });
    return;
  }
  dispatch({ type: 'scenes/loaded', payload: { scenes } });
  lab.scenesLoaded(scenes);

  const search = window.location.search;
  const q = queryToState(search, { scene: scenes.length ? scenes[0].name : null });
  let ok = false;
  if (q.scene === CUSTOM) {
    dispatch({ type: 'custom/edit', payload: { field: 'f', value: q.f } });
    dispatch({ type: 'custom/edit', payload: { field: 'p', value: q.p } });
    dispatch({ type: 'custom/edit', payload: { field: 'exact', value: q.exact || '' } });
    ok = await applyCustom({ search });
  }
  if (!ok) {
    const known = scenes.some((s) => s.name === q.scene);
    const customFailed = q.scene === CUSTOM;
    // A broken custom link keeps its error shown and falls back to the first scene.
    const err = store.getState().custom.error;
    ok = await loadScene(known ? q.scene : (scenes[0] && scenes[0].name), customFailed ? null : { search });
    if (customFailed && err) dispatch({ type: 'custom/error', payload: err });
    if (ok && !customFailed && q.scene && !known) {
      dispatch({ type: 'notice', payload: { message: `unknown scene '${q.scene}' in the link: showing ${scenes[0].name}` } });
    }
  }
  // A shared link: name what it asked for that could not be used; restore how its plots were
  // looked at, and run it when it was made with plots to show (run=1), else offer to.
  if (ok && new URLSearchParams(search).has('scene') && store.getState().sceneId === q.scene) {
    const st = store.getState();
    const problems = urlProblems(search, st.sceneInfo ? st.sceneInfo.estimators : null, kindOf(st.sceneInfo));
    const what = problems.length ? `The link's ${problems.join('; ')}: the defaults are used instead. ` : '';
    const view = queryToView(search);
    if (hasView(search)) applyView(view);
    if (view.run && !runBlocker(store.getState())) {
      dispatch({ type: 'notice', payload: { message: `${what}Running this link's study: its plots draw as each N ends.` } });
      dispatch({ type: 'run/request' });
      if (view.calibration !== 'all') dispatch({ type: 'calibration/set', payload: { value: view.calibration } });
    } else {
      dispatch({ type: 'notice', payload: { message: `${what}Press Run to draw this link's plots.` } });
    }
    document.getElementById('run').focus({ preventScroll: true });
  }
  urlReady = true;
  writeUrl(store.getState());
  await clockKnown;
  runnersFor(Math.min(CORES, (store.getState().sceneInfo?.estimators || []).length || 1));
  return ok;
}

/** A worker's READY payload; a worker restarted meanwhile (a scene change stops busy run
 *  workers) answers its new load request instead. */
async function loadedReply(worker) {
  for (;;) {
    const loaded = worker.loaded;
    try {
      return await loaded;
    } catch (e) {
      if (!(e && e.cancelled) || worker.loaded === loaded) throw e;
    }
  }
}

// Resolves once the core is loaded and the first scene is shown; rejects with the reason if not.
const ready = start().then((ok) => {
  const s = store.getState();
  if (s.run.status === 'error') throw new Error(s.run.message);
  if (!ok) throw new Error(s.notice || 'no scene could be loaded');
  return true;
});
ready.catch(() => {});

// Read-only hook for tests: a structured-cloneable snapshot and a promise of the first scene.
window.mcplayDebug = Object.freeze({
  state: () => structuredClone(debugSnapshot(store.getState())),
  hidden: () => hiddenEstimators(),
  pngLegend: () => lastPngLegend(),
  // the link "Copy link" gives now, and where the time plot's guide labels were last drawn
  shareUrl: () => shareUrl(store.getState()),
  guideLabels: () => guideLabels(),
  lab: () => structuredClone(labSnapshot(lab.store.getState())),
  live: () => structuredClone(live.snapshot()),
  ready,
});
