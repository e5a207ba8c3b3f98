// The "race" to a requested accuracy: what the page says about a stopping result (the C API's
// "kind": "stopping", docs/result-schema.md). Each estimator ran R independent times, each time
// doubling N until its error bar met the target or a budget ended; this module turns those runs
// into a time to the target per estimator, with the uncertainty of that time (the statistics);
// claims/race.js decides what the card says of them. Pure functions, no DOM: web/test/race.test.mjs.
//
// A run that did not meet the target is censored: its time to the target is longer than what it
// used, so it counts as +Infinity. Medians and rank tests stay valid with such values (a median
// is finite while fewer than half the runs are censored); means would not.

/** Bounds of the race's settings (the core checks the tolerances and the budget again). */
export const RACE_LIMITS = Object.freeze({
  runsMin: 2,
  runsMax: 200,
  secondsMin: 0.01,
  secondsMax: 600,
  nMax: 2 ** 30,
});

export const RACE_DEFAULTS = Object.freeze({ relTol: '1e-3', absTol: '', runs: '10', maxSeconds: '2' });

/** Parses a finite number > 0 (decimal or exponent notation); anything else gives null. */
export function parsePositive(text) {
  if (typeof text === 'number') text = String(text);
  if (typeof text !== 'string') return null;
  const t = text.trim();
  if (!/^[+]?(\d+\.?\d*|\.\d+)(e[+-]?\d+)?$/i.test(t)) return null;
  const v = Number(t);
  return Number.isFinite(v) && v > 0 ? v : null;
}

/**
 * The race's settings from the card's inputs ({relTol, absTol, runs, maxSeconds}, text):
 * {ok: true, options} with the stopping options of the C API, or {ok: false, errors: {field:
 * message}}. At least one tolerance is needed; an empty one is not used.
 */
export function raceOptions(inputs) {
  const errors = {};
  const options = {};
  const rel = (inputs.relTol ?? '').trim();
  const abs = (inputs.absTol ?? '').trim();
  if (rel) {
    const v = parsePositive(rel);
    if (v === null || v >= 1) errors.relTol = 'relative tolerance: a number in (0, 1), e.g. 1e-3';
    else options.rel_tol = v;
  }
  if (abs) {
    const v = parsePositive(abs);
    if (v === null) errors.absTol = 'absolute tolerance: a number > 0, e.g. 1e-4';
    else options.abs_tol = v;
  }
  if (!rel && !abs) errors.relTol = 'give a relative or an absolute tolerance';
  const runs = Number((inputs.runs ?? '').trim());
  if (!Number.isSafeInteger(runs) || runs < RACE_LIMITS.runsMin || runs > RACE_LIMITS.runsMax) {
    errors.runs = `runs: a whole number in ${RACE_LIMITS.runsMin}..${RACE_LIMITS.runsMax}`;
  } else {
    options.reps = runs;
  }
  const s = parsePositive(inputs.maxSeconds ?? '');
  if (s === null || s < RACE_LIMITS.secondsMin || s > RACE_LIMITS.secondsMax) {
    errors.maxSeconds = `seconds per run: a number in ${RACE_LIMITS.secondsMin}..${RACE_LIMITS.secondsMax}`;
  } else {
    options.max_seconds = s;
  }
  return Object.keys(errors).length ? { ok: false, errors } : { ok: true, options };
}

/** The scene without the fields that ask for stopping (the page's N ladder runs it as a study). */
export function withoutStopping(scene) {
  if (!scene || typeof scene !== 'object') return scene;
  const { rel_tol: _r, abs_tol: _a, max_seconds: _s, ...rest } = scene;
  return rest;
}

/** The tolerance a scene asks for, as the race card's text inputs (empty when none). */
export function sceneTolerance(scene) {
  const t = (v) => (typeof v === 'number' && Number.isFinite(v) && v > 0 ? String(v) : '');
  return scene && typeof scene === 'object' ? { relTol: t(scene.rel_tol), absTol: t(scene.abs_tol) } : { relTol: '', absTol: '' };
}

function median(sorted) {
  const n = sorted.length;
  if (!n) return null;
  const h = Math.floor(n / 2);
  return n % 2 ? sorted[h] : (sorted[h - 1] === Infinity ? Infinity : (sorted[h - 1] + sorted[h]) / 2);
}

/** log of the binomial coefficient C(n, k). */
function logChoose(n, k) {
  let s = 0;
  for (let i = 1; i <= k; ++i) s += Math.log((n - k + i) / i);
  return s;
}

/**
 * The distribution-free confidence interval of a median from order statistics [DavidNagaraja03,
 * section 7.1]: with B ~ Binomial(n, 1/2), [x_(j), x_(n+1-j)] covers the median
 * with probability 1 - 2 P(B < j). Returns {lo, hi, level} for the largest j whose level is at
 * least `level`, or the whole range with its own (lower) level when n is too small for it.
 */
