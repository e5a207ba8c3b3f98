// The live view's pure parts (no DOM, no workers; web/test/live_model.test.mjs): the choices it
// offers, the options of a session, how an image is cut into row bands over the workers, the
// pass schedule (1, 2, 4, ... spp), merging the bands' passes into one estimator's level (pixels
// placed by rows, relative MSE = sum over bands of error.sum / sum of error.terms, seconds = sum
// of the bands' own seconds / workers), tone mapping and the relative-error colours (those of
// the core's error PNGs, src/render_api/image_io.cpp), the wipe's geometry, the prediction of
// the time to 64 spp, and the view's state (reducer).
import { atReferenceNoise, relativeMseText } from '../claims/reference_noise.js';

/** The long sides offered (pixels); the core computes the other side from the camera's aspect. */
export const LONG_SIDES = Object.freeze([128, 256, 512, 1024]);
export const DEFAULT_LONG_SIDE = 256;
/** At most this many estimators at once (the core's limit of a session). */
export const MAX_LIVE_ESTIMATORS = 4;
/** The samplers whose first n samples of a pixel do not depend on the final spp. */
export const LIVE_SAMPLERS = Object.freeze(['padded_sobol', 'independent']);
export const SAMPLER_WHY = 'padded_sobol: Owen-scrambled Sobol\' points per pixel, whose first n samples do not ' +
  'depend on the final spp, so each pass extends the image without restarting. Stratified strata and the ' +
  'image-wide sobol sampler are laid out for the final spp: their first samples change when it changes, so ' +
  'they cannot extend. independent: plain random samples (extend too, converge more slowly).';
/** The last spp offered (passes stop there unless paused or cancelled first). */
export const MAX_SPP_CHOICES = Object.freeze([64, 256, 1024, 4096, 16384]);
export const DEFAULT_MAX_SPP = 4096;
/** Workers of the view's own pool: at most this many (the core renders one thread per worker). */
export const MAX_LIVE_WORKERS = 4;
/** Bands per worker (band i goes to worker i mod K, so several a worker interleave). One: two
 *  interleaved bands a worker (to share out an expensive region of the image) made 64 spp 7-9%
 *  slower on veach_mis, near_mirror and cornell_box (2 workers, 2026-12-04): each session reads
 *  the shipped reference again, and each pass is one more call. */
export const BANDS_PER_WORKER = 1;
/** Predicted times to 64 spp above this (seconds) pause the view after the first passes (every
 *  prediction is said; a lecture can wait 20 s, not several minutes unannounced). */
export const LONG_SECONDS = 60;

/** The workers of the pool: hardwareConcurrency, at most MAX_LIVE_WORKERS, at least 1. */
export function liveWorkers(cores, override = null) {
  const n = Number.isInteger(override) && override > 0 ? override : cores;
  return Math.max(1, Math.min(MAX_LIVE_WORKERS, Number.isFinite(n) ? Math.floor(n) : 1));
}

/**
 * The estimators chosen by default, from the scene's list (names, or the scene info's estimator
 * objects {name, strategy, light_selection, light_sampling}): at most four, in the scene's order.
 * When the scene has MIS estimators (strategy mis_*), they come first, then the strategies they
 * combine [Veach97, 9.2]: BSDF sampling and the light sampling of their kind (light_sampling,
 * light_selection), then other light sampling, then the rest; otherwise the scene's first four.
 */
export function defaultEstimators(list) {
  const all = (Array.isArray(list) ? list : []).map((e) => (typeof e === 'string' ? { name: e } : e))
    .filter((e) => e && typeof e.name === 'string');
  const mis = all.filter((e) => /^mis_/.test(e.strategy || ''));
  const combined = (e) => e.strategy === 'bsdf' || mis.some((m) => e.strategy === `light_${m.light_sampling}` &&
    (e.light_selection || 'power') === (m.light_selection || 'power'));
  const rank = (e) => {
    if (!mis.length || mis.includes(e)) return 0;
    if (combined(e)) return 1;
    return /^light_/.test(e.strategy || '') ? 2 : 3;
  };
  const chosen = new Set(all.map((e, i) => [rank(e), i, e.name]).sort((a, b) => a[0] - b[0] || a[1] - b[1])
    .slice(0, MAX_LIVE_ESTIMATORS).map((x) => x[2]));
  return all.map((e) => e.name).filter((n) => chosen.has(n));
}

