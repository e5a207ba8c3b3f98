// Sample points (core.samples): the f/p overlay of 1D problems, MIS weight curves, weight
// histograms, the CSV export and summary, the running estimate, and the domain view.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.
import { round9 } from './numbers.js';
import { fmt } from './text.js';

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
      const label = t ? `${t.pdf_text || t.pdf} (${fmt(t.share, 2)})` : `technique ${k + 1}`;
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
