// Pure functions from the core's result / level JSON (docs/result-schema.md) to what the plots
// draw: aligned x/y arrays for uPlot (null where a series has no point), confidence bands,
// reference slopes, z-scores and their histogram, and the merge of the per-worker results.
// No DOM and no uPlot: web/test/series.test.mjs runs this under Node.

/** The core's N ladder: every power of two in [nMin, nMax]. */
export function ladder(nMin, nMax) {
  const out = [];
  if (!(nMin >= 1) || !(nMax >= nMin)) return out;
  for (let n = 1; n <= nMax; n *= 2) if (n >= nMin) out.push(n);
  return out;
}

/** v when it can sit on a log axis (a finite number > 0), else null. */
export function positive(v) {
  return typeof v === 'number' && Number.isFinite(v) && v > 0 ? v : null;
}

// ---------------------------------------------------------------------------------------------
// Streaming and merging

/**
 * Folds one progress object of the core's level callback ({level_index, n, estimators: [{name,
 * ...estimator fields, level, fit}]}) into `records` (name -> {name, ...estimator fields,
 * levels: [...]}, the shape of result.estimators[k]); returns a new object, `records` unchanged.
 */
export function applyLevel(records, progress) {
  const out = { ...records };
  for (const e of progress.estimators || []) {
    const { level, ...meta } = e;
    const prev = out[e.name];
    const levels = prev ? prev.levels.filter((l) => l.n !== level.n) : [];
    levels.push(level);
    levels.sort((a, b) => a.n - b.n);
    out[e.name] = { ...meta, levels };
  }
  return out;
}

/** Share of the run's work done: levels finished weighted by their N (the cost of a level). */
export function progressOf(records, order, nLadder) {
  const perEstimator = nLadder.reduce((s, n) => s + n, 0);
  if (!order.length || !perEstimator) return 0;
  const inLadder = new Set(nLadder);
  let done = 0;
  for (const name of order) {
    const r = records[name];
    if (r) for (const l of r.levels) if (inLadder.has(l.n)) done += l.n;
  }
  return Math.min(1, done / (perEstimator * order.length));
}

// What makes two results parts of one study. A render study's scene block carries the time its
// worker took to render the reference (each worker renders the same reference, from the same
// random stream): that is not part of the key.
function studyKey(r) {
  const s = r.settings || {};
  let scene = r.scene;
  if (r.kind === 'render' && scene && scene.reference) {
    const { seconds: _seconds, ...reference } = scene.reference;
    scene = { ...scene, reference };
  }
  return JSON.stringify([r.version, r.kind, scene, s.n_min, s.n_max, s.reps, s.seed, s.accumulator,
    s.width, s.height]);
}

/**
 * One result from the results of several workers, each run with options.estimators = a subset
 * (every estimator has its own random streams, so the split does not change any number; in a
 * render study every worker also renders the same reference, and the first part's scene block
 * and reference image are kept).
 * The estimators come in `order` (names; any others after them); settings.threads is the sum
 * of the workers' threads, wall_time_s the longest worker's (they ran side by side), and the
 * merge is cancelled if any part was. Throws if the parts are not of one study.
 */
export function mergeResults(partials, order = null) {
  if (!Array.isArray(partials) || !partials.length) throw new Error('mergeResults: no results to merge');
  const first = partials[0];
  const key = studyKey(first);
  const byName = new Map();
  for (const r of partials) {
    if (studyKey(r) !== key) {
      throw new Error('mergeResults: the parts are results of different studies (scene or settings differ)');
    }
    for (const e of r.estimators) {
      if (byName.has(e.name)) throw new Error(`mergeResults: estimator '${e.name}' is in two parts`);
      byName.set(e.name, e);
    }
  }
  const names = (order || []).filter((n) => byName.has(n));
  for (const n of byName.keys()) if (!names.includes(n)) names.push(n);
  return {
    ...first,
    cancelled: partials.some((r) => r.cancelled),
    settings: {
      ...first.settings,
      threads: partials.reduce((s, r) => s + ((r.settings && r.settings.threads) || 1), 0),
    },
    wall_time_s: Math.max(...partials.map((r) => r.wall_time_s || 0)),
    estimators: names.map((n) => byName.get(n)),
  };
}

// ---------------------------------------------------------------------------------------------
// Variance (or MSE) against N

function unionSorted(values) {
  return [...new Set(values)].sort((a, b) => a - b);
}

/**
 * The variance plot: x = every N any estimator has reached; per estimator y = its MSE when
 * the exact value is known (`exact` not null), else its variance, and the band lo/hi = the
 * core's variance_ci95 (chi-square interval of the variance). For the MSE the band is the same
 * interval scaled by mse / variance: the same relative uncertainty, centred on the plotted
 * value. Values that cannot sit on a log axis (0, null) are null. `xs` (optional) fixes the x
 * values, e.g. the whole N ladder of a run that is still going.
 */
// Each series also has exactAt (per x: that level is exact to round-off, so y is null there) and
// exact (every level so far is).
export function varianceSeries(records, order, exact = null, xs = null) {
  const useMse = exact !== null && exact !== undefined && Number.isFinite(exact);
  const named = order.filter((n) => records[n]);
  const x = xs ? xs.slice() : unionSorted(named.flatMap((n) => records[n].levels.map((l) => l.n)));
  const series = named.map((name) => {
    const byN = new Map(records[name].levels.map((l) => [l.n, l]));
    const y = [];
    const lo = [];
    const hi = [];
    const exactAt = [];
    for (const n of x) {
      const l = byN.get(n);
      exactAt.push(Boolean(l && l.exact_to_roundoff === true));
      if (!l || l.exact_to_roundoff === true) {
        // an exact level (variance zero up to round-off) has no point on a log axis: the plot
        // marks it apart
        y.push(null); lo.push(null); hi.push(null);
        continue;
      }
      const variance = l.variance;
      const v = useMse && l.mse !== null && l.mse !== undefined ? l.mse : variance;
      y.push(positive(v));
      const ci = l.variance_ci95;
      const scale = v === variance ? 1 : (positive(variance) ? v / variance : NaN);
      lo.push(ci ? positive(ci[0] * scale) : null);
      hi.push(ci ? positive(ci[1] * scale) : null);
    }
    const levels = records[name].levels;
    const exact = levels.length > 0 && levels.every((l) => l.exact_to_roundoff === true);
    return { name, y, lo, hi, exactAt, exact, fit: records[name].fit || null };
  });
  return { quantity: useMse ? 'mse' : 'variance', x, series };
}

