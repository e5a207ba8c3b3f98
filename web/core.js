// The only module that talks to the wasm core (build-wasm/mcplay_web.mjs, the C API of
// src/api/mcplay.h). Plain ES module: no bundler, no DOM, no Node APIs, so it runs in a page,
// in a (module) Web Worker and in Node.
//
//   import createMcplay from './mcplay_web.mjs';
//   const core = await loadCore(createMcplay);              // Node: loadCore(createMcplay, {wasmBinary})
//   const result = core.runStudy(scene, {n_max: 4096}, (level) => { draw(level); });
//
// Every call is synchronous once the core is loaded (a long study blocks its thread: run it
// in a Worker). Strings go in through malloc + stringToUTF8 and come out through the C API's
// char** out-parameters, which are freed with mcp_free on every path. That machinery
// (wasmBridge, instantiate) is shared with render_core.js, the wrapper of the render module.

/** Status codes of src/api/mcplay.h (enum mcp_status). */
export const Status = Object.freeze({ OK: 0, ARGUMENT: 1, SCENE: 2, CANCELLED: 3, INTERNAL: 4, FUNCTION: 5 });

const STATUS_NAMES = Object.freeze(['OK', 'ARGUMENT', 'SCENE', 'CANCELLED', 'INTERNAL', 'FUNCTION']);

/** A failed C call: `status` is the C status code, `message` the C API's mcp_last_error(). */
export class McplayError extends Error {
  constructor(status, message) {
    super(message);
    this.name = 'McplayError';
    this.status = status;
    this.statusName = STATUS_NAMES[status] ?? `status ${status}`;
  }
}

/** The module's exported functions this wrapper needs: exactly src/wasm/exported_functions.txt
 *  (web/test/core.test.mjs checks that the two lists agree). */
export const WASM_FUNCTIONS = Object.freeze([
  '_malloc', '_free',
  '_mcp_version', '_mcp_last_error', '_mcp_study_run', '_mcp_study_plan', '_mcp_result_format',
  '_mcp_scene_info', '_mcp_catalog', '_mcp_study_samples',
  '_mcp_points', '_mcp_points_analyze', '_mcp_discrepancy_curve', '_mcp_points_integrate', '_mcp_warp_test',
  '_mcp_free',
  '_mallinfo',
]);

/** The Emscripten runtime helpers this wrapper uses (all listed in
 *  src/wasm/exported_runtime_methods.txt). */
export const WASM_RUNTIME_METHODS = Object.freeze([
  'UTF8ToString', 'stringToUTF8', 'lengthBytesUTF8', 'addFunction', 'removeFunction',
  'getValue', 'setValue', 'HEAPU8',
]);

const FORMATS = Object.freeze(['table', 'csv', 'json']);

/** Largest JSON text sent to the core: the C side's limit (kMaxJsonBytes, src/api/json_read.h),
 *  checked here before any wasm memory is allocated for it. */
export const MAX_JSON_BYTES = 256 * 1024 * 1024;

/**
 * Instantiates the wasm module and returns the core.
 * @param {Function} createMcplay the default export of mcplay_web.mjs
 * @param {object} moduleOptions Emscripten module options, e.g. {wasmBinary} in Node or
 *        {locateFile} when the .wasm is not beside the .mjs
 */
export async function loadCore(createMcplay, moduleOptions = {}) {
  return makeCore(await instantiate(createMcplay, moduleOptions, WASM_FUNCTIONS, 'loadCore', 'mcplay_web'));
}

/**
 * The calling machinery shared by the wasm modules' wrappers (this file and render_core.js):
 * strings in through malloc, `char** out` results out and freed with mcp_free, errors as
 * McplayError with mcp_last_error's message, one progress trampoline routed to the study in
 * progress, and a module that trapped never used again. `M` is an instantiated Emscripten
 * module exporting _malloc, _free, _mcp_last_error, _mcp_free, _mallinfo and the runtime
 * methods of WASM_RUNTIME_METHODS. Not part of the public API.
 */
