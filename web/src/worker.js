// The Web Worker that owns the wasm cores: the only module that imports web/core.js,
// web/render_core.js and the Emscripten glue (paths are those of the built site:
// site/src/worker.js, site/core.js, site/render_core.js, site/mcplay_web.mjs + .wasm,
// site/mcplay_render_web.mjs + .wasm). Started as new Worker('src/worker.js', {type: 'module'}).
//
// Requests and replies are the messages of protocol.js. The integration core is loaded at
// start-up and every handler awaits the same promise: a top-level await before self.onmessage
// would lose the messages that arrive while the wasm compiles. The render core is imported
// (dynamic import) on the first request about a render scene only, so a page that shows
// integrals never downloads mcplay_render_web.wasm. Every failure goes back as an ERROR
// message; nothing is thrown out of a handler.
import createMcplay from '../mcplay_web.mjs';
import { loadCore } from '../core.js';
import { MSG, message, errorPayload, isRenderScene, float32OfBase64 } from './protocol.js';
import { clockResolution } from './series/time.js';

const ready = loadCore(createMcplay);
ready.catch(() => {}); // reported to each request below, not as an unhandled rejection

let renderReady = null;
/** The render core, imported and instantiated on first use (a failure is retried next time). */
function renderCore() {
  renderReady ??= Promise.all([import('../mcplay_render_web.mjs'), import('../render_core.js')])
    .then(([glue, wrapper]) => wrapper.loadRenderCore(glue.default))
    .catch((e) => {
      renderReady = null;
      throw new Error(`the render module did not load: ${e && e.message ? e.message : e}`);
    });
  return renderReady;
}

function reply(id, type, payload, transfer = []) {
  self.postMessage(message(id, type, payload), transfer);
}

// The live view's pixels: the core's base64 rgb_f32 becomes `rgb`, a Float32Array whose buffer
// is transferred to the page (no copy, no base64 on the page's thread).
function withPixels(block, transfer) {
  if (!block || typeof block !== 'object') return block;
  const { rgb_f32: b64, ...rest } = block;
  if (typeof b64 !== 'string') return rest;
  const rgb = float32OfBase64(b64);
  transfer.push(rgb.buffer);
  return { ...rest, rgb };
}

// A small image of each estimator before a render study, for the same reason as the
// integration warm-up below: V8 runs a wasm function's first calls in its baseline compiler.
// Its own random stream (seed + 1), a few pixels: it costs little and changes no number.
function warmRender(render, scene, options) {
  for (const estimator of options.estimators || []) {
    try {
      render.renderImage(scene, { estimator, spp: 2, width: 16, height: 16, seed: (options.seed || 0) + 1, outputs: [] });
    } catch {
      // the real study reports the error
    }
  }
}