/** Where reference slopes start: the smallest N with a point, at the largest y there. */
export function anchorOf(x, series) {
  for (let i = 0; i < x.length; i++) {
    let y = null;
    for (const s of series) if (s.y[i] !== null && (y === null || s.y[i] > y)) y = s.y[i];
    if (y !== null) return { x: x[i], y };
  }
  return null;
}

/** Lines y = anchor.y (x / anchor.x)^-k for k in `orders` (N^-1, N^-2, N^-3 by default). */
export function referenceLines(x, anchor, orders = [1, 2, 3]) {
  if (!anchor) return [];
  return orders.map((k) => ({
    order: -k,
    label: `N^-${k}`,
    y: x.map((v) => anchor.y * (v / anchor.x) ** -k),
  }));
}

/**
 * Least-squares slope of log y on log x over the pairs where both are > 0 and finite:
 * {slope, intercept (of ln y at ln x = 0), n}, or null with fewer than two distinct x.
 * (The fitted order in the legend is the core's fit.order; this is for the plots' own lines.)
 */
export function fitSlope(xs, ys) {
  const px = [];
  const py = [];
  for (let i = 0; i < Math.min(xs.length, ys.length); i++) {
    if (positive(xs[i]) !== null && positive(ys[i]) !== null) {
      px.push(Math.log(xs[i]));
      py.push(Math.log(ys[i]));
    }
  }
  const n = px.length;
  if (n < 2) return null;
  const mx = px.reduce((s, v) => s + v, 0) / n;
  const my = py.reduce((s, v) => s + v, 0) / n;
  let sxx = 0;
  let sxy = 0;
  for (let i = 0; i < n; i++) {
    sxx += (px[i] - mx) ** 2;
    sxy += (px[i] - mx) * (py[i] - my);
  }
  if (!(sxx > 0)) return null;
  const slope = sxy / sxx;
  return { slope, intercept: my - slope * mx, n };
}

// ---------------------------------------------------------------------------------------------
// Error against time

/** The seconds per estimate a level is plotted at: the replicates' median (robust to the one
 *  that a busy machine delayed), or their mean when the level has no median. */
export function timeOf(l) {
  return positive(l.time_median_s) !== null ? l.time_median_s : l.time_mean_s;
}

/** The 95% interval of timeOf(l): the median's order-statistic interval, else the mean's t-free
 *  normal interval from time_std_s; null when neither is known. */
export function timeInterval(l) {
  const ci = l.time_median_ci95_s;
  if (Array.isArray(ci) && positive(ci[0]) !== null && positive(ci[1]) !== null) return [ci[0], ci[1]];
  if (positive(l.time_std_s) !== null && (l.reps || 0) > 1 && positive(l.time_mean_s) !== null) {
    const h = 1.959963984540054 * l.time_std_s / Math.sqrt(l.reps);
    return [Math.max(l.time_mean_s - h, l.time_mean_s * 1e-3), l.time_mean_s + h];
  }
  return null;
}

/**
 * The finest step of a clock (ms): the smallest positive difference between successive readings
 * of `now`, watched for at most `budgetMs` (or `maxReadings` readings). Browsers coarsen performance.now() (to 5 us, or
 * 100 us without cross-origin isolation), and the wasm core's timings are taken with it.
 */
export function clockResolution(now, budgetMs = 5, maxReadings = 1e6) {
  const start = now();
  let last = start;
  let step = Infinity;
  let seen = 0;
  for (let k = 0; seen < 20 && k < maxReadings; ++k) {
    const t = now();
    if (t > last) {
      step = Math.min(step, t - last);
      last = t;
      ++seen;
    }
    if (t - start > budgetMs) break;
  }
  return Number.isFinite(step) ? step : null;
}

/** Times under this many clock steps are not fitted: the clock's rounding is over 5% of them. */
export const CLOCK_STEPS_FITTED = 20;

/**
 * The equal-time plot: per estimator the points (timeOf, error) of its levels (error =
 * RMSE when the exact value is known, else sqrt(variance)), on the sorted union of all times
 * (uPlot's aligned data; null where a series has no point), the points in the order of N
 * (`points`: [time, error] pairs, for joining them), and the least-squares slope of log error on
 * log time over the points at t >= clockFloor (`fitted` of them; `untimed` below it, where the
 * clock's rounding bends the line). Adaptive estimators also get `estimating` (the [time minus training time, error]
 * pairs) and `trainingShare` (the mean share of the time spent training or probing; null for
 * the others).
 */
export function timeSeries(records, order, clockFloor = 0) {
  const named = order.filter((n) => records[n]);
  const pts = named.map((name) => records[name].levels
    .map((l) => [positive(timeOf(l)), positive(l.error)])
    .filter(([t, e]) => t !== null && e !== null));
  const x = unionSorted(pts.flat().map(([t]) => t));
  const index = new Map(x.map((t, i) => [t, i]));
  const series = named.map((name, k) => {
    const y = new Array(x.length).fill(null);
    for (const [t, e] of pts[k]) y[index.get(t)] = e;
    // The slope over the points the clock can time (t >= clockFloor): below, its rounding
    // would bend the line.
    const timed = pts[k].filter(([t]) => t >= clockFloor);
    const fit = fitSlope(timed.map((p) => p[0]), timed.map((p) => p[1]));
    // Adaptive estimators: the same errors at the time spent estimating only (training or
    // probing left out), and the mean share of the time that training took.
    const levels = records[name].levels.filter((l) => positive(timeOf(l)) !== null && positive(l.error) !== null);
    const trained = levels.filter((l) => l.training_time_mean_s > 0 && l.training_time_mean_s < l.time_mean_s);
    const estimating = trained.map((l) => [timeOf(l) * (1 - l.training_time_mean_s / l.time_mean_s), l.error]);
    const trainingShare = trained.length
      ? trained.reduce((a, l) => a + l.training_time_mean_s / l.time_mean_s, 0) / trained.length : null;
    // The timing's own uncertainty: the 95% interval of the median seconds over the replicates.
    const whiskers = levels.map((l) => timeInterval(l)).map((ci, i) => (ci ? [ci[0], ci[1], levels[i].error] : null))
      .filter(Boolean);
    return { name, y, points: pts[k], slope: fit ? fit.slope : null, fitted: timed.length,
      untimed: pts[k].length - timed.length, estimating, trainingShare, whiskers };
  });
  return { x, series };
}

