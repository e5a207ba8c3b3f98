// The sampler lab's line plots as data, pure (no uPlot, no DOM): the discrepancy curves with
// their reference slopes, the spectrum's radial average with the line P = 1, and a 1-D warp's
// observed and expected counts. Display mappings only: the values are the core's.

/** Bin centres of axis `k` of a warp test: the result's edges when it gives them, else
 *  (i + 1/2) / n on the unit interval of the natural coordinate. */
export function binCentres(result, k = 0) {
  const n = result.bins[k];
  const edges = Array.isArray(result.edges) && Array.isArray(result.edges[k]) && result.edges[k].length === n + 1 ? result.edges[k] : null;
  return Array.from({ length: n }, (_, i) => (edges ? (edges[i] + edges[i + 1]) / 2 : (i + 0.5) / n));
}

/** A 1-D warp's counts per bin: {x, observed, expected}. */
export function density1d(result) {
  return { x: binCentres(result, 0), observed: result.observed.slice(), expected: result.expected.slice() };
}

/** The radial average of a spectrum: {x: |k|, y: power, one: the line P = 1}, rings without
 *  a frequency (count 0) left out. */
export function radialSeries(spectrum) {
  const r = spectrum.radial;
  const x = [];
  const y = [];
  r.frequency.forEach((f, i) => {
    if (r.count && r.count[i] === 0) return;
    x.push(f);
    y.push(r.power[i]);
  });
  return { x, y, one: x.map(() => 1) };
}

/**
 * The discrepancy curves of mcp_discrepancy_curve: x = the N of the ladder, one series per
 * sampler of its L2-star discrepancy, one per sampler of its RMS integration error when the
 * result has a problem, and the reference slopes N^-1/2 and N^-1 ("up to log factors") through
 * the highest first point (display guides, not fits). Values <= 0 become null (log axes).
 */
export function curveSeries(result) {
  const xs = [...new Set(result.curves.flatMap((c) => c.n))].sort((a, b) => a - b);
  const align = (c, key) => xs.map((n) => {
    const i = c.n.indexOf(n);
    const v = i < 0 || !Array.isArray(c[key]) ? null : c[key][i];
    return typeof v === 'number' && v > 0 ? v : null;
  });
  const series = result.curves.map((c) => ({ sampler: c.sampler, kind: 'discrepancy', label: `${c.sampler} L2-star discrepancy`, y: align(c, 'l2_star_discrepancy') }));
  const errors = result.curves.filter((c) => Array.isArray(c.rms_error))
    .map((c) => ({ sampler: c.sampler, kind: 'error', label: `${c.sampler} RMS error`, y: align(c, 'rms_error') }));
  const first = series.map((s) => s.y[0]).filter((v) => v !== null);
  const anchor = first.length ? Math.max(...first) : null;
  const refs = anchor === null ? [] : [
    { label: 'N^-1/2', order: 0.5, y: xs.map((n) => anchor * (xs[0] / n) ** 0.5) },
    { label: 'N^-1', order: 1, y: xs.map((n) => anchor * (xs[0] / n)) },
  ];
  return { x: xs, series, errors, refs };
}