const handlers = {
  [MSG.LOAD](core, id) {
    // The clock the core's timings are taken with: this worker's performance.now() and whether
    // the page is cross-origin isolated (browsers step the clock by ~5 us then, 100 us without).
    reply(id, MSG.READY, {
      version: core.version(),
      isolated: self.crossOriginIsolated === true,
      clockStepMs: clockResolution(() => performance.now()),
    });
  },
  async [MSG.VALIDATE](core, id, { scene }) {
    if (isRenderScene(scene)) {
      const render = await renderCore();
      reply(id, MSG.VALIDATED, { info: render.sceneInfo(scene) });
      return;
    }
    reply(id, MSG.VALIDATED, { info: core.sceneInfo(scene) });
  },
  async [MSG.RUN](core, id, { scene, options, warmup = false }) {
    // Each finished N goes to the page at once; cancelling is done by terminating this worker.
    const onLevel = (level) => {
      reply(id, MSG.LEVEL, { level });
    };
    if (isRenderScene(scene)) {
      const render = await renderCore();
      if (warmup) warmRender(render, scene, options || {});
      // The rows of a reference being rendered go the same way as levels (kind "render_reference").
      reply(id, MSG.RESULT, { result: render.runStudy(scene, options, onLevel, onLevel) });
      return;
    }
    if (warmup) {
      // A small study of the same scene and estimators first, so that the timed levels do not
      // include V8's lazy compilation of the wasm functions they use (the first call of a
      // function runs unoptimised code). It uses the study's seed, but each study starts its
      // random streams afresh, so the real study's numbers are those it gives alone.
      try {
        core.runStudy(scene, { estimators: options.estimators, n_min: 16, n_max: 4096, reps: 2, seed: options.seed });
      } catch {
        // the real study reports the error
      }
    }
    // With rel_tol or abs_tol (the page's race; or a scene's own fields) the answer is a
    // stopping result ("kind": "stopping"), sent whole when it ends: it has no levels.
    const result = core.runStudy(scene, options, onLevel);
    reply(id, MSG.RESULT, { result });
  },
  async [MSG.IMAGE](core, id, { scene, options }) {
    if (!isRenderScene(scene)) throw new Error('image: not a render scene (no "render" object)');
    const render = await renderCore();
    reply(id, MSG.IMAGED, { image: render.renderImage(scene, options) });
  },
  async [MSG.MERGE](core, id, { parts }) {
    const render = await renderCore();
    reply(id, MSG.MERGED, { result: render.mergeParts(parts) });
  },
  [MSG.FORMAT](core, id, { result, format }) {
    reply(id, MSG.FORMATTED, { text: core.format(result, format) });
  },
  [MSG.SAMPLES](core, id, { scene, options, fields = null }) {
    // The points of replicate 0 of a study at N = options.n. `fields` (e.g. ['weight']) drops
    // the other per-point arrays before the answer is copied to the page.
    const samples = core.samples(scene, options);
    if (Array.isArray(fields)) {
      const per = new Set(['u', 'x', 'f', 'density', 'weight']);
      samples.estimators = samples.estimators.map((e) => Object.fromEntries(
        Object.entries(e).filter(([k]) => !per.has(k) || fields.includes(k))));
      if (!fields.includes('curve')) delete samples.curve;
    }
    reply(id, MSG.SAMPLED, { samples });
  },
  // The sampler lab: one call of the core each, answered whole.
  [MSG.POINTS](core, id, { request }) {
    reply(id, MSG.POINTS_DRAWN, { points: core.points(request) });
  },
  // The renderer's per-pixel samplers: the render core, loaded on first use as for render scenes.
  async [MSG.PIXEL_POINTS](core, id, { request }) {
    const render = await renderCore();
    reply(id, MSG.PIXEL_POINTS_DRAWN, { points: render.pixelPoints(request) });
  },
  [MSG.ANALYZE](core, id, { request }) {
    reply(id, MSG.ANALYZED, { analysis: core.analyzePoints(request) });
  },
  [MSG.CURVE](core, id, { request }) {
    reply(id, MSG.CURVED, { curve: core.discrepancyCurve(request) });
  },
  [MSG.INTEGRATE_POINTS](core, id, { scene, request }) {
    reply(id, MSG.INTEGRATED, { result: core.integratePoints(scene, request) });
  },
  [MSG.WARP_TEST](core, id, { scene, options = null }) {
    reply(id, MSG.WARP_TESTED, { result: core.warpTest(scene, options) });
  },
  // The live view (render scenes): a reference rendered in the background (its rows as they
  // finish, at most one line per percent), and the sessions of one band each, pass by pass.
  async [MSG.REFERENCE](core, id, { scene, options = null }) {
    const render = await renderCore();
    let last = -1;
    const reference = render.reference(scene, options, (p) => {
      const pct = p && p.rows ? Math.floor((100 * p.rows_done) / p.rows) : 0;
      if (pct !== last) {
        last = pct;
        reply(id, MSG.REFERENCE_ROWS, { progress: p });
      }
    });
    reply(id, MSG.REFERENCED, { reference });
  },
  async [MSG.LIVE_OPEN](core, id, { scene, options = null }) {
    const render = await renderCore();
    const session = render.liveOpen(scene, options);
    const transfer = [];
    session.reference = withPixels(session.reference, transfer);
    reply(id, MSG.LIVE_OPENED, { session }, transfer);
  },
  async [MSG.LIVE_PASS](core, id, { session, pass }) {
    const render = await renderCore();
    const transfer = [];
    reply(id, MSG.LIVE_PASSED, { pass: withPixels(render.livePass(session, pass), transfer) }, transfer);
  },
  async [MSG.LIVE_REFERENCE](core, id, { session, reference }) {
    const render = await renderCore();
    const transfer = [];
    reply(id, MSG.LIVE_REFERENCED, { reference: withPixels(render.liveReference(session, reference), transfer) }, transfer);
  },
  async [MSG.LIVE_CLOSE](core, id, { session }) {
    const render = await renderCore();
    render.liveClose(session);
    reply(id, MSG.LIVE_CLOSED, {});
  },
};

self.onmessage = async (e) => {
  const { id = null, type, payload = {} } = e.data || {};
  try {
    const core = await ready;
    const handler = handlers[type];
    if (!handler) throw new Error(`worker: unknown message type '${type}'`);
    await handler(core, id, payload || {});
  } catch (err) {
    reply(id, MSG.ERROR, errorPayload(err));
  }
};