/**
 * Who wins at equal time: the efficiency 1 / (error² × seconds) of each estimator at the
 * largest N it reached (the MSE when the exact value is known, else the variance; the median
 * seconds), with its uncertainty in log space from the error's chi-square interval
 * (variance_ci95) and the timing's (timeInterval). The most efficient is named only when a
 * z test on the log efficiencies separates it from the next (|z| > 1.96); an estimator exact to
 * round-off wins at any time. Returns {text, ranked: [{name, efficiency, lo, hi, n}], winner}.
 */
export function equalTimeVerdict(records, order, exact = null) {
  const useMse = exact !== null && exact !== undefined && Number.isFinite(exact);
  const rows = [];
  const exactOnes = [];
  for (const name of order) {
    const r = records[name];
    const l = r && r.levels.length ? r.levels[r.levels.length - 1] : null;
    if (!l) continue;
    if (l.exact_to_roundoff === true) {
      exactOnes.push(name);
      continue;
    }
    const v = l.variance;
    const q = useMse && positive(l.mse) !== null ? l.mse : v;
    const t = timeOf(l);
    if (positive(q) === null || positive(t) === null) continue;
    const ci = l.variance_ci95;
    const seLogQ = ci && positive(ci[0]) !== null && positive(ci[1]) !== null
      ? (Math.log(ci[1]) - Math.log(ci[0])) / (2 * 1.959963984540054) : null;
    const tci = timeInterval(l);
    const seLogT = tci ? (Math.log(tci[1]) - Math.log(tci[0])) / (2 * 1.959963984540054) : 0;
    const logE = -Math.log(q) - Math.log(t);
    const se = seLogQ === null ? null : Math.sqrt(seLogQ * seLogQ + seLogT * seLogT);
    rows.push({ name, n: l.n, efficiency: Math.exp(logE), logE, se,
      lo: se === null ? null : Math.exp(logE - 1.96 * se), hi: se === null ? null : Math.exp(logE + 1.96 * se) });
  }
  rows.sort((a, b) => b.logE - a.logE);
  const what = useMse ? 'MSE' : 'variance';
  if (exactOnes.length) {
    return { winner: exactOnes[0], ranked: rows, text: `${exactOnes.join(' and ')} ${exactOnes.length > 1 ? 'are' : 'is'} exact (zero ${what} to round-off): nothing beats that at any time.` };
  }
  if (rows.length < 2) return { winner: rows.length ? rows[0].name : null, ranked: rows, text: '' };
  const [a, b] = rows;
  const lead = `at the largest N each reached (1 / (${what} × seconds); it grows with N for estimators steeper than N⁻¹)`;
  if (a.se === null || b.se === null) {
    return { winner: null, ranked: rows, text: `Most efficient ${lead}: ${a.name}, ${fmt(a.efficiency / b.efficiency, 2)}× ${b.name}; no uncertainty to test it.` };
  }
  const z = (a.logE - b.logE) / Math.sqrt(a.se * a.se + b.se * b.se);
  if (z > 1.959963984540054) {
    return { winner: a.name, ranked: rows, text: `Equal-time winner ${lead}: ${a.name}, ${fmt(a.efficiency / b.efficiency, 2)}× as efficient as the next, ${b.name} (z = ${fmt(z, 2)}, with the error's and the timing's uncertainty).` };
  }
  return { winner: null, ranked: rows, text: `No significant difference at equal time between ${a.name} and ${b.name} ${lead}: ${fmt(a.efficiency / b.efficiency, 2)}× (z = ${fmt(z, 2)} < 1.96).` };
}

// ---------------------------------------------------------------------------------------------
// Calibration of the error bars

/**
 * z = (estimate - reference) / std_error of every replicate of `levels` (all of them, or the
 * one with n === which). The reference is the exact value, or when it is unknown each level's
 * mean of its replicates. Replicates with a zero or missing error bar are counted in zeroSe
 * (a zero error bar with a wrong estimate is the confident wrong answer), not in z. Levels exact
 * to round-off (exact_to_roundoff: f/p constant) are counted in exactRuns, not in z: their z is
 * round-off over round-off.
 */
export function zScores(levels, exact = null, which = 'all') {
  const useExact = exact !== null && exact !== undefined && Number.isFinite(exact);
  const z = [];
  let zeroSe = 0;
  let exactRuns = 0;
  for (const l of levels) {
    if (which !== 'all' && l.n !== which) continue;
    const rep = l.replicates;
    if (!rep) continue;
    if (l.exact_to_roundoff === true) {
      exactRuns += rep.estimate.length;
      continue;
    }
    const ref = useExact ? exact : l.mean;
    for (let i = 0; i < rep.estimate.length; i++) {
      const est = rep.estimate[i];
      const se = rep.std_error[i];
      if (typeof est !== 'number' || !Number.isFinite(est) || typeof ref !== 'number') continue;
      if (typeof se === 'number' && se > 0 && Number.isFinite(se)) z.push((est - ref) / se);
      else zeroSe++;
    }
  }
  return { z, zeroSe, exactRuns, reference: useExact ? 'exact' : 'mean' };
}

/**
 * Histogram of `values` over [lo, hi) in bins of `width`: counts, and density = counts /
 * (all values x width) so that it compares with a density; values outside go to below/above.
 */
export function histogram(values, { lo = -5, hi = 5, width = 0.5 } = {}) {
  const bins = Math.round((hi - lo) / width);
  const edges = Array.from({ length: bins + 1 }, (_, i) => round9(lo + i * width));
  const counts = new Array(bins).fill(0);
  let below = 0;
  let above = 0;
  let total = 0;
  for (const v of values) {
    if (typeof v !== 'number' || Number.isNaN(v)) continue;
    total++;
    if (v < lo) below++;
    else if (v >= hi) above++;
    else counts[Math.min(bins - 1, Math.floor((v - lo) / width))]++;
  }
  const density = counts.map((c) => (total ? c / (total * width) : 0));
  return { edges, counts, density, below, above, total };
}

function round9(v) {
  return Math.round(v * 1e9) / 1e9;
}

export function normalDensity(x) {
  return Math.exp(-0.5 * x * x) / Math.sqrt(2 * Math.PI);
}

