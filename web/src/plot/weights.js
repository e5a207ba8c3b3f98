// The charts of f against the sampling densities, from the sample points (state.samples):
// the 1D overlay of f / integral |f| and each estimator's density p(x), the MIS weights w_k(x)
// of multiple importance sampling estimators, and the histogram of the weights |f/p|.
import { fmt, curveOverlay, misWeightCurves, weightBins, weightHistogram } from '../series.js';
import { AXIS, LOG10_AXIS, log10Ticks } from './axes.js';
import { uPlot, dom, draw, drop, empty } from './chart.js';
import { sceneColor, setLegend } from './legend.js';
import { coincidences, COINCIDE_DASHES } from './coincide.js';

// Curves closer than this share of the plot's height are drawn as one: the later one dashed.
const SAME_CURVE = 0.004;
const dashOf = (rank) => COINCIDE_DASHES[Math.min(rank, COINCIDE_DASHES.length - 1)];
/** The legend's words for a curve drawn dashed over an identical one. */
const sameText = (c, what) => ({ text: `same ${what} as ${c.of} (dashed over it)`, className: 'fit same-curve' });
/** The 1D overlay (#plot-overlay): f / integral |f| against each estimator's density p(x). */
export function renderOverlay(state, data) {
  const exact = state.sceneInfo && typeof state.sceneInfo.exact === 'number' ? state.sceneInfo.exact : null;
  const ov = data && data.curve ? curveOverlay(data.curve, data.estimators.map((e) => e.name), { exact }) : null;
  if (!ov) {
    drop('overlay');
    empty(dom.overlay, data && data.dimension !== 1 ? `1D problems only (this one is ${data.dimension}D).` : data ? '1D problems only.' : '1D problems only; no points yet.');
    dom.overlay.dataset.drawn = 'false';
    setLegend('overlay', dom['legend-overlay'], []);
    return;
  }
  const data2 = [ov.x, ov.f, ...ov.pdfs.map((p) => p.y)];
  // a density equal to another one, or to f / ∫|f|, would hide it: dashed over it, and said
  const same = coincidences([{ name: 'f / ∫|f|', y: ov.f }, ...ov.pdfs], SAME_CURVE, ov.yRange[1] - ov.yRange[0]).slice(1);
  const series = [{}, { label: 'f / ∫|f|', stroke: '#000', width: 2.5, points: { show: false } },
    ...ov.pdfs.map((p, i) => ({ label: p.name, stroke: sceneColor(state, p.name), width: same[i].rank ? 2 : 1.5,
      dash: dashOf(same[i].rank), points: { show: false } }))];
  const sig = JSON.stringify(['overlay', ov.pdfs.map((p) => p.name), same.map((c) => c.rank)]);
  draw('overlay', dom.overlay, sig, (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
    axes: [{ ...AXIS, label: 'x', space: 40 },
      { ...AXIS, label: 'density', size: 52, values: (u, splits) => splits.map((v) => fmt(v, 3)) }],
    series,
    cursor: { drag: { x: false, y: false } },
  }), data2, { xRange: [ov.x[0], ov.x[ov.x.length - 1]], yRange: ov.yRange });
  dom.overlay.dataset.drawn = 'true';
  setLegend('overlay', dom['legend-overlay'], [
    { name: 'f / ∫|f|', color: '#000', parts: [{ text: ov.areaFrom === 'exact' ? `∫f = ${fmt(ov.area, 4)} (exact; the grid gives ${fmt(ov.trapezoid, 4)})` : `∫|f| ≈ ${fmt(ov.area, 4)}`, className: 'fit' }] },
    ...ov.pdfs.map((p, i) => ({ name: p.name, color: sceneColor(state, p.name), dashed: same[i].rank > 0,
      data: { overlay: p.name, ...(same[i].of ? { same: same[i].of } : {}) },
      parts: same[i].of ? [sameText(same[i], 'density')] : [] })),
  ]);
  if (dom.overlayNote) {
    dom.overlayNote.textContent = 'f divided by ∫|f| (black, unit area; trapezoid rule on the grid) against each estimator\'s'
      + ' sampling density p(x): where p is much smaller than |f|, the weights f/p are large.'
      + (ov.areaFrom === 'exact' ? ' Here f is divided by its exact integral: the grid misses the mass of its singularity.' : '')
      + (ov.clipped ? ` The y axis is cut at ${fmt(ov.yRange[1], 3)}: a spike goes above it.` : '');
  }
}

const DASHES = [[], [8, 5], [2, 4], [10, 4, 2, 4]];

