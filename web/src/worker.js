// The Web Worker that owns one wasm core: the only module that imports web/core.js and the
// Emscripten glue (paths are those of the built site: site/src/worker.js, site/core.js,
// site/mcplay_web.mjs + .wasm). Started as new Worker('src/worker.js', {type: 'module'}).
//
// Requests and replies are the messages of protocol.js. The core is loaded at start-up and
// every handler awaits the same promise: a top-level await before self.onmessage would lose
// the messages that arrive while the wasm compiles. Every failure goes back as an ERROR
// message; nothing is thrown out of a handler.
import createMcplay from '../mcplay_web.mjs';
import { loadCore } from '../core.js';
import { MSG, message, errorPayload } from './protocol.js';

const ready = loadCore(createMcplay);
ready.catch(() => {}); // reported to each request below, not as an unhandled rejection

function reply(id, type, payload) {
  self.postMessage(message(id, type, payload));
}

const handlers = {
  [MSG.LOAD](core, id) {
    reply(id, MSG.READY, { version: core.version() });
  },
  [MSG.VALIDATE](core, id, { scene }) {
    reply(id, MSG.VALIDATED, { info: core.sceneInfo(scene) });
  },
  [MSG.RUN](core, id, { scene, options, warmup = false }) {
    if (warmup) {
      // A small study of the same scene and estimators first, so that the timed levels do not
      // include V8's lazy compilation of the wasm functions they use (the first call of a
      // function runs unoptimised code). It shares no random stream with the real study.
      try {
        core.runStudy(scene, { estimators: options.estimators, n_min: 16, n_max: 4096, reps: 2, seed: options.seed });
      } catch {
        // the real study reports the error
      }
    }
    // Each finished N goes to the page at once; cancelling is done by terminating this worker.
    const result = core.runStudy(scene, options, (level) => {
      reply(id, MSG.LEVEL, { level });
    });
    reply(id, MSG.RESULT, { result });
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
};

self.onmessage = async (e) => {
  const { id = null, type, payload = {} } = e.data || {};
  try {
    const core = await ready;
    const handler = handlers[type];
    if (!handler) throw new Error(`worker: unknown message type '${type}'`);
    handler(core, id, payload || {});
  } catch (err) {
    reply(id, MSG.ERROR, errorPayload(err));
  }
};