/**
 * The calibration plot: x a grid over [lo, hi] (step 0.1, a multiple of the bin width), the
 * standard normal density on it, and per estimator its z-score histogram as a step function
 * (y at grid point x = the density of the bin starting at or before x).
 */
export function calibrationSeries(records, order, exact = null, which = 'all',
  { lo = -5, hi = 5, width = 0.5, step = 0.1 } = {}) {
  const count = Math.round((hi - lo) / step);
  const x = Array.from({ length: count + 1 }, (_, i) => round9(lo + i * step));
  const normal = x.map(normalDensity);
  const series = order.filter((n) => records[n]).map((name) => {
    const zs = zScores(records[name].levels, exact, which);
    const h = histogram(zs.z, { lo, hi, width });
    const bins = h.counts.length;
    const y = x.map((v) => (h.total ? h.density[Math.min(bins - 1, Math.floor((v - lo) / width + 1e-9))] : null));
    return {
      name, y, total: h.total, below: h.below, above: h.above, zeroSe: zs.zeroSe, exactRuns: zs.exactRuns,
      reference: zs.reference, within2: zs.z.filter((v) => Math.abs(v) <= 1.96).length,
    };
  });
  return { x, normal, series };
}

/** coverage95 against N per estimator (null where unknown: no exact value). */
export function coverageSeries(records, order, xs = null) {
  const named = order.filter((n) => records[n]);
  const x = xs ? xs.slice() : unionSorted(named.flatMap((n) => records[n].levels.map((l) => l.n)));
  const series = named.map((name) => {
    const byN = new Map(records[name].levels.map((l) => [l.n, l]));
    return {
      name,
      y: x.map((n) => {
        const l = byN.get(n);
        return l && typeof l.coverage95 === 'number' ? l.coverage95 : null;
      }),
    };
  });
  return { x, series };
}

// ---------------------------------------------------------------------------------------------
// Diagnostics and text

/** Severities most severe first; a warning without one (an older result) counts as "warning". */
export const SEVERITIES = ['error', 'warning', 'info'];
export function severityOf(w) {
  return SEVERITIES.includes(w && w.severity) ? w.severity : 'warning';
}

/**
 * Every warning of the records, grouped by (estimator, scope, code): estimator-level flags
 * once, level flags with the list of N where they were raised and the message of the first;
 * errors first, then warnings, then info (in record order within a severity).
 */
/** Each diagnostic code in plain words: what it means for the reader (the code itself stays
 *  beside it, small, for searching the documentation). */
export const FLAG_TITLES = Object.freeze({
  no_estimate: 'No estimate: every replicate failed',
  nonfinite_estimate: 'The estimate is not a number',
  nonfinite_variance: 'The error bar is not a number',
  zero_error_bar: 'An error bar of zero where the replicates disagree: the interval is wrong',
  nonfinite: 'Samples that were not numbers were dropped',
  zero_pdf_samples: 'Points where the density is zero but f is not: that mass is missed',
  skewed_weights: 'Skewed weights: the error bar is not yet trustworthy at this N',
  low_ess: 'Few effective samples: a handful of points carry the estimate',
  exact_outside_ci: 'The exact value is outside the replicates\' interval: biased or wrong error bars',
  heavy_tail: 'Heavy tail: the variance may be infinite',
  heavy_tail_4: 'Heavy tail: the fourth moment may be infinite (the error bar\'s own error converges slowly)',
  pdf_support: 'The density misses part of where f is non-zero: biased',
  level_drift: 'The estimates drift across N more than their error bars allow',
  iterations_disagree: 'The iterations disagree more than their error bars allow',
  error_bars_understate: 'The error bars are too small for the spread of the replicates',
  error_bars_unstable: 'The replicates\' error bars disagree with each other: some saw a feature others missed',
  bias_dominates: 'The bias dominates the error from some N on',
  conservative_error_bars: 'Conservative error bars: wider than the replicates\' spread',
  float32_accumulator: 'A single-precision accumulator limits the accuracy',
  below_reference_noise: 'The error is below the reference\'s own noise',
  reference_noise: 'The reference is noisy',
  slow_convergence: 'Slower convergence than an unbiased estimator\'s',
  pixel_error_bars: 'The pixels\' error bars cover too rarely',
  few_pixel_errors: 'A few pixel errors make this level\'s error: it rests on rare events',
  rare_large_errors: 'Rare large pixel errors make the error: levels that missed them understate it',
  tolerance_not_met: 'The requested accuracy was not reached',
});

/** The plain-language title of a diagnostic code (the code itself when unknown). */
export function flagTitle(code) {
  return FLAG_TITLES[code] || code;
}

/**
 * The N of a collapsed diagnostic as text: every level of the ladder ("every N, 16 … 65536"), a
 * run of consecutive ladder steps ("N = 16 … 1024, 7 levels") or a list.
 */
export function nText(ns, steps = [], name = 'N') {
  if (!ns.length) return '';
  const sorted = [...new Set(ns)].sort((a, b) => a - b);
  if (sorted.length === 1) return `${name} = ${sorted[0]}`;
  const idx = sorted.map((n) => steps.indexOf(n));
  const consecutive = idx.every((k, i) => k >= 0 && (i === 0 || k === idx[i - 1] + 1));
  if (consecutive && sorted.length >= 3) {
    const range = `${sorted[0]} … ${sorted[sorted.length - 1]}`;
    return sorted.length === steps.length ? `every ${name}, ${range}` : `${name} = ${range} (${sorted.length} levels)`;
  }
  return `${name} = ${sorted.join(', ')}`;
}

export function collectWarnings(records, order) {
  const out = [];
  for (const name of order) {
    const r = records[name];
    if (!r) continue;
    for (const w of r.warnings || []) {
      out.push({ estimator: name, scope: 'estimator', severity: severityOf(w), code: w.code, message: w.message, n: [] });
    }
    const byCode = new Map();
    for (const l of r.levels) {
      for (const w of l.warnings || []) {
        if (!byCode.has(w.code)) {
          const item = { estimator: name, scope: 'level', severity: severityOf(w), code: w.code, message: w.message, n: [] };
          byCode.set(w.code, item);
          out.push(item);
        }
        byCode.get(w.code).n.push(l.n);
      }
    }
  }
  const rank = (w) => SEVERITIES.indexOf(w.severity);
  return out.map((w, i) => [w, i]).sort((a, b) => rank(a[0]) - rank(b[0]) || a[1] - b[1]).map(([w]) => w);
}