/** The MIS weights w_k(x) of each multiple importance sampling estimator (1D problems). */
export function renderMisWeights(state, data) {
  if (!dom.misweights) return;
  const lines = data ? misWeightCurves(data, data.estimators.map((e) => e.name)) : [];
  dom.misweightsBlock.hidden = !lines.length;
  if (!lines.length) {
    drop('misweights');
    setLegend('misweights', dom['legend-misweights'], []);
    return;
  }
  const x = data.curve.x;
  const series = [{}, ...lines.map((l) => ({
    label: `${l.name}: ${l.label}`, stroke: sceneColor(state, l.name), width: 1.75,
    dash: DASHES[l.k % DASHES.length], points: { show: false },
  }))];
  draw('misweights', dom.misweights, JSON.stringify(['misweights', lines.map((l) => [l.name, l.k])]), (c) => ({
    scales: { x: { time: false, range: () => c.xRange }, y: { range: () => [0, 1.02] } },
    axes: [{ ...AXIS, label: 'x', space: 40 }, { ...AXIS, label: 'weight', size: 52 }],
    series,
    cursor: { drag: { x: false, y: false } },
  }), [x, ...lines.map((l) => l.y)], { xRange: [x[0], x[x.length - 1]] });
  setLegend('misweights', dom['legend-misweights'], lines.map((l) => ({
    name: l.name, color: sceneColor(state, l.name), dashed: l.k > 0,
    data: { misweights: l.name, technique: String(l.k) }, parts: [{ text: l.label, className: 'fit' }],
  })));
}

/** The histogram of the weights |f/p| of each estimator's points, on log bins. */
export function renderWeights(state, weights) {
  if (!weights || !weights.estimators.length) {
    drop('weights');
    empty(dom.weights, 'No weights yet.');
    setLegend('weights', dom['legend-weights'], []);
    return;
  }
  const bins = weightBins(weights.estimators.map((e) => e.weight));
  const hs = weights.estimators.map((e) => ({ name: e.name, h: weightHistogram(e.weight, bins) }));
  let same = hs.map(({ name }) => ({ name, of: null, rank: 0 }));
  if (!bins) {
    drop('weights');
    empty(dom.weights, 'Every weight is 0 (or not finite).');
  } else {
    const x = bins.logEdges;
    const data = [x, ...hs.map(({ h }) => [...h.fraction, h.fraction[h.fraction.length - 1]].map((v) => (v > 0 ? Math.log10(v) : null)))];
    const stepped = uPlot.paths.stepped({ align: 1 });
    // identical histograms would hide each other: the later ones dashed over the first
    same = coincidences(hs.map(({ name }, i) => ({ name, y: data[i + 1] })), 1e-9);
    const series = [{}, ...hs.map(({ name }, i) => {
      const color = sceneColor(state, name);
      return { label: name, stroke: color, width: 2, dash: dashOf(same[i].rank), paths: stepped, points: { show: false } };
    })];
    const lowest = Math.floor(Math.log10(1 / Math.max(...hs.map(({ h }) => h.total || 1))));
    draw('weights', dom.weights, JSON.stringify(['weights', hs.map((h) => h.name), same.map((c) => c.rank)]), (c) => ({
      scales: { x: { time: false, range: () => c.xRange }, y: { range: () => c.yRange } },
      axes: [{ ...AXIS, values: log10Ticks, incrs: LOG10_AXIS.incrs, label: '|w| = |f / p|', space: 30 },
        { ...AXIS, ...LOG10_AXIS, label: 'fraction of the points' }],
      series,
      cursor: { drag: { x: false, y: false } },
    }), data, { xRange: [x[0], x[x.length - 1]], yRange: [lowest, 0.15] });
  }
  setLegend('weights', dom['legend-weights'], hs.map(({ name, h }, i) => {
    const parts = [{ text: h.tail === null ? 'max|w| / mean|w| = —' : `max|w| / mean|w| = ${fmt(h.tail, 3)}`, className: 'fit' }];
    if (same[i].of) parts.push(sameText(same[i], 'histogram'));
    if (h.zeros) parts.push({ text: `${h.zeros} zero weights`, className: 'fit' });
    // the first edge may be a fractional power of ten (4 bins per decade)
    if (h.below) parts.push({ text: `${h.below} below ${fmt(10 ** bins.logEdges[0], 2)} (over 12 decades under the largest)`, className: 'fit' });
    if (h.negative) parts.push({ text: `${h.negative} negative`, className: 'fit' });
    if (h.nonFinite) parts.push({ text: `${h.nonFinite} not finite`, className: 'badge' });
    return { name, color: sceneColor(state, name), dashed: same[i].rank > 0,
      data: { weights: name, zeros: String(h.zeros), ...(same[i].of ? { same: same[i].of } : {}) }, parts };
  }));
}