/**
 * The rows [begin, end) of `bands` bands over an image `height` rows high: every row in exactly
 * one band, in order, sizes differing by at most one row, no empty band (fewer bands than asked
 * when the image has fewer rows).
 */
export function splitRows(height, bands) {
  const h = Math.max(0, Math.floor(height));
  const k = Math.max(1, Math.min(h || 1, Math.floor(bands) || 1));
  const out = [];
  let row = 0;
  for (let i = 0; i < k; ++i) {
    const size = Math.floor(h / k) + (i < h % k ? 1 : 0);
    out.push([row, row + size]);
    row += size;
  }
  return h ? out : [];
}

/** Which worker renders band i of `bands`: interleaved, i mod workers. */
export function workerOfBand(i, workers) {
  return i % Math.max(1, workers);
}

/** The spp after `spp` in the schedule 1, 2, 4, ...: each pass doubles it. */
export function nextSpp(spp) {
  return spp >= 1 ? spp * 2 : 1;
}

/** The options of one band's session (mcp_render_live_open). */
export function sessionOptions({ estimators, sampler, longSide, rows, referenceData = null, seed = null }) {
  const o = {
    estimators: estimators.slice(), pixel_sampler: sampler, long_side: longSide, rows: rows.slice(),
    live_reference: 'available', pixels: true, threads: 1,
  };
  if (referenceData) o.reference_data = referenceData;
  if (Number.isInteger(seed)) o.seed = seed;
  return o;
}

/**
 * Collects the bands' passes of a live image into levels. `bands`: [[begin, end), ...]; width:
 * the image's. add(estimator, band, pass) places the band's pixels (pass.rgb, float32 RGB of
 * its rows) in the level's image and returns the level once every band has reached pass.spp:
 * {estimator, spp, rgb (the whole image), relmse (null without a reference in every band),
 * seconds (sum of the bands' seconds / workers), complete: true}; else null.
 */
export function createCollector({ width, height, bands, workers }) {
  const pending = new Map(); // `${estimator}:${spp}` -> level in progress
  function add(estimator, band, pass) {
    const key = `${estimator}:${pass.spp}`;
    let level = pending.get(key);
    if (!level) {
      level = { estimator, spp: pass.spp, rgb: new Float32Array(width * height * 3), seen: new Set(), sum: 0, terms: 0,
        errors: 0, seconds: [], passSeconds: 0 };
      pending.set(key, level);
    }
    if (level.seen.has(band)) throw new Error(`band ${band} sent ${pass.spp} spp of estimator ${estimator} twice`);
    const [b, e] = bands[band];
    const want = (e - b) * width * 3;
    if (pass.rgb && pass.rgb.length !== want) {
      throw new Error(`band ${band} (rows ${b}..${e}): ${pass.rgb.length} values, expected ${want}`);
    }
    if (pass.rgb) level.rgb.set(pass.rgb, b * width * 3);
    level.seen.add(band);
    if (pass.error) {
      level.sum += pass.error.sum;
      level.terms += pass.error.terms;
      level.errors += 1;
    }
    level.seconds.push(pass.seconds || 0);
    level.passSeconds += pass.pass_seconds || 0;
    if (level.seen.size < bands.length) return null;
    pending.delete(key);
    return {
      estimator, spp: level.spp, rgb: level.rgb, complete: true,
      relmse: level.errors === bands.length ? relativeMse([{ sum: level.sum, terms: level.terms }]) : null,
      seconds: estimatorSeconds(level.seconds, workers),
      passSeconds: level.passSeconds / Math.max(1, workers),
    };
  }
  return { add, pendingLevels: () => pending.size };
}

/** The relative MSE of an image from its bands' error sums: sum of sum / sum of terms (null
 *  when any band has none or there are no terms). */
export function relativeMse(errors) {
  let sum = 0;
  let terms = 0;
  for (const e of errors) {
    if (!e || !Number.isFinite(e.sum) || !Number.isFinite(e.terms)) return null;
    sum += e.sum;
    terms += e.terms;
  }
  return terms > 0 ? sum / terms : null;
}