/** x with 3 decimals exactly as C's printf("%.3f") writes it (ties to even, -0.000 kept). */
export function fixed3(x) {
  if (!Number.isFinite(x)) return String(x);
  // toFixed rounds an exact tie (a binary value ending in exactly 5 at the 4th decimal, such as
  // 1.0625) away from zero; glibc's printf rounds it to even. Other values round alike.
  const digits = Math.abs(x).toFixed(20);
  let s;
  if (/^\d+\.\d{3}50*$/.test(digits)) {
    const [int, frac] = digits.split('.');
    let k = BigInt(int + frac.slice(0, 3));
    if (k % 2n === 1n) k += 1n;
    const t = k.toString().padStart(4, '0');
    s = `${t.slice(0, -3)}.${t.slice(-3)}`;
  } else {
    s = Math.abs(x).toFixed(3);
  }
  return x < 0 || Object.is(x, -0) ? `-${s}` : s;
}

/** The core's fitted order as the CLI prints it: "-1.040 ± 0.028", or why there is none. */
export function fitText(fit) {
  if (!fit || !fit.valid || typeof fit.order !== 'number') {
    return fit && fit.note ? `no fit (${fit.note})` : 'no fit yet';
  }
  const se = typeof fit.order_se === 'number' ? ` ± ${fixed3(fit.order_se)}` : '';
  return `${fixed3(fit.order)}${se}`;
}

/** A number for tables: 4 significant digits, exponent form when very small or large. */
export function fmt(v, digits = 4) {
  if (v === null || v === undefined) return '—';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return String(v);
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a < 1e-3 || a >= 1e6) return v.toExponential(digits - 1);
  return Number(v.toPrecision(digits)).toString();
}

/** [lo, hi] in whole decades around the positive finite values (for log axes). */
export function decadeRange(values, fallback = [1e-6, 1]) {
  let min = Infinity;
  let max = -Infinity;
  for (const v of values) {
    if (positive(v) === null) continue;
    if (v < min) min = v;
    if (v > max) max = v;
  }
  if (!(min <= max)) return fallback.slice();
  // Number('1e-5') is the double nearest 10^-5; 10 ** -5 is not always.
  let lo = Math.floor(Math.log10(min) + 1e-9);
  let hi = Math.ceil(Math.log10(max) - 1e-9);
  if (hi <= lo) {
    lo -= 1;
    hi += 1;
  }
  return [Number(`1e${lo}`), Number(`1e${hi}`)];
}

// ---------------------------------------------------------------------------------------------
// Splitting a run over workers, and the result of a run cut short

/** Deals `names` round-robin into at most k non-empty groups (one per worker), order kept. */
export function splitEstimators(names, k) {
  const groups = Array.from({ length: Math.max(1, Math.min(k, names.length)) }, () => []);
  names.forEach((n, i) => groups[i % groups.length].push(n));
  return groups.filter((g) => g.length);
}

/**
 * How a render run's estimators are dealt over k workers: [{estimators, part, parts}]. While
 * there are at least as many estimators as workers, each worker studies a group of them
 * (part 0 of 1). With fewer, every estimator's replicates are split over its share of the
 * workers (replicate r to part r % parts; at most `reps` parts), so that one estimator's
 * images use every core; the parts' results are merged by the render core (mergeParts).
 */
export function splitRenderWork(names, k, reps) {
  if (names.length >= k || !(reps >= 2)) {
    return splitEstimators(names, k).map((estimators) => ({ estimators, part: 0, parts: 1 }));
  }
  const parts = Math.max(1, Math.min(Math.floor(k / names.length), reps));
  return names.flatMap((name) => Array.from({ length: parts }, (_, part) => ({ estimators: [name], part, parts })));
}

/**
 * Gathers the parts of one estimator group split by replicate and hands on whole levels and a
 * whole result. `merge(parts)` returns a promise of the merged result (the render core's
 * mergeParts, in a worker); `onLevel(line)` gets a progress line like an unsplit study's once
 * every part has finished that level (its fit and warnings over the levels so far), and
 * `onResult(result)` the merged result once every part has returned. Merges run one after
 * another, so lines come in order and before the result.
 */
export function splitCollector({ parts, merge, onLevel, onResult, onError = () => {} }) {
  const lines = Array.from({ length: parts }, () => []);
  const results = Array(parts).fill(null);
  let merged = 0; // levels handed on
  let chain = Promise.resolve();
  let failed = false;
  const queue = (task) => {
    chain = chain.then(task).catch((e) => {
      if (!failed) onError(e);
      failed = true;
    });
  };
  // A level line of each part as a result of its levels so far (what mergeParts reads).
  const asResult = (partLines) => {
    const last = partLines[partLines.length - 1];
    return {
      ...last,
      estimators: last.estimators.map((e, i) => {
        const { level, ...meta } = e;
        return { ...meta, levels: partLines.map((l) => l.estimators[i].level) };
      }),
    };
  };
  const flushLevels = () => {
    while (lines.every((l) => l.length > merged)) {
      const index = merged++;
      const parts = lines.map((l) => asResult(l.slice(0, index + 1)));
      queue(async () => {
        const m = await merge(parts);
        onLevel({
          ...m,
          estimators: m.estimators.map(({ levels, ...meta }) => ({ ...meta, level: levels[index] })),
        });
      });
    }
  };
  return {
    level(part, line) {
      if (!line || line.kind === 'render_reference') return;
      lines[part].push(line);
      flushLevels();
    },
    result(part, result) {
      results[part] = result;
      if (results.every((r) => r)) queue(async () => onResult(await merge(results)));
    },
    /** A promise that settles when the merges queued so far have. */
    settled: () => chain,
  };
}

/**
 * A result object (docs/result-schema.md) from the levels streamed so far, for exporting a
 * run that was cancelled (its workers were terminated, so they returned no result): the
 * estimators are the streamed records, the scene block what core.sceneInfo said of the scene.
 */
