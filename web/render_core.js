// The only module that talks to the render wasm module (build-wasm/mcplay_render_web.mjs, the
// C API of src/render_api/mcplay_render.h). Same style and conventions as core.js, whose
// calling machinery it shares: plain ES module, no DOM, no Node APIs; it runs in a page, in a
// (module) Web Worker and in Node. The playground's worker imports it (and the render module)
// only when a render scene is asked for, so the integration page never downloads the renderer.
//
//   import createMcplayRender from './mcplay_render_web.mjs';
//   const render = await loadRenderCore(createMcplayRender);   // Node: (..., {wasmBinary})
//   const result = render.runStudy(scene, {spp_max: 16, previews: true}, (level) => draw(level));
//
// The scene is the whole render scene JSON with its "gltf" given inline as the glTF object
// (the module has no file system access to the site). Every call is synchronous once the core
// is loaded: run studies in a Worker.
import { McplayError, Status, WASM_RUNTIME_METHODS, instantiate, wasmBridge } from './core.js';

export { McplayError, Status };

/** The module's exported functions this wrapper needs: exactly
 *  src/wasm/render_exported_functions.txt (web/test/render_core.test.mjs checks it). */
export const RENDER_WASM_FUNCTIONS = Object.freeze([
  '_malloc', '_free',
  '_mcp_version', '_mcp_last_error', '_mcp_render_study_run', '_mcp_render_study_plan', '_mcp_render_image',
  '_mcp_render_scene_info', '_mcp_render_study_merge', '_mcp_render_pixel_points', '_mcp_render_reference',
  '_mcp_render_live_open', '_mcp_render_live_pass', '_mcp_render_live_reference', '_mcp_render_live_close', '_mcp_free',
  '_mallinfo',
]);

/** The Emscripten runtime helpers used (the same list as core.js). */
export const RENDER_WASM_RUNTIME_METHODS = WASM_RUNTIME_METHODS;

/**
 * Instantiates the render wasm module and returns the render core.
 * @param {Function} createMcplayRender the default export of mcplay_render_web.mjs
 * @param {object} moduleOptions Emscripten module options, e.g. {wasmBinary} in Node
 */
export async function loadRenderCore(createMcplayRender, moduleOptions = {}) {
  const M = await instantiate(createMcplayRender, moduleOptions, RENDER_WASM_FUNCTIONS,
    'loadRenderCore', 'mcplay_render_web');
  return makeRenderCore(M);
}