/** An estimator's seconds: its bands' own rendering seconds (one thread each) summed, over the workers. */
export function estimatorSeconds(bandSeconds, workers) {
  return bandSeconds.reduce((a, b) => a + b, 0) / Math.max(1, workers);
}

// ---------------------------------------------------------------------------------------------
// Pixels

/** The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1]. */
export function srgbEncode(x) {
  const v = Math.min(1, Math.max(0, x));
  return v <= 0.0031308 ? 12.92 * v : 1.055 * v ** (1 / 2.4) - 0.055;
}

// 4096 entries over [0, 1] of linear light: sRGB bytes, as the core's PNGs round them.
const SRGB_TABLE = (() => {
  const t = new Uint8Array(4097);
  for (let i = 0; i <= 4096; ++i) t[i] = Math.round(srgbEncode(i / 4096) * 255);
  return t;
})();

/** Linear RGB (float32, 3 a pixel) to RGBA bytes: times 2^exposure, clamped, sRGB; not a
 *  number is black (as the core's PNGs). `out` (Uint8ClampedArray of 4 a pixel) is filled. */
export function toneMap(rgb, out, exposure = 0) {
  const scale = 2 ** exposure;
  const n = Math.min(rgb.length / 3, out.length / 4);
  for (let p = 0; p < n; ++p) {
    for (let k = 0; k < 3; ++k) {
      const x = rgb[3 * p + k] * scale;
      out[4 * p + k] = x > 0 ? (x >= 1 ? 255 : SRGB_TABLE[Math.round(x * 4096)]) : 0;
    }
    out[4 * p + 3] = 255;
  }
  return out;
}

/** Luminance of linear Rec. 709 RGB (ITU-R BT.709), as the core's. */
export const luminance = (r, g, b) => 0.2126 * r + 0.7152 * g + 0.0722 * b;

const ERROR_STOPS = [[0.07, 0.02, 0.30], [0.17, 0.32, 0.55], [0.13, 0.57, 0.55], [0.37, 0.79, 0.38], [0.99, 0.91, 0.15]];

/** A pixel's relative error to a colour [r, g, b] bytes: log scale from 10^-3 (dark blue) to 1
 *  and above (yellow), magenta for not a number; the core's error PNG ramp. */
export function errorColor(rel) {
  if (!Number.isFinite(rel)) return [255, 0, 255];
  const t = Math.min(1, Math.max(0, (Math.log10(Math.max(rel, 1e-3)) + 3) / 3)) * 4;
  const i = Math.min(3, Math.floor(t));
  const f = t - i;
  return ERROR_STOPS[i].map((c, k) => Math.round(Math.min(1, Math.max(0, c * (1 - f) + ERROR_STOPS[i + 1][k] * f)) * 255));
}

/** The relative-error map of an image against the reference: per pixel |L - L_ref| / (|L_ref| +
 *  1% of the reference's mean luminance), coloured by errorColor, into RGBA `out`. */