export function wasmBridge(M) {
  // The study in progress ({onLevel, error}); the single progress trampoline routes to it.
  let active = null;
  // Set when the wasm itself failed (a trap or an abort): its state is unknown from then on.
  let broken = null;
  let disposed = false;

  const trampoline = (levelPtr, _user) => {
    const call = active;
    if (!call || call.error) return 1;
    try {
      const level = JSON.parse(M.UTF8ToString(levelPtr));
      return call.onLevel(level) === true ? 1 : 0;
    } catch (e) {
      // Never let a JS exception unwind through the C++ frames: remember it, ask the study to
      // stop, and rethrow once the study has returned and everything is freed.
      call.error = { value: e };
      return 1;
    }
  };
  const progressPtr = M.addFunction(trampoline, 'iii');

  function usable(what) {
    if (disposed) throw new McplayError(Status.ARGUMENT, `${what}: the core was disposed`);
    if (broken) {
      throw new McplayError(Status.INTERNAL,
        `${what}: the wasm core failed earlier and cannot be used (${broken.message ?? broken})`);
    }
  }

  // Runs a C call; an exception out of it is a wasm trap/abort (JS exceptions from onLevel
  // are caught in the trampoline), after which the module is not used again.
  function callC(fn, ...args) {
    try {
      return fn(...args);
    } catch (e) {
      broken = e;
      throw e;
    }
  }

  function lastError(status) {
    const message = M.UTF8ToString(M._mcp_last_error());
    return message || `mcplay: status ${STATUS_NAMES[status] ?? status} without a message`;
  }

  function malloc(bytes) {
    const p = M._malloc(bytes);
    if (!p) throw new McplayError(Status.INTERNAL, `out of wasm memory (allocating ${bytes} bytes)`);
    return p;
  }

  // ASCII text (the JSON of images and references as base64: megabytes) is copied by the
  // engine's TextEncoder, the bytes stringToUTF8 writes, without its loop over the characters
  // in JavaScript; other text goes through stringToUTF8.
  const ASCII = /^[\x00-\x7f]*$/;
  const encoder = typeof TextEncoder === 'function' ? new TextEncoder() : null;
  const utf8Length = (text) => (ASCII.test(text) ? text.length : M.lengthBytesUTF8(text));

  // A JS string as a NUL-terminated UTF-8 copy on the C heap; the caller frees it.
  function cString(text) {
    if (encoder && ASCII.test(text)) {
      const p = malloc(text.length + 1);
      encoder.encodeInto(text, M.HEAPU8.subarray(p, p + text.length));
      M.HEAPU8[p + text.length] = 0;
      return p;
    }
    const bytes = M.lengthBytesUTF8(text) + 1;
    const p = malloc(bytes);
    M.stringToUTF8(text, p, bytes);
    return p;
  }

  // Object or JSON text -> JSON text for the C API. JSON.stringify would turn NaN and
  // +/-Infinity into null silently (an `exact` of NaN becoming "unknown"): they are refused,
  // naming the field (`scene.exact`, `options.estimators[1].pdf.mu`).
  function jsonText(value, what) {
    let text = value;
    if (typeof value !== 'string') {
      if (value === null || typeof value !== 'object') {
        throw new McplayError(Status.ARGUMENT, `${what}: expected an object or JSON text, got ` +
          (value === null ? 'null' : typeof value));
      }
      const paths = new Map(); // object -> its path, filled as stringify walks down
      function replacer(key, v) {
        const parent = paths.get(this);
        const path = parent === undefined ? what
          : Array.isArray(this) ? `${parent}[${key}]` : `${parent}.${key}`;
        if (typeof v === 'number' && !Number.isFinite(v)) {
          throw new McplayError(Status.ARGUMENT, `${path}: expected a finite number, got ${v}`);
        }
        if (v !== null && typeof v === 'object') paths.set(v, path);
        return v;
      }
      try {
        text = JSON.stringify(value, replacer);
      } catch (e) {
        if (e instanceof McplayError) throw e;
        throw new McplayError(Status.ARGUMENT, `${what}: cannot be written as JSON (${e.message})`);
      }
      if (text === undefined) {
        throw new McplayError(Status.ARGUMENT, `${what}: cannot be written as JSON`);
      }
    }
    if (text.includes('\0')) {
      throw new McplayError(Status.ARGUMENT, `${what}: contains a NUL character`);
    }
    // Before any allocation: a text beyond the C side's limit would only be refused there,
    // after growing the wasm memory for it (or failing to).
    if (text.length > MAX_JSON_BYTES || utf8Length(text) > MAX_JSON_BYTES) {
      throw new McplayError(Status.ARGUMENT, `${what}: the JSON text has more than the limit of ` +
        `${MAX_JSON_BYTES} bytes`);
    }
    return text;
  }

  // null/undefined -> null (the C API's NULL), else JSON text.
  function optionalJson(value, what) {
    return value === null || value === undefined ? null : jsonText(value, what);
  }

  /**
   * Calls a C function whose last argument is a `char** out`, with `inputs` (JS strings or
   * null) as its leading char* arguments and `extra` between them and the out slot. Returns
   * {status, text} where text is the out string (null if none); frees everything.
   */
  function callOut(fn, inputs, extra = []) {
    const ptrs = [];
    let slot = 0;
    try {
      for (const s of inputs) ptrs.push(s === null ? 0 : cString(s));
      slot = malloc(4);
      M.setValue(slot, 0, 'i32');
      const status = callC(fn, ...ptrs, ...extra, slot);
      const out = M.getValue(slot, 'i32') >>> 0;
      let text = null;
      if (out) {
        try {
          text = M.UTF8ToString(out);
        } finally {
          M._mcp_free(out);
        }
      }
      // Read the message before anything else can touch mcp_last_error.
      const message = status === Status.OK ? '' : lastError(status);
      return { status, text, message };
    } finally {
      if (!broken) {
        if (slot) M._free(slot);
        for (const p of ptrs) if (p) M._free(p);
      }
    }
  }

  // The out string of a call that must succeed, or the McplayError it failed with.
  function textOf(r, fnName) {
    if (r.status === Status.OK && r.text !== null) return r.text;
    if (r.status === Status.OK) throw new McplayError(Status.INTERNAL, `${fnName}: OK but no output`);
    throw new McplayError(r.status, r.message);
  }

  /** Calls fn(inputs..., out) and returns its output parsed as JSON; failures throw. */
  function callJson(what, fn, fnName, inputs) {
    usable(what);
    return JSON.parse(textOf(callOut(fn, inputs), fnName));
  }

  /**
   * A study through fn(scene, options, progress, user, out) (mcp_study_run, mcp_render_study_run):
   * see runStudy below for the contract of onLevel. Returns the parsed result (also when
   * cancelled); failures throw McplayError, an exception of onLevel is rethrown.
   */
  function study(what, fn, fnName, scene, options, onLevel) {
    usable(what);
    if (active) {
      throw new McplayError(Status.ARGUMENT, `${what}: a study is already running on this core ` +
        '(called from inside onLevel?)');
    }
    if (onLevel !== null && onLevel !== undefined && typeof onLevel !== 'function') {
      throw new McplayError(Status.ARGUMENT, `${what}: onLevel must be a function or null`);
    }
    const sceneText = jsonText(scene, 'scene');
    const optionsText = optionalJson(options, 'options');
    const call = { onLevel, error: null };
    let r;
    active = onLevel ? call : null;
    try {
      r = callOut(fn, [sceneText, optionsText], [onLevel ? progressPtr : 0, 0]);
    } finally {
      active = null;
    }
    if (call.error) throw call.error.value;
    if ((r.status === Status.OK || r.status === Status.CANCELLED) && r.text !== null) {
      return JSON.parse(r.text);
    }
    throw new McplayError(r.status === Status.OK ? Status.INTERNAL : r.status,
      r.message || `${fnName}: no result`);
  }

  function version() {
    usable('version');
    return M.UTF8ToString(M._mcp_version());
  }

  /** Heap figures for leak checks: the wasm memory size and malloc's own accounting. */
  function heapStats() {
    usable('heapStats');
    const info = malloc(40); // struct mallinfo: ten 32-bit fields (wasm32)
    try {
      callC(M._mallinfo, info);
      const field = (i) => M.getValue(info + 4 * i, 'i32') >>> 0;
      return {
        memoryBytes: M.HEAPU8.length, // the wasm memory (grows, never shrinks)
        arenaBytes: field(0),         // obtained from the system by malloc (sbrk)
        allocatedBytes: field(7),     // in use, including this call's 40 bytes
        freeBytes: field(8),
      };
    } finally {
      M._free(info);
    }
  }

  /** Releases the progress trampoline; the core cannot be used afterwards. */
  function dispose() {
    if (disposed) return;
    if (active) throw new McplayError(Status.ARGUMENT, 'dispose: a study is running');
    disposed = true;
    M.removeFunction(progressPtr);
  }

  return {
    usable, callOut, textOf, jsonText, optionalJson, callJson, study, version, heapStats, dispose,
  };
}