export function medianInterval(sorted, level = 0.95) {
  const n = sorted.length;
  if (!n) return null;
  let j = 1;
  let cdf = Math.exp(-n * Math.LN2); // P(B <= 0)
  let best = { j: 1, level: 1 - 2 * cdf };
  for (let k = 1; k < n / 2; ++k) {
    cdf += Math.exp(logChoose(n, k) - n * Math.LN2); // P(B <= k)
    const cover = 1 - 2 * cdf;
    if (cover < level) break;
    j = k + 1;
    best = { j, level: cover };
  }
  return { lo: sorted[best.j - 1], hi: sorted[n - best.j], level: best.level };
}

/** Standard normal upper tail P(Z > z) through erfc, by the Chebyshev fit of [NR07, section
 *  6.2.2] (erfcc: fractional error below 1.2e-7 everywhere, also in the far tail). */
export function normalUpperTail(z) {
  if (z < 0) return 1 - normalUpperTail(-z);
  const x = z / Math.SQRT2;
    const t = 1 / (1 + 0.5 * x);
  const poly = -x * x - 1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418
    + t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587
    + t * (-0.82215223 + t * 0.17087277))))))));
  return 0.5 * t * Math.exp(poly);
}

/**
 * The two-sided p-value of the Mann-Whitney-Wilcoxon rank-sum test that `a` and `b` come from
 * the same distribution [MannWhitney47], by the normal approximation with the variance
 * corrected for ties (censored runs, +Infinity, tie with each other) and a continuity
 * correction. Also the probability of superiority P(a < b) + P(a = b)/2 it estimates.
 */
export function mannWhitney(a, b) {
  const n1 = a.length;
  const n2 = b.length;
  if (!n1 || !n2) return { p: null, superiority: null };
  const all = [...a.map((v) => [v, 0]), ...b.map((v) => [v, 1])].sort((x, y) => (x[0] < y[0] ? -1 : x[0] > y[0] ? 1 : 0));
  let rankA = 0;
  let tieTerm = 0;
  for (let i = 0; i < all.length;) {
    let j = i;
    while (j < all.length && all[j][0] === all[i][0]) ++j;
    const rank = (i + 1 + j) / 2; // the tied values' mean rank
    for (let k = i; k < j; ++k) if (all[k][1] === 0) rankA += rank;
    const t = j - i;
    tieTerm += t * t * t - t;
    i = j;
  }
  const u = rankA - (n1 * (n1 + 1)) / 2; // pairs with a > b, ties counting half
  const n = n1 + n2;
  const mean = (n1 * n2) / 2;
  const variance = ((n1 * n2) / 12) * (n + 1 - tieTerm / (n * (n - 1)));
  const superiority = 1 - u / (n1 * n2);
  if (!(variance > 0)) return { p: 1, superiority };
  const z = Math.max(0, Math.abs(u - mean) - 0.5) / Math.sqrt(variance);
  return { p: Math.min(1, 2 * normalUpperTail(z)), superiority };
}

/**
 * One row per estimator of a stopping result: its runs' times to the target (censored runs as
 * +Infinity), their median and its 95% interval, the runs that met the target and that were
 * within it of the exact value, and the median evaluations and N.
 */
export function raceRows(result) {
  const rows = [];
  for (const e of (result && result.estimators) || []) {
    const runs = Array.isArray(e.runs) ? e.runs : [];
    const times = runs.map((r) => (r.met ? r.seconds : Infinity)).sort((x, y) => x - y);
    const used = runs.map((r) => r.seconds).filter(Number.isFinite);
    const evals = runs.filter((r) => r.met).map((r) => r.evaluations).sort((x, y) => x - y);
    const ns = runs.filter((r) => r.met).map((r) => r.n).sort((x, y) => x - y);
    const met = runs.filter((r) => r.met).length;
    // within the tolerance of the exact value: counted over the runs that met the target (the
    // core also judges the runs that ran out)
    const known = runs.filter((r) => r.met && typeof r.within_tolerance === 'boolean');
    const reasons = [...new Set(runs.filter((r) => !r.met).map((r) => r.reason))];
    rows.push({
      name: e.name,
      runs: runs.length,
      met,
      within: known.length ? known.filter((r) => r.within_tolerance).length : null,
      withinOf: known.length ? known.length : null,
      times,
      usedSeconds: used,
      median: median(times),
      interval: medianInterval(times),
      evaluations: evals.length * 2 > runs.length ? median(evals) : null,
      n: ns.length * 2 > runs.length ? median(ns) : null,
      reasons,
      warnings: Array.isArray(e.warnings) ? e.warnings : [],
    });
  }
  return rows;
}

/** The p-value below which the race names a winner (claims/race.js words the verdict). */
export const RACE_ALPHA = 0.05;

/** A time in s, ms or µs with 2-3 significant digits ('—' when not finite). */
export function formatSeconds(s) {
  if (!Number.isFinite(s)) return '—';
  const [v, unit] = s >= 1 ? [s, 's'] : s >= 1e-3 ? [s * 1e3, 'ms'] : [s * 1e6, 'µs'];
  return `${Number(v.toPrecision(v >= 100 ? 3 : 2))} ${unit}`;
}