export function errorMap(rgb, ref, out) {
  const n = Math.min(rgb.length, ref.length) / 3;
  let mean = 0;
  for (let p = 0; p < n; ++p) mean += luminance(ref[3 * p], ref[3 * p + 1], ref[3 * p + 2]);
  const eps = Math.max(1e-2 * (n ? mean / n : 0), 1e-300);
  for (let p = 0; p < n; ++p) {
    const l = luminance(rgb[3 * p], rgb[3 * p + 1], rgb[3 * p + 2]);
    const lr = luminance(ref[3 * p], ref[3 * p + 1], ref[3 * p + 2]);
    const [r, g, b] = errorColor(Math.abs(l - lr) / (Math.abs(lr) + eps));
    out[4 * p] = r;
    out[4 * p + 1] = g;
    out[4 * p + 2] = b;
    out[4 * p + 3] = 255;
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The wipe and the zoom

/** The wipe's position (0..100, % of the width from the left) from a pointer at clientX over a
 *  box [left, left + width): clamped. */
export function wipeFromPointer(clientX, left, width) {
  if (!(width > 0)) return 50;
  return Math.min(100, Math.max(0, ((clientX - left) / width) * 100));
}

/** The clip-path that shows the right-hand image from the wipe at `percent` on: the left part
 *  shows the image under it. */
export function wipeClip(percent) {
  const p = Math.min(100, Math.max(0, Number(percent) || 0));
  return `inset(0 0 0 ${+p.toFixed(2)}%)`;
}

/** The spp at which two images are compared: the largest both have (levels kept: sorted spp
 *  lists); the reference (null list) has every spp. Null when they share none. */
export function commonSpp(a, b) {
  if (a === null && b === null) return Infinity;
  if (a === null) return b.length ? b[b.length - 1] : null;
  if (b === null) return a.length ? a[a.length - 1] : null;
  const set = new Set(b);
  for (let i = a.length - 1; i >= 0; --i) if (set.has(a[i])) return a[i];
  return null;
}

export const ZOOMS = Object.freeze([1, 2, 3, 4, 6, 8, 12, 16]);

/** The zoom after one step in direction dir (+1 in, -1 out) from zoom z, within ZOOMS. */
export function zoomStep(z, dir) {
  const i = ZOOMS.indexOf(z);
  const at = i < 0 ? ZOOMS.findIndex((v) => v >= z) : i;
  return ZOOMS[Math.min(ZOOMS.length - 1, Math.max(0, (at < 0 ? ZOOMS.length - 1 : at) + (dir > 0 ? 1 : -1)))];
}

/** The whole factor images of w pixels are shown at by default: the largest that keeps
 *  `count` of them side by side within `box` pixels, at least 1. */
export function fitZoom(w, count, box) {
  return Math.max(1, Math.floor(box / Math.max(1, w * Math.max(1, count))));
}

// ---------------------------------------------------------------------------------------------
// Curves

/** Is a relative MSE (the reference's noise subtracted, as the core gives it) below what the
 *  reference can resolve: not positive, or below the floor (the reference's own relative MSE)?
 *  The study's rule (src/render/render_study.cpp, below_reference_noise; docs/render-scenes.md). */
export function belowReferenceNoise(relmse, floor) {
  return atReferenceNoise(relmse, { floor });
}

/** A positive number in `digits` significant digits, in scientific notation below 1e-3 or
 *  from 1e6 on: 0.0034, 2.8e-5. */
export function shortNumber(v, digits = 3) {
  const a = Math.abs(v);
  return a >= 1e-3 && a < 1e6 ? String(+v.toPrecision(digits)) : v.toExponential(digits - 1);
}

/** A relative MSE in words: its number, or, below the reference's noise, no number: "at the
 *  reference's noise (below <floor>)". Empty when there is none. */
export function relmseText(relmse, floor) {
  if (relmse === null || relmse === undefined || !Number.isFinite(relmse)) return '';
  return relativeMseText(relmse, { floor, digits: 3 });
}

/**
 * How many times lower relative MSE `a` is than `b`, as far as the reference can tell:
 * {factor, atLeast}. Both measured: b / a. `a` at the reference's noise and `b` measured: at
 * least b / floor (a is below the floor, by how much the reference cannot say). `b` at the
 * reference's noise: null (no ratio can be formed from it).
 */
export function relmseRatio(a, b, floor) {
  if (!Number.isFinite(a) || !Number.isFinite(b) || belowReferenceNoise(b, floor)) return null;
  if (!belowReferenceNoise(a, floor)) return { factor: b / a, atLeast: false };
  return Number.isFinite(floor) && floor > 0 ? { factor: b / floor, atLeast: true } : null;
}

/** A factor for people: 3.4, 28, 1200. */
const times = (f) => (f >= 10 ? String(Math.round(f)) : String(+f.toPrecision(2)));

/**
 * The live view's comparison: at the largest spp at which at least two of the chosen
 * estimators have a relative MSE, the lowest against the highest, a ratio only as far as the
 * reference tells (relmseRatio). '' when there is nothing to compare.
 */
export function compareText(order, estimators, floor) {
  const at = (n, spp) => {
    const p = (estimators[n] ? estimators[n].points : []).find((q) => q.spp === spp);
    return p && Number.isFinite(p.relmse) ? p.relmse : null;
  };
  const spps = [...new Set(order.flatMap((n) => (estimators[n] ? estimators[n].points : []).map((p) => p.spp)))]
    .sort((x, y) => y - x);
  const spp = spps.find((k) => order.filter((n) => at(n, k) !== null).length >= 2);
  if (spp === undefined) return '';
  const have = order.filter((n) => at(n, spp) !== null).sort((x, y) => at(x, spp) - at(y, spp));
  const best = have[0];
  const worst = have[have.length - 1];
  const r = relmseRatio(at(best, spp), at(worst, spp), floor);
  if (!r) return `At ${spp} spp every image is at the reference's noise: the reference cannot tell them apart.`;
  if (!r.atLeast) {
    return `At ${spp} spp ${best}'s relative MSE is ${times(r.factor)}× lower than ${worst}'s (one image each: the study ` +
      'gives error bars).';
  }
  return `At ${spp} spp ${best} is at the reference's noise: its relative MSE is at least ${times(r.factor)}× lower than ` +
    `${worst}'s; by how much more, the reference cannot tell.`;
}

/** The x values of every estimator's points (sorted, once each) and each estimator's y at
 *  them: its relative MSE where measured, null where it has no point or is at the reference's
 *  noise (belowReferenceNoise against `floor`), those x indices listed in `noise` (drawn on the
 *  floor, never as a number). The shape uPlot wants. Pure (web/test). */
export function alignPoints(order, estimators, key, floor = null) {
  const xs = [...new Set(order.flatMap((n) => (estimators[n] ? estimators[n].points : []).map((p) => p[key])))]
    .filter((x) => x > 0).sort((a, b) => a - b);
  const at = new Map(xs.map((x, i) => [x, i]));
  const noise = order.map(() => []);
  const ys = order.map((n, k) => {
    const y = new Array(xs.length).fill(null);
    for (const p of (estimators[n] ? estimators[n].points : [])) {
      if (!at.has(p[key]) || !Number.isFinite(p.relmse)) continue;
      if (belowReferenceNoise(p.relmse, floor)) noise[k].push(at.get(p[key]));
      else y[at.get(p[key])] = p.relmse;
    }
    return y;
  });
  return { xs, ys, noise };
}

// ---------------------------------------------------------------------------------------------
// Words

/** A duration for people: 850 ms, 12 s, 3 min 20 s. */
export function duration(seconds) {
  if (!Number.isFinite(seconds)) return '–';
  if (seconds < 1) return `${Math.max(1, Math.round(seconds * 1000))} ms`;
  if (seconds < 60) return `${seconds < 10 ? seconds.toFixed(1) : Math.round(seconds)} s`;
  const m = Math.floor(seconds / 60);
  const s = Math.round(seconds - 60 * m);
  return m >= 60 ? `${(seconds / 3600).toFixed(1)} h` : `${m} min${s ? ` ${s} s` : ''}`;
}

/** The spp after which the time to 64 spp is predicted: the passes to 1 and 2 spp also pay for
 *  compiling the wasm (V8 optimises a function after its first calls), so they overstate it. */
export const PREDICT_AT = 4;

/**
 * The wall time to reach `spp` predicted after the first passes: `elapsed` seconds brought every
 * estimator to `at` spp, and each further spp costs `perSpp` seconds of the workers' time (the
 * last pass's bands' pass seconds over the workers, per spp it added).
 */
export function predictSeconds(elapsed, perSpp, spp = 64, at = PREDICT_AT) {
  return elapsed + Math.max(0, spp - at) * perSpp;
}

/**
 * The line said after the first passes: how long 64 spp will take, from `at` spp (PREDICT_AT;
 * or 1, after the first pass, when that pass alone says the wait is long: a large image should
 * not wait for 4 spp to be told, and its first pass is mostly rendering, not compiling). `long`
 * (over LONG_SECONDS) pauses the view, unless `pause` is false (the view was paused once).
 */
export function predictionText(elapsed, perSpp, width, height, at = PREDICT_AT, pause = true) {
  const t = predictSeconds(elapsed, perSpp, 64, at);
  const long = t > LONG_SECONDS;
  return {
    long,
    pause: long && pause,
    seconds: t,
    text: `${width} × ${height} pixels: ${at} spp took ${duration(elapsed)}${at > 1 ? ` and each further spp takes about ${duration(perSpp)}` : ''}, ` +
      `so 64 spp will take about ${duration(t)}${long && pause ? '. Paused: press Resume to go on, or choose a smaller size.' : '.'}`,
  };
}

/** One line from an error of the core: its first line, without a trailing period duplicate. */
export function oneLine(message) {
  const text = String(message ?? '').split('\n').map((l) => l.trim()).find((l) => l) || 'failed';
  return text.length > 300 ? `${text.slice(0, 297)}…` : text;
}

// ---------------------------------------------------------------------------------------------
// State

export function initialLive() {
  return {
    id: 0,
    status: 'idle',          // idle | starting | running | paused | done | cancelled | error
    message: '',
    notice: '',
    choice: { estimators: null, sampler: 'padded_sobol', longSide: DEFAULT_LONG_SIDE, maxSpp: DEFAULT_MAX_SPP },
    view: { errors: false, zoom: 1, wipeA: null, wipeB: 'reference', wipe: 50 },
    size: null,              // {width, height} of the running view
    workers: 0,
    order: [],               // estimators of the running view
    colors: {},              // estimator -> colour index in its scene
    estimators: {},          // name -> {spp, seconds, points: [{spp, seconds, relmse}], levels: [spp]}
    reference: { status: 'none', progress: 0, source: null, spp: null }, // none | rendering | ready | error
    firstImageMs: null,
    startedAt: null,
    prediction: null,
  };
}

/** The view's reducer: actions live/<what>. */
export function liveReducer(state, action) {
  const p = action.payload || {};
  switch (action.type) {
    case 'live/choose':
      return { ...state, choice: { ...state.choice, ...p } };
    case 'live/view':
      return { ...state, view: { ...state.view, ...p } };
    case 'live/start': {
      const estimators = Object.fromEntries(p.order.map((n) => [n, { spp: 0, seconds: 0, points: [], levels: [] }]));
      return {
        ...state, id: p.id, status: 'starting', message: '', notice: '', size: null, workers: p.workers, order: p.order,
        colors: p.colors, estimators, reference: { status: 'none', progress: 0, source: null, spp: null },
        firstImageMs: null, startedAt: p.startedAt, prediction: null,
        view: { ...state.view, wipeA: p.order[0] ?? null, wipeB: p.order[1] ?? 'reference' },
      };
    }
    default:
  }
  if (p.id !== undefined && p.id !== state.id) return state; // an older view's message
  switch (action.type) {
    case 'live/opened':
      return { ...state, status: state.status === 'starting' ? 'running' : state.status, size: p.size };
    case 'live/level': {
      const e = state.estimators[p.estimator];
      if (!e) return state;
      const points = p.relmse !== null && p.relmse !== undefined ? [...e.points, { spp: p.spp, seconds: p.seconds, relmse: p.relmse }] : e.points;
      const first = state.firstImageMs === null ? p.now - state.startedAt : state.firstImageMs;
      return {
        ...state, firstImageMs: first,
        estimators: { ...state.estimators, [p.estimator]: { spp: p.spp, seconds: p.seconds, points, levels: [...e.levels, p.spp] } },
      };
    }
    case 'live/reference':
      return { ...state, reference: { ...state.reference, ...p.reference } };
    case 'live/prediction':
      return { ...state, prediction: p.prediction, status: p.prediction.pause && state.status === 'running' ? 'paused' : state.status,
        notice: p.prediction.text };
    case 'live/pause':
      return state.status === 'running' ? { ...state, status: 'paused' } : state;
    case 'live/resume':
      return state.status === 'paused' ? { ...state, status: 'running' } : state;
    case 'live/done':
      return state.status === 'running' || state.status === 'paused' ? { ...state, status: 'done' } : state;
    case 'live/cancel':
      return ['starting', 'running', 'paused'].includes(state.status) ? { ...state, status: 'cancelled' } : state;
    case 'live/error':
      return { ...state, status: 'error', message: oneLine(p.message) };
    default:
      return state;
  }
}

/** Is the view working (passes may still arrive)? */
export const liveActive = (s) => s.status === 'starting' || s.status === 'running' || s.status === 'paused';

/** What tests read: the state without functions, plus the sizes. */
export function liveSnapshot(s) {
  return JSON.parse(JSON.stringify(s));
}
