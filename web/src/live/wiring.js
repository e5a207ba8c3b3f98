// The live view's wiring: its store, its own pool of workers (up to 4, one thread each), the
// sessions (one per row band, band i in worker i mod K), the passes, the reference and the
// drawing (once per animation frame).
//
// A view: the image size comes from the core (the scene info's live_size at the default long
// side, else a probe session of one row); the rows are cut into BANDS_PER_WORKER bands per
// worker, and every band opens a session (mcp_render_live_open, options.rows) in its worker. The
// reference the site ships at the default size (or one rendered here earlier) is given to the
// sessions (mcp_render_live_reference) right after their first pass is sent, so that the first
// image does not wait for it to be read (a few hundred ms a session). Each worker then
// takes its bands level by level (1, 2, 4, ... spp: every estimator's pass of every band it
// holds), at most one level ahead of the slowest worker, so the page holds few pending levels.
// The passes' pixels (Float32Array, transferred) and error sums are merged by model.js's
// collector into an estimator's level: its image, its relative MSE (sum of the bands' sums over
// the sum of their terms) and its seconds (the bands' seconds over the workers). Without a
// reference, one more worker renders it (mcp_render_reference at the view's size, progress by
// rows) and every session is given it (mcp_render_live_reference); the curves start then.
// Pause stops sending passes (those sent finish); Cancel terminates the workers at once and
// drops whatever they would still have answered.
import { createStore } from '../state.js';
import { CoreWorker } from '../client.js';
import { MSG } from '../protocol.js';
import {
  initialLive, liveReducer, liveActive, liveSnapshot, splitRows, workerOfBand, nextSpp, sessionOptions, createCollector,
  defaultEstimators, predictionText, liveWorkers, fitZoom, PREDICT_AT, BANDS_PER_WORKER, DEFAULT_LONG_SIDE, oneLine,
} from './model.js';
import { mountLive, syncLive, renderLive } from './view.js';

const HISTORY = 4; // levels kept per estimator for the wipe (images at the same spp)

/**
 * Starts the live view. `page`: {study(): {scene, info, sceneId, entry} of the study's scene
 * (info normalised; null scene when none), liveReference(entry): a promise of the shipped
 * reference's base64 at the default live size (or null), runStudy(): starts the study,
 * workerUrl, cores: navigator.hardwareConcurrency, workers: an override of the pool's size}.
 */
