// Messages between the page and web/src/worker.js, in one place. Every message is
// {id, type, payload}: `id` names the request a reply belongs to (the worker echoes it), `type`
// is one of MSG, `payload` is plain structured-cloneable data.
//
//   page -> worker                          worker -> page
//   load     {}                             ready     {version, isolated, clockStepMs}
//   validate {scene}                        validated {info}          (core.sceneInfo)
//   run      {scene, options, warmup?}      level     {level}  x N    (after each N)
//                                           result    {result}        (core.runStudy; with
//                                                     options.rel_tol / abs_tol a stopping
//                                                     result: no level replies before it)
//   image    {scene, options}               imaged    {image}         (render scenes only:
//                                                                      renderCore.renderImage)
//   merge    {parts}                        merged    {result}        (render studies split over
//                                                                      workers by replicate:
//                                                                      renderCore.mergeParts)
//   format   {result, format}               formatted {text}          (core.format)
//   samples  {scene, options, fields?}      sampled   {samples}       (core.samples; `fields`
//                                                     keeps only those per-estimator arrays)
//   points   {request}                      pointsDrawn {points}      (core.points)
//   pixelPoints {request}                   pixelPointsDrawn {points} (render core: pixelPoints,
//                                                     one pixel's samples of a renderer's sampler)
//   analyze  {request}                      analyzed  {analysis}      (core.analyzePoints)
//   curve    {request}                      curved    {curve}         (core.discrepancyCurve)
//   integratePoints {scene, request}        integrated {result}       (core.integratePoints)
//   warpTest {scene, options}               warpTested {result}       (core.warpTest)
//   reference {scene, options}              referenceRows {progress} x N, then
//                                           referenced {reference} (render core: reference,
//                                                     mcp_render_reference; the live view's
//                                                     reference at its size, in the background)
//   liveOpen {scene, options}               liveOpened {session}      (render core: liveOpen; the
//                                                     band's reference pixels as
//                                                     session.reference.rgb, a Float32Array)
//   livePass {session, pass}                livePassed {pass}         (render core: livePass; the
//                                                     band's pixels as pass.rgb, a Float32Array,
//                                                     transferred, not base64)
//   liveReference {session, reference}      liveReferenced {reference} (render core: liveReference)
//   liveClose {session}                     liveClosed {}             (render core: liveClose)
//   any request                             error     {status, statusName, message, field?, position?}
//
// A render scene (one with a "render" object: isRenderScene) goes to the render core
// (render_core.js + mcplay_render_web.wasm), which the worker imports on the first such request
// only; validate and run answer in the same shapes (info and result of the render C API).
//
// Cancelling a run is not a message: the page terminates the worker (a study is synchronous, so
// the worker reads no message until it ends) and starts a new one.

export const MSG = Object.freeze({
  LOAD: 'load',
  READY: 'ready',
  VALIDATE: 'validate',
  VALIDATED: 'validated',
  RUN: 'run',
  LEVEL: 'level',
  RESULT: 'result',
  FORMAT: 'format',
  FORMATTED: 'formatted',
  SAMPLES: 'samples',
  SAMPLED: 'sampled',
  IMAGE: 'image',
  IMAGED: 'imaged',
  MERGE: 'merge',
  MERGED: 'merged',
  POINTS: 'points',
  POINTS_DRAWN: 'pointsDrawn',
  PIXEL_POINTS: 'pixelPoints',
  PIXEL_POINTS_DRAWN: 'pixelPointsDrawn',
  ANALYZE: 'analyze',
  ANALYZED: 'analyzed',
  CURVE: 'curve',
  CURVED: 'curved',
  INTEGRATE_POINTS: 'integratePoints',
  INTEGRATED: 'integrated',
  WARP_TEST: 'warpTest',
  WARP_TESTED: 'warpTested',
  REFERENCE: 'reference',
  REFERENCE_ROWS: 'referenceRows',
  REFERENCED: 'referenced',
  LIVE_OPEN: 'liveOpen',
  LIVE_OPENED: 'liveOpened',
  LIVE_PASS: 'livePass',
  LIVE_PASSED: 'livePassed',
  LIVE_REFERENCE: 'liveReference',
  LIVE_REFERENCED: 'liveReferenced',
  LIVE_CLOSE: 'liveClose',
  LIVE_CLOSED: 'liveClosed',
  ERROR: 'error',
});

/** The reply that ends each request type (an ERROR ends any of them). */
export const FINAL_REPLY = Object.freeze({
  [MSG.LOAD]: MSG.READY,
  [MSG.VALIDATE]: MSG.VALIDATED,
  [MSG.RUN]: MSG.RESULT,
  [MSG.FORMAT]: MSG.FORMATTED,
  [MSG.SAMPLES]: MSG.SAMPLED,
  [MSG.IMAGE]: MSG.IMAGED,
  [MSG.MERGE]: MSG.MERGED,
  [MSG.POINTS]: MSG.POINTS_DRAWN,
  [MSG.PIXEL_POINTS]: MSG.PIXEL_POINTS_DRAWN,
  [MSG.ANALYZE]: MSG.ANALYZED,
  [MSG.CURVE]: MSG.CURVED,
  [MSG.INTEGRATE_POINTS]: MSG.INTEGRATED,
  [MSG.WARP_TEST]: MSG.WARP_TESTED,
  [MSG.REFERENCE]: MSG.REFERENCED,
  [MSG.LIVE_OPEN]: MSG.LIVE_OPENED,
  [MSG.LIVE_PASS]: MSG.LIVE_PASSED,
  [MSG.LIVE_REFERENCE]: MSG.LIVE_REFERENCED,
  [MSG.LIVE_CLOSE]: MSG.LIVE_CLOSED,
});

/** Little-endian float32 values from base64 (the render core's rgb_f32); an empty array for
 *  none. Runs in the worker, so the page gets a Float32Array it can take over (transfer). */
export function float32OfBase64(text) {
  if (typeof text !== 'string' || !text.length) return new Float32Array(0);
  const bin = atob(text);
  if (bin.length % 4) throw new Error(`rgb_f32: ${bin.length} bytes is not a whole number of float32 values`);
  const bytes = new Uint8Array(bin.length);
  for (let i = 0; i < bin.length; ++i) bytes[i] = bin.charCodeAt(i);
  // wasm and every browser are little-endian: the bytes are the Float32Array's own
  return new Float32Array(bytes.buffer);
}

/** True for a render scene (an object, or JSON text of one, with a "render" key), the test
 *  the C API applies (is_render_scene); anything else goes to the integration core. */
export function isRenderScene(scene) {
  let s = scene;
  if (typeof s === 'string') {
    if (!s.includes('"render"')) return false;
    try {
      s = JSON.parse(s);
    } catch {
      return false;
    }
  }
  return s !== null && typeof s === 'object' && !Array.isArray(s) && Object.prototype.hasOwnProperty.call(s, 'render');
}

export function message(id, type, payload = {}) {
  return { id, type, payload };
}

/**
 * An error as a message payload. McplayError's status and message are kept; a core message
 * of the form "scene.f: at position 7: ..." also gives the JSON path of the field and the
 * 1-based position in the expression, for marking it next to the input.
 */
export function errorPayload(e) {
  const text = e && typeof e.message === 'string' ? e.message : String(e);
  const payload = {
    status: e && typeof e.status === 'number' ? e.status : null,
    statusName: (e && e.statusName) || (e && e.name) || 'Error',
    message: text,
  };
  const m = /^([\w.[\]]+): at position (\d+): /.exec(text);
  if (m) {
    payload.field = m[1];
    payload.position = Number(m[2]);
  }
  return payload;
}
