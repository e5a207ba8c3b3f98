// The sampler lab's wiring: its store, its view, and the effects that send its requests to the
// helper Web Worker (protocol.js: warpTest, analyze, points, pixelPoints, integratePoints, curve) and put the
// answers in the store. main.js starts it with the page's helper worker, the manifest and the
// hooks it shares with the study (the URL, opening a warp scene's study).
import { createStore } from '../state.js';
import { MSG } from '../protocol.js';
import {
  labReducer, queryToLab, labToQuery, TYPED, BUILTIN_WARPS, typedWarpScene, warpOptions, analyzeRequest,
  samplerRequest, fileRequest, pointSource, curveRequest, displayRows, isPixelSampler, opensOnExample,
} from './model.js';
import { mountLab, syncLab, renderLab } from './view.js';

/**
 * Starts the lab. `page`: {service(): the CoreWorker of the helper worker (null before the
 * core loads), scenes(): the manifest, fetchScene(entry): a scene's JSON, onChange(): the URL
 * may have changed, openStudy(name): show a scene in the study}. Returns {store, query()}.
 */
export function startLab(page, search) {
  const store = createStore(labReducer, queryToLab(search));
  const { dispatch } = store;
  let serial = 0;
  const message = (e) => (e && e.message ? e.message : String(e));

  mountLab(store, {
    openStudy: (name) => {
      dispatch({ type: 'lab/view', payload: { view: 'study' } });
      page.openStudy(name);
    },
  });

  let framed = false;
  const frame = () => {
    framed = false;
    try {
      renderLab(store.getState());
    } catch (e) {
      console.error('lab render failed', e);
    }
  };
  store.subscribe((state) => {
    syncLab(state, page.scenes(), dispatch);
    if (!framed) {
      framed = true;
      requestAnimationFrame(frame);
    }
    page.onChange();
  });

  function need() {
    const s = page.service();
    if (!s) throw new Error('the core is loading');
    return s;
  }

  /** The scene of the chosen example (built in, or a warp scene of the manifest) or of the typed warp. */
  async function warpScene(w) {
    if (w.example === TYPED) {
      const t = typedWarpScene(w.typed);
      if (t.error) throw new Error(t.error);
      return t.scene;
    }
    const builtin = BUILTIN_WARPS.find((b) => b.name === w.example);
    const entry = page.scenes().find((e) => e.name === w.example);
    if (entry) return page.fetchScene(entry);
    if (builtin) return builtin.scene;
    throw new Error(`unknown warp example '${w.example}'`);
  }

  async function runWarp() {
    const id = ++serial;
    const w = store.getState().warp;
    dispatch({ type: 'lab/warp/start', payload: { id } });
    try {
      const o = warpOptions(w);
      if (o.error) throw new Error(o.error);
      const scene = await warpScene(w);
      const { result } = await need().request(MSG.WARP_TEST, { scene, options: o.options });
      dispatch({ type: 'lab/warp/done', payload: { id, result } });
    } catch (e) {
      dispatch({ type: 'lab/warp/error', payload: { id, message: message(e) } });
    }
  }

  /** The rows of a renderer's pixel sampler (the render core, through the helper worker). */
  async function pixelRows(request) {
    return (await need().request(MSG.PIXEL_POINTS, { request })).points.points;
  }

  async function runAnalysis() {
    const id = ++serial;
    const pt = store.getState().points;
    dispatch({ type: 'lab/points/start', payload: { id } });
    try {
      // a renderer's pixel sampler: its rows first, analysed as given points
      const pixel = pt.source !== 'file' && isPixelSampler(pt.sampler);
      let rows = null;
      if (pixel) {
        const s = pointSource(pt);
        if (s.error) throw new Error(s.error);
        rows = await pixelRows(s.pixel);
      }
      // one coordinate: no spectrum axes to ask for
      const made = analyzeRequest(pt, rows);
      if (made.error) throw new Error(made.error);
      const request = made.request;
      const dim = pt.source === 'file' ? null : Number(pt.dim);
      if (dim === 1) request.spectrum = { size: 256 };
      const { analysis } = await need().request(MSG.ANALYZE, { request });
      if (pixel) {
        // rows already drawn
      } else if (pt.source === 'file') {
        rows = displayRows(pt.file.request);
      } else {
        const s = samplerRequest(pt).sampler;
        const { sets: _sets, ...one } = s;
        rows = (await need().request(MSG.POINTS, { request: one })).points.points;
      }
      dispatch({ type: 'lab/points/done', payload: { id, analysis, rows } });
    } catch (e) {
      dispatch({ type: 'lab/points/error', payload: { id, message: message(e) } });
    }
  }

  async function problemScene(name) {
    const entry = page.scenes().find((e) => e.name === name);
    if (!entry) throw new Error(`unknown problem '${name}'`);
    return page.fetchScene(entry);
  }

  async function runIntegrate() {
    const id = ++serial;
    const pt = store.getState().points;
    dispatch({ type: 'lab/integrate/start', payload: { id } });
    try {
      const s = pointSource(pt);
      if (s.error) throw new Error(s.error);
      const scene = await problemScene(pt.problem);
      const request = s.pixel ? { points: await pixelRows(s.pixel) } : s.source;
      const { result } = await need().request(MSG.INTEGRATE_POINTS, { scene, request });
      dispatch({ type: 'lab/integrate/done', payload: { id, result } });
    } catch (e) {
      dispatch({ type: 'lab/integrate/error', payload: { id, message: message(e) } });
    }
  }

  async function runCurve() {
    const id = ++serial;
    const st = store.getState();
    dispatch({ type: 'lab/curve/start', payload: { id } });
    try {
      const scene = st.points.problem ? await problemScene(st.points.problem) : null;
      const made = curveRequest(st.curve, scene);
      if (made.error) throw new Error(made.error);
      const { curve } = await need().request(MSG.CURVE, { request: made.request });
      dispatch({ type: 'lab/curve/done', payload: { id, result: curve } });
    } catch (e) {
      dispatch({ type: 'lab/curve/error', payload: { id, message: message(e) } });
    }
  }

  async function openFile(file) {
    try {
      const text = await file.text();
      const made = fileRequest(file.name, text, file.size);
      dispatch({ type: 'lab/points/file', payload: { name: file.name, ...made } });
      if (!made.error) runAnalysis();
    } catch (e) {
      dispatch({ type: 'lab/points/file', payload: { name: file.name, error: `${file.name}: ${message(e)}` } });
    }
  }

  // The lab opens on a running example (its "what to look for" beside it): the first time the
  // warp test is shown once the examples and the core are in.
  let examplesIn = false;
  const openOnExample = () => {
    if (opensOnExample(store.getState(), { examples: examplesIn, core: Boolean(page.service()) })) runWarp();
  };

  store.subscribe((state, action) => {
    const p = action.payload || {};
    if (action.type === 'lab/view' || action.type === 'lab/tab') openOnExample();
    switch (action.type) {
      case 'lab/warp/request': runWarp(); break;
      case 'lab/points/request': runAnalysis(); break;
      case 'lab/points/open': openFile(p.file); break;
      case 'lab/integrate/request': runIntegrate(); break;
      case 'lab/curve/request': runCurve(); break;
      default:
    }
  });

  /** The manifest's warp scenes become examples (call once the manifest is in). */
  function scenesLoaded(scenes) {
    const entries = scenes.filter((e) => e.warp).map((e) => ({ ...e, hasIntegrand: e.kind !== 'warp' }));
    dispatch({ type: 'lab/examples', payload: { entries } });
    examplesIn = true;
    openOnExample();
  }

  syncLab(store.getState(), [], dispatch);
  return { store, query: () => labToQuery(store.getState()), scenesLoaded };
}