/**
 * Instantiates an Emscripten module factory and checks that it exports `functions` and the
 * runtime methods; `what` names the function and target in the messages.
 */
export async function instantiate(factory, moduleOptions, functions, what, target) {
  if (typeof factory !== 'function') {
    throw new TypeError(`${what}: the first argument must be the default export of ${target}.mjs`);
  }
  const M = await factory(moduleOptions);
  const missing = [
    ...functions.filter((name) => typeof M[name] !== 'function'),
    ...WASM_RUNTIME_METHODS.filter((name) => M[name] === undefined),
  ];
  if (missing.length) {
    throw new Error(`${what}: the wasm module does not export ${missing.join(', ')} ` +
      `(stale build? rebuild target ${target})`);
  }
  return M;
}

function makeCore(M) {
  const b = wasmBridge(M);

  function catalog() {
    return b.callJson('catalog', M._mcp_catalog, 'mcp_catalog', []);
  }

  function sceneInfo(scene) {
    b.usable('sceneInfo');
    return b.callJson('sceneInfo', M._mcp_scene_info, 'mcp_scene_info', [b.jsonText(scene, 'scene')]);
  }

  /**
   * The points behind a small run of each estimator (replicate 0 of a study at N = n), for
   * scatter plots, f/p overlays and weight histograms: see mcp_study_samples in
   * src/api/mcplay.h. `options`: {estimators, n (<= 4096), seed, grid}. Throws McplayError.
   */
  function samples(scene, options = null) {
    b.usable('samples');
    return b.callJson('samples', M._mcp_study_samples, 'mcp_study_samples',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  // The sampler lab (src/api/mcplay.h, "The sampler lab"): JSON in, JSON out.

  /**
   * The points of one sampler: `request` {sampler ("uniform", "stratified", "latin_hypercube",
   * "sobol", "halton", "lattice"), n, dim, seed, randomization?} (mcp_points); returns
   * {sampler, randomization, n, dim, seed, points: [[x_1..x_dim] per point]}.
   */
  function points(request) {
    b.usable('points');
    return b.callJson('points', M._mcp_points, 'mcp_points', [b.jsonText(request, 'request')]);
  }

  /**
   * The analysis of point sets in [0,1)^d (mcp_points_analyze): `request` is one of
   * {points: rows or K sets of rows}, {csv: text} or {sampler: {..., sets}}, with spectrum
   * (false or {axes, size}) and pairwise (false skips the O(N^2 d) measures). Returns the
   * discrepancies, minimum distances, their independent-points expectation, the power spectrum
   * and its radial average, and `skipped` {measure: why}.
   */
  function analyzePoints(request) {
    b.usable('analyzePoints');
    return b.callJson('analyzePoints', M._mcp_points_analyze, 'mcp_points_analyze', [b.jsonText(request, 'request')]);
  }

  /**
   * Discrepancy against N for several samplers (mcp_discrepancy_curve): `request` {samplers,
   * dim, n_min, n_max (<= 65536), seed, reps, scene? (a problem with an exact value: its RMS
   * integration error with the same points)}. Returns {curves: [{sampler, n, l2_star_discrepancy,
   * wraparound_l2_discrepancy, rms_error?}], problem?, exact?, ...}.
   */
  function discrepancyCurve(request) {
    b.usable('discrepancyCurve');
    return b.callJson('discrepancyCurve', M._mcp_discrepancy_curve, 'mcp_discrepancy_curve',
      [b.jsonText(request, 'request')]);
  }

  /**
   * A scene's problem integrated with point sets given whole (mcp_points_integrate): `request`
   * as analyzePoints' points / csv / sampler. Returns {estimate, per_set, exact, error,
   * error_bar (null for one set: a deterministic rule, `note` says so), ...}.
   */
  function integratePoints(scene, request) {
    b.usable('integratePoints');
    return b.callJson('integratePoints', M._mcp_points_integrate, 'mcp_points_integrate',
      [b.jsonText(scene, 'scene'), b.jsonText(request, 'request')]);
  }

  /**
   * The chi-square test of a scene's warp (mcp_warp_test): `options` null or {samples, seed,
   * significance, tests, bins}. A failed test is a result ("passed": false); a warp that cannot
   * be tested (g leaves the domain, p negative or NaN) throws McplayError SCENE.
   */
  function warpTest(scene, options = null) {
    b.usable('warpTest');
    return b.callJson('warpTest', M._mcp_warp_test, 'mcp_warp_test',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * Runs a convergence study. `scene`: object or JSON text; `options`: object, JSON text or
   * null ({estimators, n_min, n_max, reps, seed, threads}); `onLevel(level)` (optional) is
   * called after each N with the progress object of docs/result-schema.md; returning exactly
   * `true` cancels the study, whose result then has `cancelled: true` (after the last N there
   * is nothing left to cancel: the result is complete and `cancelled` stays false). onLevel
   * must be synchronous (a returned promise is ignored). An exception thrown by onLevel
   * cancels the study and is rethrown from here. Failures throw McplayError.
   */
  function runStudy(scene, options = null, onLevel = null) {
    return b.study('runStudy', M._mcp_study_run, 'mcp_study_run', scene, options, onLevel);
  }

  /**
   * What a study would cost, without running it: validates scene and options exactly as
   * runStudy does (the same McplayError for the same fault, including the size limit of 2^40
   * evaluations) and returns {evaluations, limit_evaluations, predicted_seconds, threads,
   * levels, n_min, n_max, reps, pilot_samples, pilot_seconds, estimators: [{name, evaluations,
   * seconds_per_evaluation, predicted_seconds}]} from a pilot of a few ms (mcp_study_plan).
   */
  function plan(scene, options = null) {
    b.usable('plan');
    return b.callJson('plan', M._mcp_study_plan, 'mcp_study_plan',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * A study result (object or JSON text) as 'table', 'csv' or 'json' (pretty-printed) text.
   * A result of the wrong shape (estimators or their levels not lists of objects) throws a
   * McplayError ARGUMENT naming the field, e.g. "result.estimators: expected an array, got number".
   */
  function format(result, fmt = 'table') {
    b.usable('format');
    if (typeof fmt !== 'string' || fmt.includes('\0')) {
      throw new McplayError(Status.ARGUMENT, `format: expected one of ${FORMATS.join(', ')}`);
    }
    return b.textOf(b.callOut(M._mcp_result_format, [b.jsonText(result, 'result'), fmt]), 'mcp_result_format');
  }

  return Object.freeze({
    version: b.version, catalog, sceneInfo, samples, plan, runStudy, format,
    points, analyzePoints, discrepancyCurve, integratePoints, warpTest,
    heapStats: b.heapStats, dispose: b.dispose,
  });
}