export function partialResult(run, info, version = null) {
  const render = run.kind === 'render';
  let scene;
  if (!info) {
    scene = { name: run.sceneName };
  } else if (render) {
    scene = {
      name: info.name, description: info.description, kind: 'render', width: run.settings ? run.settings.width : info.width,
      height: run.settings ? run.settings.height : info.height, triangles: info.triangles, lights: info.lights,
      accel: info.accel, warnings: info.warnings, exact: null,
    };
  } else {
    scene = { name: info.name, description: info.description, domain: info.domain, dimension: info.dimension, exact: info.exact };
  }
  return {
    version: 1,
    ...(render ? { kind: 'render' } : {}),
    mcplay: version,
    scene,
    settings: {
      ...(run.settings || {}),
      threads: run.threads || run.workers,
      ...(render ? { n_name: run.nName, error_name: run.errorName } : {}),
    },
    cancelled: run.status !== 'done',
    wall_time_s: run.elapsed !== null && run.elapsed !== undefined ? run.elapsed / 1000 : null,
    estimators: run.order.filter((n) => run.records[n]).map((n) => run.records[n]),
    ...(render && run.referencePng ? { reference_png: run.referencePng } : {}),
  };
}

// ---------------------------------------------------------------------------------------------
// Sample points (core.samples): the f/p overlay of 1D problems, weight histograms, summaries

/** ∫|f| over the grid x by the trapezoid rule (0 when there is no interval). */
export function trapezoidAbs(x, f) {
  let s = 0;
  for (let i = 1; i < x.length; i++) {
    const a = Math.abs(f[i - 1]);
    const b = Math.abs(f[i]);
    if (Number.isFinite(a) && Number.isFinite(b)) s += 0.5 * (a + b) * (x[i] - x[i - 1]);
  }
  return s;
}

/** f on the grid divided by ∫|f| (trapezoid), so that it compares with a density; area = ∫|f|
 *  (y is null when that area is zero or not finite). */
export function normalizeCurve(x, f) {
  const area = trapezoidAbs(x, f);
  if (!(area > 0) || !Number.isFinite(area)) return { y: f.map(() => null), area };
  return { y: f.map((v) => (Number.isFinite(v) ? v / area : null)), area };
}

/**
 * The 1D overlay of a samples answer: x, f normalised to unit area, and each estimator's
 * density p(x) on the same grid (in `order`). The y range is capped when a spike (a singular
 * f or p) would flatten everything else: at 20 x the 75th percentile of the values (at least
 * 1.5); `clipped` tells whether anything lies above it.
 */
export function curveOverlay(curve, order, { exact = null } = {}) {
  if (!curve || !Array.isArray(curve.x) || !curve.x.length) return null;
  let { y: f, area } = normalizeCurve(curve.x, curve.f);
  // The grid misses the mass of an integrable singularity (x^-0.9: most of it lies before the
  // first grid point): when f >= 0 and the exact integral is known, divide by that instead.
  const trapezoid = area;
  let areaFrom = 'trapezoid';
  if (typeof exact === 'number' && exact > 0 && Number.isFinite(exact) && curve.f.every((v) => !(v < 0))
    && Math.abs(trapezoid - exact) > 0.01 * exact) {
    area = exact;
    areaFrom = 'exact';
    f = curve.f.map((v) => (Number.isFinite(v) ? v / exact : null));
  }
  const pdfs = order.filter((n) => curve.pdf && Array.isArray(curve.pdf[n]))
    .map((name) => ({ name, y: curve.pdf[name].map((v) => (Number.isFinite(v) ? v : null)) }));
  const all = [...f, ...pdfs.flatMap((p) => p.y)].filter((v) => v !== null && Number.isFinite(v));
  let lo = 0;
  let hi = 1;
  if (all.length) {
    const sorted = all.slice().sort((a, b) => a - b);
    const max = sorted[sorted.length - 1];
    lo = Math.min(0, sorted[0]);
    const q75 = sorted[Math.floor(0.75 * (sorted.length - 1))];
    const cap = Math.max(20 * q75, 1.5);
    hi = max > cap ? cap : max * 1.05;
    if (!(hi > lo)) hi = lo + 1;
  }
  const clipped = all.some((v) => v > hi);
  return { x: curve.x.slice(), f, area, areaFrom, trapezoid, pdfs, yRange: [lo * 1.05, hi], clipped };
}

/**
 * The MIS weight curves of a samples answer: for each estimator in `order` that has
 * curve.mis_weights, one line per technique k, w_k(x) on the curve's grid, labelled by the
 * technique's density and share (from the estimator's "techniques"). `dash` numbers the
 * technique within its estimator (0: solid).
 */
export function misWeightCurves(samples, order) {
  const curve = samples && samples.curve;
  if (!curve || !curve.mis_weights || !Array.isArray(curve.x)) return [];
  const byName = Object.fromEntries((samples.estimators || []).map((e) => [e.name, e]));
  const out = [];
  for (const name of order) {
    const rows = curve.mis_weights[name];
    if (!Array.isArray(rows)) continue;
    const techniques = (byName[name] && byName[name].techniques) || [];
    rows.forEach((y, k) => {
      const t = techniques[k];
      const label = t ? `${t.pdf} (${fmt(t.share, 2)})` : `technique ${k + 1}`;
      out.push({ name, k, label, y: y.map((v) => (Number.isFinite(v) ? v : null)) });
    });
  }
  return out;
}

/**
 * Common log-spaced bins of |w| for the weight histograms of several estimators: edges are
 * powers of 10^(1/binsPerDecade) covering the largest |w| and at most maxDecades below it
 * (smaller non-zero |w| go to the first bin's "below" count).
 */
export function weightBins(weightArrays, { binsPerDecade = 4, maxDecades = 12 } = {}) {
  let min = Infinity;
  let max = -Infinity;
  for (const ws of weightArrays) {
    for (const w of ws) {
      const a = Math.abs(w);
      if (!(a > 0) || !Number.isFinite(a)) continue;
      if (a < min) min = a;
      if (a > max) max = a;
    }
  }
  if (!(min <= max)) return null;
  const top = Math.ceil(Math.log10(max) * binsPerDecade + 1e-9) / binsPerDecade;
  let bottom = Math.floor(Math.log10(min) * binsPerDecade - 1e-9) / binsPerDecade;
  bottom = Math.max(bottom, top - maxDecades);
  if (top - bottom < 1) bottom = top - 1;
  const bins = Math.round((top - bottom) * binsPerDecade);
  const logEdges = Array.from({ length: bins + 1 }, (_, i) => round9(bottom + i / binsPerDecade));
  return { logEdges, binsPerDecade };
}