export function startLive(page) {
  const store = createStore(liveReducer, initialLive());
  const { dispatch } = store;
  const pool = [];
  let refWorker = null;
  let run = null; // the view in progress: {id, sessions, ...}
  let serial = 0;
  const references = new Map(); // `${scene key}:${w}x${h}` -> reference_data rendered here
  const px = { width: 0, height: 0, bands: 0, exposure: 0, images: new Map(), reference: null };
  const dom = { spp: document.getElementById('live-plot-spp'), seconds: document.getElementById('live-plot-seconds') };
  let sceneKey = null;   // the scene's name (references rendered here are kept by it and the size;
  let sceneShown = null; // the core refuses one made from another glTF, and one is rendered again)

  const poolSize = () => liveWorkers(page.cores, page.workers);
  function workers(k) {
    while (pool.length < k) pool.push(new CoreWorker(page.workerUrl));
    return pool.slice(0, k);
  }

  // -------------------------------------------------------------------------------------------
  // Drawing, once per animation frame at most

  let framed = false;
  const frame = () => {
    framed = false;
    try {
      renderLive(store.getState(), px, dom);
    } catch (e) {
      console.error('live render failed', e);
    }
  };
  const schedule = () => {
    if (!framed) {
      framed = true;
      requestAnimationFrame(frame);
    }
  };

  function sceneFacts() {
    const { info } = page.study();
    const render = Boolean(info && info.kind === 'render');
    return { render, names: render ? info.estimators : [] };
  }

  store.subscribe((state) => {
    syncLive(state, sceneFacts());
    schedule();
  });

  // -------------------------------------------------------------------------------------------
  // A view

  /** Stops the view now: the busy workers are terminated (and restarted empty). */
  function stopWorkers() {
    for (const w of pool) if (w.busy) w.restart();
    if (refWorker && refWorker.busy) refWorker.restart();
  }

  function cancel() {
    if (!run) return;
    const { id } = run;
    run = null;
    stopWorkers();
    dispatch({ type: 'live/cancel', payload: { id } });
  }

  function fail(id, e) {
    if (!run || run.id !== id) return;
    run = null;
    stopWorkers();
    dispatch({ type: 'live/error', payload: { id, message: e && e.message ? e.message : String(e) } });
  }

  /** Width and height of the view at `longSide`: the scene info's live_size at the default,
   *  else a probe session of one row (its errors are the view's: a size beyond the limits, an
   *  extreme aspect). */
  async function imageSize(scene, info, longSide, options) {
    if (longSide === DEFAULT_LONG_SIDE && info.live_size && info.live_size.width > 0) {
      return { width: info.live_size.width, height: info.live_size.height };
    }
    const w = workers(1)[0];
    const { session } = await w.request(MSG.LIVE_OPEN, { scene, options: { ...options, rows: [0, 1] } });
    w.request(MSG.LIVE_CLOSE, { session: session.session }).catch(() => {});
    return { width: session.width, height: session.height };
  }

  async function start() {
    const { scene, info, entry } = page.study();
    const s = store.getState();
    if (!scene || !info || info.kind !== 'render') return;
    if (run) cancel();
    const order = (s.choice.estimators || []).filter((n) => info.estimators.includes(n));
    if (!order.length) return;
    const id = ++serial;
    const k = poolSize();
    const ws = workers(k);
    const colors = Object.fromEntries(info.estimators.map((n, i) => [n, i]));
    const longSide = s.choice.longSide;
    const sampler = s.choice.sampler;
    const maxSpp = s.choice.maxSpp;
    run = { id, sessions: [], ws, order, maxSpp, longSide };
    const me = run;
    const live = () => run === me;
    px.width = 0;
    px.height = 0;
    px.bands = 0;
    px.images = new Map();
    px.reference = null;
    px.exposure = Number(scene.render && scene.render.exposure) || 0;
    dispatch({ type: 'live/start', payload: { id, order, colors, workers: k, startedAt: performance.now() } });
    try {
      performance.mark('live:start');
      // the shipped reference (fetched when the scene was shown) is given to the sessions after
      // their first pass is sent: reading it costs each session a few hundred ms, which the first
      // image should not wait for (its curves start at the next pass)
      const shipped = longSide === DEFAULT_LONG_SIDE && entry ? page.liveReference(entry) : Promise.resolve(null);
      const base = { estimators: order, sampler, longSide, rows: [0, 1] };
      const size = await imageSize(scene, info, longSide, sessionOptions(base));
      if (!live()) return;
      const key = `${sceneKey}:${size.width}x${size.height}`;
      const bands = splitRows(size.height, k * BANDS_PER_WORKER);
      px.width = size.width;
      px.height = size.height;
      px.bands = bands.length;
      // the images side by side at the largest whole zoom that fits the page (the reader may change it)
      const box = document.getElementById('live-images').clientWidth || 1200;
      dispatch({ type: 'live/view', payload: { zoom: Math.min(8, fitZoom(size.width + 20, order.length + 1, box)) } });
      me.bands = bands;
      me.collector = createCollector({ width: size.width, height: size.height, bands, workers: k });
      me.workerState = ws.map((w, i) => ({ w, bands: bands.map((_, b) => b).filter((b) => workerOfBand(b, k) === i), spp: 0, outstanding: 0 }))
        .filter((x) => x.bands.length);
      // every band's session, in its worker
      const opened = await Promise.all(bands.map((rows, b) => ws[workerOfBand(b, k)].request(MSG.LIVE_OPEN, {
        scene, options: sessionOptions({ ...base, rows }),
      })));
      if (!live()) return;
      me.sessions = opened.map((o) => o.session.session);
      performance.mark('live:opened');
      dispatch({ type: 'live/opened', payload: { id, size } });
      me.passesFrom = performance.now();
      pump(me);
      const shippedData = await shipped;
      if (!live()) return;
      const data = shippedData || references.get(key) || null;
      if (!data || !(await giveReference(me, data, shippedData ? 'shipped' : 'rendered'))) renderReference(me, scene, size, key);
    } catch (e) {
      if (e && e.cancelled) return;
      fail(id, e);
    }
  }

  /** The reference's bands (each session's reference.rgb) as one image. */
  function placeReference(me, refs) {
    const w = px.width;
    const img = new Float32Array(w * px.height * 3);
    refs.forEach((r, b) => img.set(r.rgb, me.bands[b][0] * w * 3));
    px.reference = img;
  }

  /** Gives every session the reference (mcp_render_live_reference); false when the core does
   *  not take it (made from another scene or size: then one is rendered). */
  async function giveReference(me, data, source) {
    try {
      const given = await Promise.all(me.sessions.map((session, b) => me.ws[workerOfBand(b, me.ws.length)]
        .request(MSG.LIVE_REFERENCE, { session, reference: { reference_data: data } })));
      if (run !== me) return true;
      placeReference(me, given.map((g) => g.reference));
      performance.mark('live:reference');
      dispatch({ type: 'live/reference', payload: { id: me.id, reference: { status: 'ready', source, spp: given[0].reference.spp,
        floor: given[0].reference.relative_mse_floor ?? null, progress: 1 } } });
      return true;
    } catch (e) {
      if (e && e.cancelled) return true;
      return false;
    }
  }

  /** The reference at the view's size, rendered by one more worker, then given to every session. */
  async function renderReference(me, scene, size, key) {
    const { id } = me;
    dispatch({ type: 'live/reference', payload: { id, reference: { status: 'rendering', progress: 0 } } });
    refWorker ??= new CoreWorker(page.workerUrl);
    try {
      const { reference } = await refWorker.request(MSG.REFERENCE, {
        scene, options: { live: true, long_side: me.longSide },
      }, (type, payload) => {
        if (type !== MSG.REFERENCE_ROWS || run !== me) return;
        const p = payload.progress || {};
        dispatch({ type: 'live/reference', payload: { id, reference: { progress: p.rows ? p.rows_done / p.rows : 0 } } });
      });
      references.set(key, reference.reference_data);
      if (run !== me) return;
      if (!(await giveReference(me, reference.reference_data, 'rendered')) && run === me) {
        dispatch({ type: 'live/reference', payload: { id, reference: { status: 'error', message: 'the sessions did not take the reference rendered for them' } } });
      }
    } catch (e) {
      if (e && e.cancelled) return;
      if (run === me) dispatch({ type: 'live/reference', payload: { id, reference: { status: 'error', message: oneLine(e.message) } } });
    }
  }

  /** Sends each idle worker its next level, at most one level ahead of the slowest. */
  function pump(me) {
    if (run !== me || store.getState().status !== 'running') return;
    const slowest = Math.min(...me.workerState.map((x) => x.spp));
    const limit = slowest ? 4 * slowest : 2;
    for (const x of me.workerState) {
      if (x.outstanding) continue;
      const spp = nextSpp(x.spp);
      if (spp > me.maxSpp || spp > limit) continue;
      x.outstanding = me.order.length * x.bands.length;
      me.order.forEach((_, e) => {
        for (const b of x.bands) {
          x.w.request(MSG.LIVE_PASS, { session: me.sessions[b], pass: { estimator: e, spp, pixels: true } })
            .then(({ pass }) => {
              if (run !== me) return;
              const level = me.collector.add(e, b, pass);
              if (level) onLevel(me, level);
              x.outstanding -= 1;
              if (!x.outstanding) {
                x.spp = spp;
                pump(me);
              }
            })
            .catch((err) => {
              if (err && err.cancelled) return;
              fail(me.id, err);
            });
        }
      });
    }
  }

  function onLevel(me, level) {
    const name = me.order[level.estimator];
    const im = px.images.get(name) || { spp: 0, rgb: null, history: new Map() };
    im.spp = level.spp;
    im.rgb = level.rgb;
    im.history.set(level.spp, level.rgb);
    while (im.history.size > HISTORY) im.history.delete(im.history.keys().next().value);
    px.images.set(name, im);
    if (!me.firstLevel) {
      me.firstLevel = true;
      performance.mark('live:first-level');
    }
    dispatch({ type: 'live/level', payload: { id: me.id, estimator: name, spp: level.spp, seconds: level.seconds, relmse: level.relmse, now: performance.now() } });
    const st = store.getState();
    const reached = me.order.map((n) => st.estimators[n].spp);
    // how long 64 spp will take: after the first pass when that pass alone says it is long, else
    // (and more closely) after PREDICT_AT spp; the pass to PREDICT_AT spp added PREDICT_AT / 2 spp
    if (level.spp === PREDICT_AT) me.perSpp = (me.perSpp || 0) + level.passSeconds / (PREDICT_AT / 2);
    const elapsed = (performance.now() - me.passesFrom) / 1000;
    if (reached.every((v) => v >= 1) && !me.early && level.spp === 1) {
      me.early = true;
      const early = predictionText(elapsed, elapsed, px.width, px.height, 1);
      if (early.long) {
        me.pausedOnce = true;
        dispatch({ type: 'live/prediction', payload: { id: me.id, prediction: early } });
      }
    }
    if (reached.every((v) => v >= PREDICT_AT) && !me.predicted) {
      me.predicted = true;
      const prediction = predictionText(elapsed, me.perSpp, px.width, px.height, PREDICT_AT, !me.pausedOnce);
      dispatch({ type: 'live/prediction', payload: { id: me.id, prediction } });
    }
    if (reached.every((v) => v >= me.maxSpp)) {
      dispatch({ type: 'live/done', payload: { id: me.id } });
      me.sessions.forEach((session, b) => me.ws[workerOfBand(b, me.ws.length)].request(MSG.LIVE_CLOSE, { session }).catch(() => {}));
      run = null;
    }
  }

  mountLive(store, {
    start,
    pause: () => dispatch({ type: 'live/pause', payload: { id: run ? run.id : undefined } }),
    resume: () => {
      dispatch({ type: 'live/resume', payload: { id: run ? run.id : undefined } });
      if (run) pump(run);
    },
    cancel,
    runStudy: () => {
      if (store.getState().status === 'running') dispatch({ type: 'live/pause', payload: { id: run ? run.id : undefined } });
      page.runStudy();
    },
  });

  /** The study's scene changed: a running view of another scene stops; the estimators chosen
   *  become the new scene's defaults (model.js: its MIS estimators and what they combine); the
   *  pool is started (render module loaded) early. */
  function sceneChanged() {
    const { scene, info, sceneId } = page.study();
    const render = Boolean(info && info.kind === 'render');
    const next = render ? `${sceneId}:${info.name}` : null;
    if (next === sceneKey && scene === sceneShown) return;
    sceneKey = next;
    sceneShown = scene;
    if (run) cancel();
    const chosen = render ? defaultEstimators(info.estimatorDetails || info.estimators) : null;
    dispatch({ type: 'live/choose', payload: { estimators: chosen } });
    if (render) {
      page.liveReference(page.study().entry); // fetched while the reader looks
      // the render module compiles in every worker of the pool while the reader looks
      for (const w of workers(poolSize())) w.request(MSG.VALIDATE, { scene }).catch(() => {});
    }
  }

  syncLive(store.getState(), sceneFacts());
  return {
    store,
    sceneChanged,
    snapshot: () => ({ ...liveSnapshot(store.getState()), size: px.width ? { width: px.width, height: px.height } : null, bands: px.bands,
      // passes sent and not yet answered (Pause lets them finish)
      inFlight: run && run.workerState ? run.workerState.reduce((a, x) => a + x.outstanding, 0) : 0,
      canvases: [...document.querySelectorAll('#live-section canvas.live-canvas')].map((c) => ({ key: c.dataset.live || c.id, width: c.width, height: c.height, spp: c.dataset.spp || null })) }),
    active: () => liveActive(store.getState()),
  };
}
