// Messages between the page and web/src/worker.js, in one place. Every message is
// {id, type, payload}: `id` names the request a reply belongs to (the worker echoes it), `type`
// is one of MSG, `payload` is plain structured-cloneable data.
//
//   page -> worker                          worker -> page
//   load     {}                             ready     {version}
//   validate {scene}                        validated {info}          (core.sceneInfo)
//   run      {scene, options, warmup?}      level     {level}  x N    (after each N)
//                                           result    {result}        (core.runStudy)
//   format   {result, format}               formatted {text}          (core.format)
//   samples  {scene, options, fields?}      sampled   {samples}       (core.samples; `fields`
//                                                     keeps only those per-estimator arrays)
//   any request                             error     {status, statusName, message, field?, position?}
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
  ERROR: 'error',
});

/** The reply that ends each request type (an ERROR ends any of them). */
export const FINAL_REPLY = Object.freeze({
  [MSG.LOAD]: MSG.READY,
  [MSG.VALIDATE]: MSG.VALIDATED,
  [MSG.RUN]: MSG.RESULT,
  [MSG.FORMAT]: MSG.FORMATTED,
  [MSG.SAMPLES]: MSG.SAMPLED,
});

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