function makeRenderCore(M) {
  const b = wasmBridge(M);

  /**
   * What a render scene holds (mcp_render_scene_info): name, description, kind "render",
   * width, height, triangles, lights, materials, accel, warnings, estimators (objects with
   * name, strategy, light_selection, ...), settings {n_min, n_max, reps, seed, n_name,
   * error_name, ...} and the reference. `options` (optional) overrides the scene's settings.
   */
  function sceneInfo(scene, options = null) {
    b.usable('sceneInfo');
    return b.callJson('sceneInfo', M._mcp_render_scene_info, 'mcp_render_scene_info',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * What a study would cost before it starts (mcp_render_study_plan): {samples,
   * predicted_seconds, threads, levels, reps, reference: {source, spp, ...}, estimators:
   * [{name, samples, seconds_per_sample, predicted_seconds}]} from a pilot of one small image
   * per estimator. Same errors as runStudy.
   */
  function plan(scene, options = null) {
    b.usable('plan');
    return b.callJson('plan', M._mcp_render_study_plan, 'mcp_render_study_plan',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * A render convergence study (mcp_render_study_run): every estimator at spp = spp_min ..
   * spp_max (powers of two), reps images each, measured by relative MSE against the
   * reference. `options`: {estimators, spp_min, spp_max, reps, seed, width, height, previews,
   * ...} or null. onLevel(progress) gets {kind: "render", level_index, n, estimators: [{...,
   * level, fit, preview_png?, error_png?}]} after each spp; returning exactly `true` cancels
   * (the result then has cancelled: true). An exception thrown by onLevel cancels the study
   * and is rethrown. onReference(progress), when given, gets {kind: "render_reference",
   * rows_done, rows} while the study renders its reference (at most one per percent; none when
   * options.reference_data or the cache gives it); returning exactly `true` cancels too.
   * Failures throw McplayError.
   */
  function runStudy(scene, options = null, onLevel = null, onReference = null) {
    if (onReference !== null && typeof onReference !== 'function') {
      throw new McplayError(Status.ARGUMENT, 'runStudy: onReference must be a function or null');
    }
    const route = onReference === null ? onLevel
      : (p) => (p && p.kind === 'render_reference' ? onReference(p) : typeof onLevel === 'function' ? onLevel(p) : undefined);
    const levelsOnly = typeof onLevel === 'function'
      ? (p) => (p && p.kind === 'render_reference' ? undefined : onLevel(p)) : onLevel;
    return b.study('runStudy', M._mcp_render_study_run, 'mcp_render_study_run', scene, options,
      onReference === null ? levelsOnly : route);
  }

  /**
   * One image (mcp_render_image): options {estimator, spp, outputs: ["png", "hdr",
   * "error_png"], width, height, seed, ...}. Returns {kind: "render_image", images: {png:
   * base64, ...}, diagnostics, seconds, rays_per_second, warnings, ...}.
   */
  function renderImage(scene, options = null) {
    b.usable('renderImage');
    return b.callJson('renderImage', M._mcp_render_image, 'mcp_render_image',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * The parts of a study split over workers by replicate (mcp_render_study_merge): each part
   * is runStudy's result with options {part: i, parts: K} (its levels carry their images);
   * the merge is the whole study's result, levels, fit and warnings as one worker would give
   * them. Parts cut short merge over the levels every part finished. Failures throw McplayError.
   */
  function mergeParts(parts) {
    b.usable('mergeParts');
    return b.callJson('mergeParts', M._mcp_render_study_merge, 'mcp_render_study_merge',
      [b.jsonText({ parts }, 'parts')]);
  }

  /**
   * The points one pixel's samples take from a render pixel sampler (mcp_render_pixel_points):
   * {pixel_sampler, spp, dim, seed, width, height, pixel} to {n, dim, points: rows, ...}, rows as
   * the integration core's analyzePoints takes them. Failures throw McplayError.
   */
  function pixelPoints(request) {
    b.usable('pixelPoints');
    return b.callJson('pixelPoints', M._mcp_render_pixel_points, 'mcp_render_pixel_points',
      [b.jsonText(request, 'request')]);
  }

  /**
   * The study's reference image alone (mcp_render_reference): options as runStudy's (width,
   * height, reference_data, ...). onProgress({kind: "render_reference", rows_done, rows}), when
   * given, hears the rows while it renders; returning exactly `true` cancels (McplayError
   * CANCELLED). Returns {kind: "render_reference", spp, width, height, reference_data, ...}.
   */
  function reference(scene, options = null, onProgress = null) {
    const r = b.study('reference', M._mcp_render_reference, 'mcp_render_reference', scene, options, onProgress);
    if (!r || r.kind !== 'render_reference') throw new McplayError(Status.CANCELLED, 'reference: cancelled');
    return r;
  }

  // A call whose first argument is a session id: (session, inputs..., extra..., out).
  function sessionCall(what, fn, fnName, session, inputs, extra = []) {
    b.usable(what);
    if (!Number.isInteger(session) || session <= 0) {
      throw new McplayError(Status.ARGUMENT, `${what}: session must be an integer > 0, got ${session}`);
    }
    const r = b.callOut((...args) => fn(session, ...args), inputs, extra);
    return JSON.parse(b.textOf(r, fnName));
  }

  /**
   * Opens a live session (mcp_render_live_open): one scene, 1 to 4 estimators, the rows
   * options.rows = [begin, end] of an image of options.long_side (or width x height) pixels;
   * options {estimators, pixel_sampler: "padded_sobol" | "independent", long_side, rows,
   * live_reference: "available" | "obtain", reference_data, pixels, seed, threads}. Returns
   * {kind: "render_live", session, width, height, rows, estimators, reference: null or
   * {source, spp, mean_luminance, relative_mse_floor, rgb_f32?}, warnings}. Throws McplayError.
   */
  function liveOpen(scene, options = null) {
    b.usable('liveOpen');
    return b.callJson('liveOpen', (...a) => M._mcp_render_live_open(a[0], a[1], 0, 0, a[2]), 'mcp_render_live_open',
      [b.jsonText(scene, 'scene'), b.optionalJson(options, 'options')]);
  }

  /**
   * One pass of a session (mcp_render_live_pass): pass {estimator: index, spp: the band's new
   * total, pixels: bool}. Returns {estimator, spp, seconds (the band's, all its passes),
   * pass_seconds, samples, error: null | {sum, sum_raw, terms}, rgb_f32?, ...}.
   */
  function livePass(session, pass) {
    return sessionCall('livePass', M._mcp_render_live_pass, 'mcp_render_live_pass', session,
      [b.jsonText(pass, 'pass')], [0, 0]);
  }

  /** Gives a session its reference (mcp_render_live_reference): {reference_data} made at the
   *  session's image size. Returns the session's reference block (as liveOpen's "reference"). */
  function liveReference(session, reference) {
    return sessionCall('liveReference', M._mcp_render_live_reference, 'mcp_render_live_reference', session,
      [b.jsonText(reference, 'reference')]);
  }

  /** Frees a session (mcp_render_live_close); unknown ids throw. */
  function liveClose(session) {
    b.usable('liveClose');
    const status = M._mcp_render_live_close(session);
    if (status !== Status.OK) throw new McplayError(status, M.UTF8ToString(M._mcp_last_error()) || `liveClose: status ${status}`);
  }

  return Object.freeze({
    version: b.version, sceneInfo, plan, runStudy, renderImage, mergeParts, pixelPoints,
    reference, liveOpen, livePass, liveReference, liveClose, heapStats: b.heapStats, dispose: b.dispose,
  });
}