/**
 * Histogram of |w| on the bins of weightBins: counts per bin, `zeros` (w = 0, e.g. f = 0 there)
 * and `nonFinite` counted apart, `below` (0 < |w| under the first edge), `negative` (w < 0),
 * fraction = counts / total, and the heavy-tail figure max|w| / mean|w|.
 */
export function weightHistogram(weights, bins) {
  const nb = bins ? bins.logEdges.length - 1 : 0;
  const counts = new Array(nb).fill(0);
  let zeros = 0;
  let nonFinite = 0;
  let below = 0;
  let negative = 0;
  let sumAbs = 0;
  let maxAbs = 0;
  let total = 0;
  for (const w of weights) {
    total++;
    if (typeof w !== 'number' || !Number.isFinite(w)) {
      nonFinite++;
      continue;
    }
    if (w < 0) negative++;
    const a = Math.abs(w);
    sumAbs += a;
    if (a > maxAbs) maxAbs = a;
    if (a === 0) {
      zeros++;
      continue;
    }
    if (!bins) continue;
    const k = Math.floor((Math.log10(a) - bins.logEdges[0]) * bins.binsPerDecade + 1e-9);
    if (k < 0) below++;
    else counts[Math.min(nb - 1, k)]++;
  }
  const finite = total - nonFinite;
  const meanAbs = finite ? sumAbs / finite : 0;
  return {
    counts, fraction: counts.map((c) => (total ? c / total : 0)), zeros, nonFinite, below, negative, total,
    maxAbs, meanAbs, tail: meanAbs > 0 ? maxAbs / meanAbs : null,
  };
}

/**
 * The sample points of a samples answer as CSV: one row per point of each estimator, with its
 * index, the unit-cube point u, the domain point x, f(x), the density p(x) and the weight f/p
 * (empty where the answer has no such array). Numbers as JavaScript writes them (round trip).
 */
export function samplesCsv(samples) {
  if (!samples || !Array.isArray(samples.estimators)) return '';
  const dimOf = (a) => (Array.isArray(a) ? a.length : 0);
  const du = Math.max(0, ...samples.estimators.map((e) => dimOf(e.u)));
  const dx = Math.max(0, ...samples.estimators.map((e) => dimOf(e.x)));
  const head = ['estimator', 'i', ...Array.from({ length: du }, (_, k) => `u${k + 1}`),
    ...Array.from({ length: dx }, (_, k) => `x${k + 1}`), 'f', 'density', 'weight'];
  const cell = (v) => (v === null || v === undefined ? '' : String(v));
  const rows = [head.join(',')];
  for (const e of samples.estimators) {
    const n = Math.max(dimOf(e.u) ? e.u[0].length : 0, dimOf(e.x) ? e.x[0].length : 0,
      Array.isArray(e.weight) ? e.weight.length : 0);
    const name = /[",\n]/.test(e.name) ? `"${e.name.replace(/"/g, '""')}"` : e.name;
    for (let i = 0; i < n; ++i) {
      rows.push([name, i,
        ...Array.from({ length: du }, (_, k) => cell(e.u && e.u[k] ? e.u[k][i] : null)),
        ...Array.from({ length: dx }, (_, k) => cell(e.x && e.x[k] ? e.x[k][i] : null)),
        cell(e.f ? e.f[i] : null), cell(e.density ? e.density[i] : null), cell(e.weight ? e.weight[i] : null)].join(','));
    }
  }
  return `${rows.join('\n')}\n`;
}

/** What the scatter shows of each estimator of a samples answer (for mcplayDebug and the notes). */
export function samplesSummary(samples) {
  if (!samples) return null;
  return {
    n: samples.n, seed: samples.seed, domain: samples.domain, dimension: samples.dimension,
    curve: Boolean(samples.curve),
    estimators: samples.estimators.map((e) => ({
      name: e.name, sampler: e.sampler, points: e.u && e.u[0] ? e.u[0].length : 0,
      strata: (e.strata || []).slice(), samplesPerStratum: e.samples_per_stratum,
      mapIncrements: Array.isArray(e.map_edges) && e.map_edges.length ? e.map_edges[0].length - 1 : 0,
      boxes: e.boxes && Array.isArray(e.boxes.lo) ? e.boxes.lo.length : 0,
      mapHistory: Array.isArray(e.map_history) ? e.map_history.length : 0,
      runN: e.run_n || samples.n,
    })),
  };
}

/**
 * How the points are drawn in the domain: which coordinates (axes), their ranges and the outline
 * of the domain ({type: 'circle', cx, cy, r} | {type: 'polygon', points} | {type: 'rect'}), and
 * a note when it is a projection. `domain` is the scene's domain object, when known.
 */
/**
 * The running estimate of a point sequence's weights (the mean of the first k, k = 1..n) with
 * its 95% interval, mean +- 1.96 s / sqrt(k) from the first k's sample standard deviation
 * (Welford's update [Welford62]; no interval at k = 1). For independent points (uniform or
 * importance sampling) the mean at k is the estimator at N = k; for stratified, Latin
 * hypercube and quasi-random sets only the whole set is (their first k points are not a
 * design of k points, and their spread is not the error of the mean).
 */
export function runningEstimate(weights) {
  const n = Array.isArray(weights) ? weights.length : 0;
  const mean = new Array(n);
  const lo = new Array(n);
  const hi = new Array(n);
  let m = 0;
  let m2 = 0;
  let k = 0;
  for (let i = 0; i < n; ++i) {
    const w = Number(weights[i]);
    if (!Number.isFinite(w)) {
      mean[i] = lo[i] = hi[i] = null;
      continue;
    }
    k += 1;
    const d = w - m;
    m += d / k;
    m2 += d * (w - m);
    mean[i] = m;
    const h = k > 1 ? 1.959963984540054 * Math.sqrt(m2 / (k - 1) / k) : null;
    lo[i] = h === null ? null : m - h;
    hi[i] = h === null ? null : m + h;
  }
  return { mean, lo, hi };
}

/**
 * Why an estimator's error bars are wider than its estimates' spread, by design, or null: the
 * core's error_method (collapsed strata pair neighbouring cells [Cochran77, 5A.12]; the iid
 * formula on a Latin hypercube or similar design overstates its variance). Their z-scores are
 * narrower than N(0, 1) and their coverage above 95%: that is what conservative means.
 */
export function conservativeErrorBars(record) {
  // The core says which error bars are conservative (error_bars_conservative, from the error
  // method); the words say why, for the methods that have words.
  if (!record || record.error_bars_conservative !== true) return null;
  const why = {
    collapsed_strata: 'collapsed strata: neighbouring cells paired',
    iid_conservative: 'the iid formula, wider than this design\'s spread',
  }[record.error_method];
  return `conservative error bars (${why || 'wider than the estimator\'s spread by design'})`;
}

/** Is the mean of the first k of an estimator's points its estimate at N = k (independent points)? */
export function replayIsEstimator(e) {
  // The core says so per estimator (samples output replay_is_estimate, from its kind); without
  // it, no band is drawn.
  return Boolean(e && e.replay_is_estimate === true);
}

export function domainView(samples, domain = null, pair = [0, 1]) {
  const type = samples.domain;
  const d = samples.dimension;
  const xs = samples.estimators.length ? samples.estimators[0].x : [];
  const extent = (k) => {
    let lo = Infinity;
    let hi = -Infinity;
    for (const e of samples.estimators) for (const v of e.x[k] || []) {
      if (v < lo) lo = v;
      if (v > hi) hi = v;
    }
    if (!(lo <= hi)) return [0, 1];
    if (lo >= 0 && hi <= 1) return [0, 1];
    const pad = 0.02 * (hi - lo || 1);
    return [lo - pad, hi + pad];
  };
  if (type === 'disk') {
    const [cx, cy] = domain && Array.isArray(domain.center) ? domain.center : [0, 0];
    const r = domain && typeof domain.radius === 'number' ? domain.radius : 1;
    return { axes: [0, 1], labels: ['x', 'y'], xRange: [cx - r, cx + r], yRange: [cy - r, cy + r],
      outline: { type: 'circle', cx, cy, r }, note: '' };
  }
  if (type === 'triangle') {
    const v = domain && Array.isArray(domain.vertices) ? domain.vertices : [[0, 0], [1, 0], [0, 1]];
    const xr = [Math.min(...v.map((p) => p[0])), Math.max(...v.map((p) => p[0]))];
    const yr = [Math.min(...v.map((p) => p[1])), Math.max(...v.map((p) => p[1]))];
    return { axes: [0, 1], labels: ['x', 'y'], xRange: xr, yRange: yr, outline: { type: 'polygon', points: v }, note: '' };
  }
  if (type === 'sphere' || type === 'hemisphere' || (xs.length === 3 && d === 3 && type !== 'box')) {
    return { axes: [0, 1], labels: ['x', 'y'], xRange: [-1, 1], yRange: [-1, 1], outline: { type: 'circle', cx: 0, cy: 0, r: 1 },
      note: `directions on the ${type} projected to (x, y)` };
  }
  if (d === 1) {
    const interval = domain && domain.type === 'interval' && Number.isFinite(domain.lower) && Number.isFinite(domain.upper);
    const r = interval ? [domain.lower, domain.upper]
      : samples.curve && samples.curve.x.length ? [samples.curve.x[0], samples.curve.x[samples.curve.x.length - 1]] : extent(0);
    return { axes: [0], labels: ['x', 'f(x)'], xRange: r, yRange: null, outline: { type: 'rect' }, note: '' };
  }
  // A box of d > 2 axes: the projection on the chosen pair.
  const [a, b] = d > 2 && pair[0] !== pair[1] && pair.every((k) => k >= 0 && k < d) ? pair : [0, 1];
  return { axes: [a, b], labels: [`x${a + 1}`, `x${b + 1}`], xRange: extent(a), yRange: extent(b), outline: { type: 'rect' },
    note: d > 2 ? `axes ${a + 1} and ${b + 1} of ${d}` : '' };
}

/**
 * Maps from the unit square to a disk (center c, radius R) that the core's disk samplers use:
 * polar (r = R sqrt(u1), θ = 2π u2) and concentric (Shirley–Chiu). Used only to draw the images
 * of the strata cells in the domain, and only when the map reproduces the estimator's own
 * points (mapFor), so a sampler the page does not know simply gets no mapped grid.
 */
export const DISK_MAPS = Object.freeze({
  polar: ([u0, u1]) => {
    const r = Math.sqrt(u0);
    return [r * Math.cos(2 * Math.PI * u1), r * Math.sin(2 * Math.PI * u1)];
  },
  concentric: ([u0, u1]) => {
    const a = 2 * u0 - 1;
    const b = 2 * u1 - 1;
    if (a === 0 && b === 0) return [0, 0];
    let r;
    let phi;
    if (Math.abs(a) > Math.abs(b)) {
      r = a;
      phi = (Math.PI / 4) * (b / a);
    } else {
      r = b;
      phi = Math.PI / 2 - (Math.PI / 4) * (a / b);
    }
    return [r * Math.cos(phi), r * Math.sin(phi)];
  },
});

/** The disk map (of DISK_MAPS, scaled to the disk) that gives estimator e's x from its u, or null. */
export function mapFor(e, domain = null) {
  if (!e || !e.u || e.u.length !== 2 || !e.x || e.x.length < 2 || !e.u[0].length) return null;
  const [cx, cy] = domain && Array.isArray(domain.center) ? domain.center : [0, 0];
  const R = domain && typeof domain.radius === 'number' ? domain.radius : 1;
  for (const [name, m] of Object.entries(DISK_MAPS)) {
    const f = (u) => {
      const [x, y] = m(u);
      return [cx + R * x, cy + R * y];
    };
    let ok = true;
    for (let i = 0; i < e.u[0].length && ok; i++) {
      const [x, y] = f([e.u[0][i], e.u[1][i]]);
      ok = Math.abs(x - e.x[0][i]) <= 1e-7 * R && Math.abs(y - e.x[1][i]) <= 1e-7 * R;
    }
    if (ok) return { name, map: f };
  }
  return null;
}

/** The images of the strata lines u_k = j / cells_k under `map`, as polylines of [x, y]. */
export function mappedGrid(map, strata, steps = 64) {
  const lines = [];
  const [c0, c1] = strata;
  const line = (fixed, axis) => Array.from({ length: steps + 1 }, (_, i) => map(axis === 0 ? [fixed, i / steps] : [i / steps, fixed]));
  for (let j = 0; j <= c0; j++) lines.push(line(j / c0, 0));
  for (let j = 0; j <= c1; j++) lines.push(line(j / c1, 1));
  return lines;
}
