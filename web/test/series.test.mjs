// Tests of web/src/series.js: plot series from result / level JSON, bands, MSE, slopes,
// z-score histograms, merging the workers' parts. Pure functions under Node's test runner.
import { test } from 'node:test';
import assert from 'node:assert/strict';

import {
  ladder, applyLevel, progressOf, mergeResults, varianceSeries, anchorOf, referenceLines, fitSlope,
  timeSeries, clockResolution, runningEstimate, replayIsEstimator, CLOCK_STEPS_FITTED, zScores, histogram, normalDensity, calibrationSeries, coverageSeries, collectWarnings,
  fixed3, fitText, fmt, decadeRange, splitEstimators, splitRenderWork, splitCollector, partialResult,
} from '../src/series.js';

// A level as the core reports it (docs/result-schema.md), with the fields the plots use.
function lvl(n, over = {}) {
  const variance = 1 / n;
  return {
    n, reps: 4, mean: 1, variance, variance_ci95: [variance / 2, variance * 3], std_error: Math.sqrt(variance / 4),
    mse: variance * 1.5, rmse: Math.sqrt(variance * 1.5), error: Math.sqrt(variance * 1.5), coverage95: 0.75,
    time_mean_s: n * 1e-8, warnings: [], replicates: { estimate: [1, 1, 1, 1], std_error: [1, 1, 1, 1] }, ...over,
  };
}
function record(name, ns, over = {}) {
  return { name, sampler: 'independent', warnings: [], fit: { valid: true, order: -1, order_se: 0.01 }, levels: ns.map((n) => lvl(n)), ...over };
}

test('ladder: the powers of two in [n_min, n_max]', () => {
  assert.deepEqual(ladder(16, 256), [16, 32, 64, 128, 256]);
  assert.deepEqual(ladder(17, 100), [32, 64]);
  assert.deepEqual(ladder(1, 1), [1]);
  assert.deepEqual(ladder(17, 31), []);
  assert.deepEqual(ladder(64, 16), []);
  assert.equal(ladder(16, 2 ** 36).length, 33);
});

test('variance against N: one series per estimator, nulls where it has no level', () => {
  const records = { a: record('a', [16, 32, 64]), b: record('b', [16, 32]) };
  const vs = varianceSeries(records, ['a', 'b', 'missing']);
  assert.equal(vs.quantity, 'variance');
  assert.deepEqual(vs.x, [16, 32, 64]);
  assert.deepEqual(vs.series.map((s) => s.name), ['a', 'b']);
  assert.deepEqual(vs.series[0].y, [1 / 16, 1 / 32, 1 / 64]);
  assert.deepEqual(vs.series[1].y, [1 / 16, 1 / 32, null]);
  // the band is the core's variance_ci95
  assert.deepEqual(vs.series[0].lo, [1 / 32, 1 / 64, 1 / 128]);
  assert.deepEqual(vs.series[0].hi, [3 / 16, 3 / 32, 3 / 64]);
  assert.deepEqual(vs.series[1].hi[2], null);
  // a fixed x (the run's whole ladder) leaves room for the levels still to come
  const wide = varianceSeries(records, ['a'], null, [16, 32, 64, 128]);
  assert.deepEqual(wide.series[0].y, [1 / 16, 1 / 32, 1 / 64, null]);
});

test('MSE instead of variance when the exact value is known; its band scaled alike', () => {
  const records = { a: record('a', [16, 32]) };
  const vs = varianceSeries(records, ['a'], 2.5);
  assert.equal(vs.quantity, 'mse');
  assert.deepEqual(vs.series[0].y, [1.5 / 16, 1.5 / 32]);
  assert.ok(Math.abs(vs.series[0].lo[0] - 1.5 / 32) < 1e-15);
  assert.ok(Math.abs(vs.series[0].hi[0] - 4.5 / 16) < 1e-15);
  assert.equal(varianceSeries(records, ['a'], null).quantity, 'variance');
});

test('values that cannot sit on a log axis become null', () => {
  const r = record('a', [16, 32, 64]);
  r.levels[0] = lvl(16, { variance: 0, mse: 0, variance_ci95: [0, 0] });
  r.levels[1] = lvl(32, { variance: null, variance_ci95: null, mse: null });
  r.levels[2] = lvl(64, { variance: Infinity, variance_ci95: [1, Infinity] });
  const vs = varianceSeries({ a: r }, ['a']);
  assert.deepEqual(vs.series[0].y, [null, null, null]);
  assert.deepEqual(vs.series[0].lo, [null, null, 1]);
  assert.deepEqual(vs.series[0].hi, [null, null, null]);
  // a zero variance with a nonzero MSE (all replicates equal and wrong): no band
  const z = record('z', [16]);
  z.levels[0] = lvl(16, { variance: 0, mse: 0.25, variance_ci95: [0, 0] });
  const ms = varianceSeries({ z }, ['z'], 1);
  assert.deepEqual([ms.series[0].y[0], ms.series[0].lo[0], ms.series[0].hi[0]], [0.25, null, null]);
});

test('fitSlope is exact on power laws and ignores what a log cannot take', () => {
  const xs = [16, 32, 64, 128, 256, 512];
  for (const order of [-1, -1.5, -2, -3, 0.5]) {
    const fit = fitSlope(xs, xs.map((x) => 3.7 * x ** order));
    assert.ok(Math.abs(fit.slope - order) < 1e-12, `slope ${fit.slope} for ${order}`);
    assert.ok(Math.abs(fit.intercept - Math.log(3.7)) < 1e-10);
    assert.equal(fit.n, 6);
  }
  const fit = fitSlope([1, 2, 4, 8, 16], [1, 0, null, 1 / 64, -1]);
  assert.equal(fit.n, 2);
  assert.ok(Math.abs(fit.slope + 2) < 1e-12);
  assert.equal(fitSlope([4, 4, 4], [1, 2, 3]), null, 'one distinct x');
  assert.equal(fitSlope([1], [1]), null);
  // least squares, not two-point: y = x^-1 with one point off
  const noisy = fitSlope([1, 2, 4], [1, 0.5 * Math.E, 0.25]);
  const lx = [0, Math.LN2, 2 * Math.LN2];
  const ly = [0, Math.log(0.5 * Math.E), Math.log(0.25)];
  const mx = (lx[0] + lx[1] + lx[2]) / 3;
  const my = (ly[0] + ly[1] + ly[2]) / 3;
  const slope = lx.reduce((s, x, i) => s + (x - mx) * (ly[i] - my), 0) / lx.reduce((s, x) => s + (x - mx) ** 2, 0);
  assert.ok(Math.abs(noisy.slope - slope) < 1e-12);
});

test('reference slopes start at the first point with the largest y there', () => {
  const x = [16, 32, 64];
  const series = [{ y: [null, 2, 1] }, { y: [null, 8, 4] }];
  const anchor = anchorOf(x, series);
  assert.deepEqual(anchor, { x: 32, y: 8 });
  const refs = referenceLines(x, anchor);
  assert.deepEqual(refs.map((r) => r.order), [-1, -2, -3]);
  assert.deepEqual(refs[0].y, [16, 8, 4]);
  assert.deepEqual(refs[1].y, [32, 8, 2]);
  assert.deepEqual(refs[2].y, [64, 8, 1]);
  for (const r of refs) assert.ok(Math.abs(fitSlope(x, r.y).slope - r.order) < 1e-12);
  assert.equal(anchorOf(x, [{ y: [null, null, null] }]), null);
  assert.deepEqual(referenceLines(x, null), []);
});

test('error against time: aligned on the union of times, points kept in the order of N', () => {
  const a = record('a', [16, 32, 64]);
  a.levels[0].time_mean_s = 5e-6; // slower than the next level (warm-up): not monotone
  a.levels[1].time_mean_s = 2e-6;
  a.levels[2].time_mean_s = 8e-6;
  const b = record('b', [16]);
  b.levels[0].time_mean_s = 2e-6; // same time as a's second point
  b.levels[0].error = 0.5;
  const ts = timeSeries({ a, b }, ['a', 'b']);
  assert.deepEqual(ts.x, [2e-6, 5e-6, 8e-6]);
  assert.deepEqual(ts.series[0].y, [a.levels[1].error, a.levels[0].error, a.levels[2].error]);
  assert.deepEqual(ts.series[1].y, [0.5, null, null]);
  assert.deepEqual(ts.series[0].points.map((p) => p[0]), [5e-6, 2e-6, 8e-6]);
  assert.equal(ts.series[1].slope, null);
  // error ~ t^-1/2 exactly
  const c = record('c', [16, 32, 64, 128]);
  c.levels.forEach((l) => { l.time_mean_s = l.n * 1e-7; l.error = 3 / Math.sqrt(l.n); });
  assert.ok(Math.abs(timeSeries({ c }, ['c']).series[0].slope + 0.5) < 1e-12);
  assert.equal(ts.series[0].trainingShare, null);
  assert.deepEqual(ts.series[0].estimating, []);
  // An adaptive estimator: the estimation-only times, and the mean share of the training.
  const v = record('v', [16, 32]);
  v.levels.forEach((l) => { l.time_mean_s = 4e-6; l.training_time_mean_s = 1e-6; });
  v.levels[1].training_time_mean_s = 3e-6;
  const tv = timeSeries({ v }, ['v']).series[0];
  tv.estimating.forEach(([t], i) => assert.ok(Math.abs(t - [3e-6, 1e-6][i]) < 1e-18, `${t}`));
  // The median seconds are plotted when the core gives them, with their interval as whiskers.
  const m = record('m', [16]);
  Object.assign(m.levels[0], { time_mean_s: 9e-6, time_median_s: 4e-6, time_median_ci95_s: [3e-6, 6e-6] });
  const tm = timeSeries({ m }, ['m']);
  assert.deepEqual(tm.x, [4e-6]);
  assert.deepEqual(tm.series[0].whiskers, [[3e-6, 6e-6, m.levels[0].error]]);
  assert.ok(Math.abs(tv.trainingShare - 0.5) < 1e-12);
});

test('z-scores against the exact value, or each level\'s mean when it is unknown', () => {
  const levels = [
    lvl(16, { mean: 1.5, replicates: { estimate: [1, 2, 3, 2], std_error: [0.5, 0.5, 1, 0] } }),
    lvl(32, { mean: 2, replicates: { estimate: [2.5, 1.5], std_error: [0.25, 0.25] } }),
  ];
  const all = zScores(levels, 2);
  assert.deepEqual(all.z, [-2, 0, 1, 2, -2]);
  assert.equal(all.zeroSe, 1, 'a zero error bar is counted, not divided by');
  assert.equal(all.reference, 'exact');
  assert.deepEqual(zScores(levels, 2, 32).z, [2, -2]);
  const mean = zScores(levels, null, 16);
  assert.deepEqual(mean.z, [-1, 1, 1.5]);
  assert.equal(mean.reference, 'mean');
  // A level exact to round-off gives no z (round-off over round-off), only a count.
  const exact = [lvl(64, { mean: 2, mse: 0, exact_to_roundoff: true, replicates: { estimate: [2, 2, 2], std_error: [1e-16, 2e-16, 1e-16] } }), ...levels];
  const withExact = zScores(exact, 2);
  assert.deepEqual(withExact.z, all.z);
  assert.equal(withExact.exactRuns, 3);
});

test('histogram: counts per bin, a density that integrates to the share inside, outliers apart', () => {
  const h = histogram([-5, -0.25, 0, 0.1, 0.49, 0.5, 4.99, 5, -7, NaN], { lo: -5, hi: 5, width: 0.5 });
  assert.equal(h.edges.length, 21);
  assert.equal(h.edges[0], -5);
  assert.equal(h.edges[10], 0);
  assert.equal(h.total, 9, 'NaN is dropped');
  assert.equal(h.below, 1);
  assert.equal(h.above, 1);
  assert.equal(h.counts[0], 1);  // -5
  assert.equal(h.counts[9], 1);  // -0.25
  assert.equal(h.counts[10], 3); // 0, 0.1, 0.49
  assert.equal(h.counts[11], 1); // 0.5
  assert.equal(h.counts[19], 1); // 4.99
  const area = h.density.reduce((s, d) => s + d * 0.5, 0);
  assert.ok(Math.abs(area - 7 / 9) < 1e-12);
  assert.deepEqual(histogram([]).density.every((d) => d === 0), true);
});

test('the calibration plot: a step histogram per estimator against N(0, 1)', () => {
  assert.ok(Math.abs(normalDensity(0) - 1 / Math.sqrt(2 * Math.PI)) < 1e-15);
  const r = record('a', [16]);
  r.levels[0].replicates = { estimate: [1.25, 0.75, 1.1, 1.0], std_error: [1, 1, 1, 1] }; // z = 0.25, -0.25, 0.1, 0
  const cs = calibrationSeries({ a: r }, ['a'], 1);
  assert.equal(cs.x.length, 101);
  assert.equal(cs.x[50], 0);
  assert.equal(cs.normal[50], normalDensity(0));
  const s = cs.series[0];
  assert.equal(s.total, 4);
  assert.equal(s.within2, 4);
  // bin [-0.5, 0) holds one of 4, bin [0, 0.5) three: densities 0.5 and 1.5
  assert.equal(s.y[cs.x.indexOf(-0.5)], 0.5);
  assert.equal(s.y[cs.x.indexOf(-0.1)], 0.5);
  assert.equal(s.y[cs.x.indexOf(0)], 1.5);
  assert.equal(s.y[cs.x.indexOf(0.4)], 1.5);
  assert.equal(s.y[cs.x.indexOf(0.5)], 0);
});

test('coverage against N', () => {
  const r = record('a', [16, 32]);
  r.levels[1].coverage95 = null;
  const cs = coverageSeries({ a: r }, ['a'], [16, 32, 64]);
  assert.deepEqual(cs.series[0].y, [0.75, null, null]);
});

test('levels stream into records; progress is weighted by N', () => {
  const meta = (name, n) => ({ name, sampler: 'stratified', warnings: [], fit: { valid: n > 16, order: -2 }, level: lvl(n) });
  let rec = applyLevel({}, { level_index: 0, n: 16, estimators: [meta('a', 16), meta('b', 16)] });
  assert.deepEqual(Object.keys(rec), ['a', 'b']);
  assert.deepEqual(rec.a.levels.map((l) => l.n), [16]);
  assert.equal(rec.a.level, undefined);
  const before = rec;
  rec = applyLevel(rec, { level_index: 1, n: 32, estimators: [meta('a', 32)] });
  assert.deepEqual(before.a.levels.map((l) => l.n), [16], 'the old records are not changed');
  assert.deepEqual(rec.a.levels.map((l) => l.n), [16, 32]);
  assert.equal(rec.a.fit.valid, true, 'the latest fit');
  rec = applyLevel(rec, { level_index: 1, n: 32, estimators: [meta('a', 32)] });
  assert.equal(rec.a.levels.length, 2, 'a repeated level replaces');
  const lad = ladder(16, 64);
  assert.ok(Math.abs(progressOf(rec, ['a', 'b'], lad) - (48 + 16) / (2 * 112)) < 1e-12);
  assert.equal(progressOf({}, [], lad), 0);
});

function part(names, over = {}) {
  return {
    cancelled: false,
    estimators: names.map((n) => record(n, [16, 32])),
    mcplay: '0.1.0',
    scene: { name: 'disk_third', exact: 1 / 9 },
    settings: { accumulator: 'compensated', n_max: 32, n_min: 16, reps: 4, seed: 1, threads: 1 },
    version: 1,
    wall_time_s: 0.5,
    ...over,
  };
}

test('merging the workers\' results: the scene\'s order, threads summed, the longest wall time', () => {
  const merged = mergeResults([part(['b', 'd']), part(['a', 'c'], { wall_time_s: 0.75 })], ['a', 'b', 'c', 'd']);
  assert.deepEqual(merged.estimators.map((e) => e.name), ['a', 'b', 'c', 'd']);
  assert.equal(merged.settings.threads, 2);
  assert.equal(merged.wall_time_s, 0.75);
  assert.equal(merged.cancelled, false);
  assert.deepEqual(merged.scene, part([]).scene);
  assert.deepEqual(Object.keys(merged), Object.keys(part([])), 'the same fields as a result');
  // one part: the result itself (but for threads)
  assert.deepEqual(mergeResults([part(['a'])]), part(['a']));
  // names missing from `order` come last; a cancelled part cancels the whole
  const m2 = mergeResults([part(['x']), part(['a'], { cancelled: true })], ['a']);
  assert.deepEqual(m2.estimators.map((e) => e.name), ['a', 'x']);
  assert.equal(m2.cancelled, true);
});

test('merging refuses parts of different studies and duplicate estimators', () => {
  assert.throws(() => mergeResults([]), /no results/);
  assert.throws(() => mergeResults([part(['a']), part(['b'], { settings: { ...part([]).settings, seed: 2 } })]), /different studies/);
  assert.throws(() => mergeResults([part(['a']), part(['b'], { scene: { name: 'other' } })]), /different studies/);
  assert.throws(() => mergeResults([part(['a']), part(['a'])]), /'a' is in two parts/);
});

test('splitting the estimators over workers: round robin, never an empty group', () => {
  assert.deepEqual(splitEstimators(['a', 'b', 'c', 'd', 'e'], 2), [['a', 'c', 'e'], ['b', 'd']]);
  assert.deepEqual(splitEstimators(['a', 'b'], 8), [['a'], ['b']]);
  assert.deepEqual(splitEstimators(['a'], 0), [['a']]);
  assert.deepEqual(splitEstimators([], 4), []);
  const names = ['u', 'v', 'w', 'x', 'y', 'z', 'q'];
  for (let k = 1; k <= 8; k++) assert.deepEqual(splitEstimators(names, k).flat().sort(), [...names].sort());
});

test('render work: groups of estimators while they fill the workers, else replicates split', () => {
  assert.deepEqual(splitRenderWork(['a', 'b', 'c'], 2, 4), [
    { estimators: ['a', 'c'], part: 0, parts: 1 }, { estimators: ['b'], part: 0, parts: 1 }]);
  assert.deepEqual(splitRenderWork(['a'], 4, 8).map((g) => [g.estimators[0], g.part, g.parts]),
    [['a', 0, 4], ['a', 1, 4], ['a', 2, 4], ['a', 3, 4]]);
  // never more parts than replicates, and every estimator gets its share of the workers
  assert.deepEqual(splitRenderWork(['a'], 8, 3).map((g) => g.part), [0, 1, 2]);
  assert.deepEqual(splitRenderWork(['a', 'b'], 5, 4).map((g) => `${g.estimators[0]}${g.part}/${g.parts}`),
    ['a0/2', 'a1/2', 'b0/2', 'b1/2']);
  assert.equal(splitRenderWork(['a'], 1, 4)[0].parts, 1);
});

test('a split estimator\'s parts: whole levels in order once every part has them, then the result', async () => {
  const merges = [];
  const got = [];
  // a fake merge: the levels' images concatenated, as the render core's merge gathers them
  const merge = async (parts) => {
    merges.push(parts);
    await new Promise((r) => setTimeout(r, parts.length));
    const e0 = parts[0].estimators[0];
    return { ...parts[0], estimators: [{ ...e0, levels: e0.levels.map((l, i) => ({ n: l.n, images: parts.flatMap((p) => p.estimators[0].levels[i].images) })) }] };
  };
  const c = splitCollector({ parts: 2, merge, onLevel: (line) => got.push(['level', line]), onResult: (r) => got.push(['result', r]) });
  const line = (part, index) => ({ kind: 'render', level_index: index, n: 2 ** index, part: { index: part, of: 2 },
    estimators: [{ name: 'a', fit: {}, level: { n: 2 ** index, images: [`${part}:${index}`] } }] });
  c.level(0, { kind: 'render_reference', rows_done: 1, rows: 8 }); // not a level
  c.level(0, line(0, 0));
  c.level(0, line(0, 1));
  assert.equal(merges.length, 0); // part 1 has no level yet
  c.level(1, line(1, 0));
  c.level(1, line(1, 1));
  c.result(1, { estimators: [{ name: 'a', levels: [] }], part: { index: 1, of: 2 } });
  c.result(0, { estimators: [{ name: 'a', levels: [] }], part: { index: 0, of: 2 } });
  await c.settled();
  assert.deepEqual(got.map(([k, x]) => (k === 'level' ? `${k}${x.estimators[0].level.n}:${x.estimators[0].level.images}` : k)),
    ['level1:0:0,1:0', 'level2:0:1,1:1', 'result']);
  // each level's merge sees every level so far of every part, as a result with levels
  assert.equal(merges[1][0].estimators[0].levels.length, 2);
  assert.equal(merges[1][0].estimators[0].level, undefined);
  const failed = [];
  const bad = splitCollector({ parts: 1, merge: async () => { throw new Error('no'); }, onLevel: () => {}, onResult: () => {}, onError: (e) => failed.push(e.message) });
  bad.level(0, line(0, 0));
  bad.result(0, {});
  await bad.settled();
  assert.deepEqual(failed, ['no']);
});

test('a cancelled run exports the streamed levels as a result', () => {
  const run = {
    status: 'cancelled', settings: { n_min: 16, n_max: 64, reps: 4, seed: 1 }, workers: 2, elapsed: 250,
    order: ['a', 'b', 'c'], records: { a: record('a', [16]), c: record('c', [16, 32]) }, sceneName: 'x',
  };
  const r = partialResult(run, { name: 'x', description: 'd', domain: 'box', dimension: 1, exact: null, estimators: ['a'] }, '0.1.0');
  assert.equal(r.cancelled, true);
  assert.equal(r.wall_time_s, 0.25);
  assert.equal(r.settings.threads, 2);
  assert.deepEqual(r.estimators.map((e) => e.name), ['a', 'c']);
  assert.deepEqual(r.scene, { name: 'x', description: 'd', domain: 'box', dimension: 1, exact: null });
});

test('warnings grouped per estimator and code, level flags with their N, errors first', () => {
  const a = record('a', [16, 32, 64], { warnings: [{ code: 'heavy_tail', severity: 'warning', message: 'tail index 1.4' }] });
  a.levels[0].warnings = [{ code: 'low_ess', severity: 'warning', message: 'ess 2 at N = 16' }];
  a.levels[1].warnings = [{ code: 'low_ess', severity: 'warning', message: 'ess 3 at N = 32' }, { code: 'skewed_weights', message: 'skewness 40' }];
  const b = record('b', [16], { warnings: [{ code: 'heavy_tail_4', severity: 'info', message: 'tail index 3' }] });
  b.levels[0].warnings = [{ code: 'exact_outside_ci', severity: 'error', message: 'misses' }];
  const w = collectWarnings({ a, b }, ['a', 'b']);
  assert.deepEqual(w, [
    { estimator: 'b', scope: 'level', severity: 'error', code: 'exact_outside_ci', message: 'misses', n: [16] },
    { estimator: 'a', scope: 'estimator', severity: 'warning', code: 'heavy_tail', message: 'tail index 1.4', n: [] },
    { estimator: 'a', scope: 'level', severity: 'warning', code: 'low_ess', message: 'ess 2 at N = 16', n: [16, 32] },
    // no severity (a result from before severities): shown as a warning
    { estimator: 'a', scope: 'level', severity: 'warning', code: 'skewed_weights', message: 'skewness 40', n: [32] },
    { estimator: 'b', scope: 'estimator', severity: 'info', code: 'heavy_tail_4', message: 'tail index 3', n: [] },
  ]);
});

test('the fitted order is printed as the CLI prints it (%.3f)', () => {
  assert.equal(fitText({ valid: true, order: -1.04049, order_se: 0.02751 }), '-1.040 ± 0.028');
  assert.equal(fitText({ valid: true, order: -0.978, order_se: null }), '-0.978');
  assert.equal(fitText({ valid: false, order: null, note: 'fewer than 3 levels with a variance: no fit' }),
    'no fit (fewer than 3 levels with a variance: no fit)');
  assert.equal(fitText(null), 'no fit yet');
  // printf rounds exact binary ties to even, toFixed away from zero
  assert.equal(fixed3(1.0625), '1.062');
  assert.equal(fixed3(-1.0625), '-1.062');
  assert.equal(fixed3(0.1875), '0.188');
  assert.equal(fixed3(2.0015625), '2.002');
  assert.equal(fixed3(0.0005), '0.001', '0.0005 is a little above the tie in binary');
  assert.equal(fixed3(-0.0001), '-0.000');
  assert.equal(fixed3(-0), '-0.000');
  assert.equal(fixed3(12.3456), '12.346');
});

test('fmt and decadeRange', () => {
  assert.equal(fmt(null), '—');
  assert.equal(fmt(0), '0');
  assert.equal(fmt(0.123456), '0.1235');
  assert.equal(fmt(1.5e-7), '1.500e-7');
  assert.equal(fmt(123456789), '1.235e+8');
  assert.deepEqual(decadeRange([3e-5, 0.02, null, 0, -1]), [1e-5, 0.1]);
  assert.deepEqual(decadeRange([1e-3]), [1e-4, 1e-2]);
  assert.deepEqual(decadeRange([]), [1e-6, 1]);
});

// ---------------------------------------------------------------------------------------------
// Sample points: overlay normalisation, weight histograms, summaries, disk maps

import {
  trapezoidAbs, normalizeCurve, curveOverlay, weightBins, weightHistogram, samplesSummary, domainView,
  mapFor, DISK_MAPS, misWeightCurves,
} from '../src/series.js';

test('normalizeCurve: f divided by the trapezoid integral of |f|', () => {
  const x = [0, 0.5, 1];
  assert.equal(trapezoidAbs(x, [1, 1, 1]), 1);
  assert.equal(trapezoidAbs(x, [-2, -2, -2]), 2);
  const { y, area } = normalizeCurve(x, [0, 2, 0]);
  assert.equal(area, 1);
  assert.deepEqual(y, [0, 2, 0]);
  assert.deepEqual(normalizeCurve(x, [0, 0, 0]).y, [null, null, null]);
});

test('curveOverlay: pdfs in order, exact integral for a singular f >= 0, clipped range', () => {
  const x = Array.from({ length: 11 }, (_, i) => i / 10);
  const curve = { x, f: x.map(() => 3), pdf: { b: x.map(() => 1), a: x.map(() => 1) } };
  const ov = curveOverlay(curve, ['a', 'b', 'missing']);
  assert.deepEqual(ov.pdfs.map((p) => p.name), ['a', 'b']);
  assert.ok(ov.f.every((v) => Math.abs(v - 1) < 1e-12));
  assert.equal(ov.areaFrom, 'trapezoid');
  assert.equal(ov.clipped, false);
  const spike = { x, f: x.map((v, i) => (i === 0 ? 1000 : 1)), pdf: {} };
  const s = curveOverlay(spike, [], { exact: 50 });
  assert.equal(s.areaFrom, 'exact');
  assert.equal(s.area, 50);
  assert.equal(s.clipped, true);
  assert.ok(s.yRange[1] < 1000 / 50);
  assert.equal(curveOverlay(null, []), null);
});

test('misWeightCurves: one line per technique of each MIS estimator, in order, labelled', () => {
  const samples = {
    curve: { x: [0, 1], mis_weights: { b: [[0.2, NaN], [0.8, 1]], a: [[1, 0]] } },
    estimators: [{ name: 'a' }, { name: 'b', techniques: [{ pdf: 'gaussian', share: 0.25 }, { pdf: 'uniform', share: 0.75 }] }],
  };
  const lines = misWeightCurves(samples, ['a', 'b', 'c']);
  assert.deepEqual(lines.map((l) => [l.name, l.k, l.label]),
    [['a', 0, 'technique 1'], ['b', 0, 'gaussian (0.25)'], ['b', 1, 'uniform (0.75)']]);
  assert.deepEqual(lines[1].y, [0.2, null]);
  assert.deepEqual(misWeightCurves({ curve: { x: [0] } }, ['a']), []);
  assert.deepEqual(misWeightCurves(null, ['a']), []);
});

test('weight histograms: log bins of |w|, zeros and non-finite apart, tail ratio', () => {
  const w = [0, 0, 1, 1.5, 10, -100, 1e-20, Infinity];
  const bins = weightBins([w], { binsPerDecade: 1, maxDecades: 5 });
  assert.deepEqual(bins.logEdges, [-2, -1, 0, 1, 2, 3]); // 100 lies in [10^2, 10^3)
  const h = weightHistogram(w, bins);
  assert.equal(h.zeros, 2);
  assert.equal(h.nonFinite, 1);
  assert.equal(h.below, 1);
  assert.equal(h.negative, 1);
  assert.deepEqual(h.counts, [0, 0, 2, 1, 1]);
  assert.equal(h.counts.reduce((a, b) => a + b) + h.zeros + h.nonFinite + h.below, w.length);
  assert.equal(h.total, 8);
  assert.equal(h.maxAbs, 100);
  assert.ok(Math.abs(h.tail - 100 / ((1 + 1.5 + 10 + 100 + 1e-20) / 7)) < 1e-9);
  assert.equal(weightBins([[0, 0]]), null);
  assert.equal(weightHistogram([0, 0], null).zeros, 2);
});

test('samplesSummary and domainView', () => {
  const e = { name: 'a', sampler: 'stratified', strata: [2, 2], samples_per_stratum: 1, u: [[0.1, 0.9], [0.2, 0.7]], x: [[0.1, 0.9], [0.2, 0.7]] };
  const smp = { n: 2, seed: 3, domain: 'box', dimension: 2, estimators: [e] };
  assert.deepEqual(samplesSummary(smp).estimators[0], { name: 'a', sampler: 'stratified', points: 2, strata: [2, 2], samplesPerStratum: 1, mapIncrements: 0, boxes: 0, mapHistory: 0, runN: 2 });
  // adaptive estimators: VEGAS's map edges (K + 1 per axis) and MISER's leaf boxes
  const vegas = { ...e, name: 'v', strata: [], map_edges: [[0, 0.2, 1], [0, 0.5, 1]], run_n: 64,
    map_history: [[[0, 0.5, 1], [0, 0.5, 1]], [[0, 0.2, 1], [0, 0.5, 1]]] };
  const miser = { ...e, name: 'm', strata: [], boxes: { lo: [[0, 0], [0.5, 0]], hi: [[0.5, 1], [1, 1]] } };
  const s2 = samplesSummary({ ...smp, estimators: [vegas, miser] });
  assert.equal(s2.estimators[0].mapIncrements, 2);
  assert.equal(s2.estimators[0].mapHistory, 2);
  assert.equal(s2.estimators[0].runN, 64);
  assert.equal(s2.estimators[1].boxes, 2);
  assert.deepEqual(domainView(smp).xRange, [0, 1]);
  assert.match(domainView({ ...smp, dimension: 5 }).note, /axes 1 and 2 of 5/);
  assert.equal(domainView({ ...smp, domain: 'disk' }, { center: [1, 0], radius: 2 }).outline.r, 2);
  assert.match(domainView({ ...smp, domain: 'hemisphere', dimension: 3 }).note, /projected/);
  assert.deepEqual(domainView({ ...smp, dimension: 1, curve: { x: [0.1, 0.9] } }, { type: 'interval', lower: -1, upper: 2 }).xRange, [-1, 2]);
});

test('mapFor: recognises the disk map that produced the points, and only that', () => {
  const u = [[0.1, 0.6, 0.95], [0.3, 0.5, 0.05]];
  for (const name of ['polar', 'concentric']) {
    const pts = u[0].map((_, i) => DISK_MAPS[name]([u[0][i], u[1][i]]));
    const e = { u, x: [pts.map((p) => 2 * p[0] + 1), pts.map((p) => 2 * p[1])] };
    assert.equal(mapFor(e, { center: [1, 0], radius: 2 }).name, name);
  }
  assert.equal(mapFor({ u, x: [[0, 0, 0], [0, 0, 0]] }), null);
});

// ---------------------------------------------------------------------------------------------
// Render results (kind "render": N is spp, a level's variance its relative MSE)

function renderPart(names, { seconds = 0.3, luminance = 0.5, threads = 1, cancelled = false } = {}) {
  return {
    version: 1, kind: 'render', mcplay: '0.1.0', reference_png: 'REF',
    scene: { name: 'q', kind: 'render', width: 16, height: 16, exact: luminance, reference: { spp: 256, seconds, mean_luminance: luminance, source: 'rendered' } },
    settings: { n_min: 1, n_max: 4, reps: 2, seed: 1, threads, n_name: 'spp', error_name: 'relative_mse' },
    cancelled, wall_time_s: seconds + 0.1,
    estimators: names.map((name) => record(name, [1, 2, 4])),
  };
}

test('render parts merge although each worker timed its own reference; other references do not', () => {
  const m = mergeResults([renderPart(['b'], { seconds: 0.2 }), renderPart(['a'], { seconds: 0.4 })], ['a', 'b']);
  assert.equal(m.kind, 'render');
  assert.deepEqual(m.estimators.map((e) => e.name), ['a', 'b']);
  assert.equal(m.reference_png, 'REF');
  assert.equal(m.settings.threads, 2);
  assert.equal(m.settings.n_name, 'spp');
  assert.ok(Math.abs(m.wall_time_s - 0.5) < 1e-12);
  assert.throws(() => mergeResults([renderPart(['a']), renderPart(['b'], { luminance: 0.6 })]), /different studies/);
  const other = renderPart(['b']);
  other.settings.n_max = 8;
  assert.throws(() => mergeResults([renderPart(['a']), other]), /different studies/);
});

test('render series: relative MSE against spp with one reference slope, error against time per image', () => {
  const records = { a: record('a', [1, 2, 4]), b: record('b', [1, 2]) };
  const vs = varianceSeries(records, ['a', 'b'], null, ladder(1, 4));
  assert.equal(vs.quantity, 'variance');
  assert.deepEqual(vs.x, [1, 2, 4]);
  assert.deepEqual(vs.series[0].y, [1, 0.5, 0.25]);
  assert.deepEqual(vs.series[1].y, [1, 0.5, null]);
  const refs = referenceLines(vs.x, anchorOf(vs.x, vs.series), [1]);
  assert.equal(refs.length, 1);
  assert.deepEqual(refs[0].y, [1, 0.5, 0.25]);
  const ts = timeSeries(records, ['a']);
  assert.deepEqual(ts.series[0].points.map(([t]) => t), [1e-8, 2e-8, 4e-8]);
  assert.ok(Math.abs(ts.series[0].slope + 0.5) < 1e-12, 'RMSE ∝ t^-1/2 when relative MSE ∝ 1/spp');
});

test('a cancelled render run exports its streamed levels with the render names', () => {
  const run = {
    kind: 'render', nName: 'spp', errorName: 'relative_mse', sceneName: 'q', settings: { n_min: 1, n_max: 4, reps: 2, seed: 1, width: 16, height: 16 },
    workers: 2, status: 'cancelled', elapsed: 1500, order: ['a', 'b'], records: { a: record('a', [1]) }, referencePng: null,
  };
  const info = { name: 'q', description: 'd', kind: 'render', width: 48, height: 48, triangles: 4, lights: 2, accel: { kind: 'bvh' }, warnings: [] };
  const r = partialResult(run, info, '0.1.0');
  assert.equal(r.kind, 'render');
  assert.equal(r.cancelled, true);
  assert.deepEqual([r.scene.kind, r.scene.width, r.scene.height, r.scene.triangles], ['render', 16, 16, 4]);
  assert.deepEqual([r.settings.n_name, r.settings.error_name, r.settings.threads], ['spp', 'relative_mse', 2]);
  assert.deepEqual(r.estimators.map((e) => e.name), ['a']);
  assert.equal(r.wall_time_s, 1.5);
  assert.equal('reference_png' in r, false);
  // an integration run's export is unchanged: no kind
  assert.equal('kind' in partialResult({ ...run, kind: 'integral' }, { name: 'q' }), false);
});

test('nText collapses the N of a diagnostic', async () => {
  const { nText } = await import('../src/series.js');
  const steps = [16, 32, 64, 128, 256];
  assert.equal(nText([16, 32, 64, 128, 256], steps), 'every N, 16 … 256');
  assert.equal(nText([32, 64, 128], steps), 'N = 32 … 128 (3 levels)');
  assert.equal(nText([16, 64], steps), 'N = 16, 64');
  assert.equal(nText([64], steps), 'N = 64');
  assert.equal(nText([1, 2, 4], [1, 2, 4], 'spp'), 'every spp, 1 … 4');
  assert.equal(nText([], steps), '');
});

test('samplesCsv: one row per point, u and x per coordinate, f, density and weight', async () => {
  const { samplesCsv } = await import('../src/series.js');
  const samples = { n: 2, estimators: [
    { name: 'uniform', u: [[0.1, 0.6], [0.2, 0.7]], x: [[0.1, 0.6], [0.2, 0.7]], f: [1, 2], density: [1, 1], weight: [1, 2] },
    { name: 'is,odd', u: [[0.5, 0.25]], x: [[0.5, 0.25]], f: [3, 4], density: [2, 0.5], weight: [1.5, 8] },
  ] };
  const lines = samplesCsv(samples).trim().split('\n');
  assert.equal(lines[0], 'estimator,i,u1,u2,x1,x2,f,density,weight');
  assert.equal(lines[1], 'uniform,0,0.1,0.2,0.1,0.2,1,1,1');
  assert.equal(lines[3], '"is,odd",0,0.5,,0.5,,3,2,1.5');
  assert.equal(lines.length, 5);
  assert.equal(samplesCsv(null), '');
});

test('the clock step is the smallest advance of the clock, and times under 20 steps are not fitted', () => {
  // A clock that rounds to 5 us (0.005 ms) and advances 1.3 us per reading.
  let t = 0;
  const coarse = () => { t += 0.0013; return Math.floor(t / 0.005) * 0.005; };
  assert.ok(Math.abs(clockResolution(coarse) - 0.005) < 1e-12);
  assert.equal(clockResolution(() => 7, 1), null, 'a clock that never moves');
  // error = t^-0.5 above the floor; below it, quantized times that would bend the fit.
  const floor = CLOCK_STEPS_FITTED * 5e-6;
  const levels = [[5e-6, 1e-1], [5e-6, 5e-2], [1e-5, 3e-2], [2e-4, 2e-4 ** -0.5], [8e-4, 8e-4 ** -0.5], [3.2e-3, 3.2e-3 ** -0.5]]
    .map(([s, e], i) => ({ n: 16 << i, time_median_s: s, error: e }));
  const records = { a: { name: 'a', levels } };
  const fitted = timeSeries(records, ['a'], floor).series[0];
  assert.ok(Math.abs(fitted.slope + 0.5) < 1e-9, `slope ${fitted.slope}`);
  assert.equal(fitted.fitted, 3);
  assert.equal(fitted.untimed, 3);
  assert.equal(fitted.points.length, 6, 'every point is still drawn');
  const all = timeSeries(records, ['a']).series[0];
  assert.ok(Math.abs(all.slope + 0.5) > 0.05, `without the floor the quantized points bend the slope: ${all.slope}`);
  const none = timeSeries(records, ['a'], 1).series[0];
  assert.equal(none.slope, null);
  assert.equal(none.untimed, 6);
});

test('the running estimate is the mean of the first k weights, with a t-free 95% interval', () => {
  const w = [3, 1, 2, 6, NaN, 4];
  const r = runningEstimate(w);
  assert.deepEqual(r.mean.slice(0, 4), [3, 2, 2, 3]);
  assert.equal(r.lo[0], null, 'no interval from one point');
  // k = 4: s^2 = ((0)^2 + (-2)^2 + (-1)^2 + 3^2) / 3 = 14/3 around the mean 3
  assert.ok(Math.abs(r.hi[3] - (3 + 1.959963984540054 * Math.sqrt(14 / 3 / 4))) < 1e-12);
  assert.equal(r.mean[4], null, 'a non-finite weight is skipped');
  assert.equal(r.mean[5], 16 / 5);
  // Coverage of the final interval over independent uniform sets (fixed seed): about 95%.
  let seed = 12345;
  const rand = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648);
  let covered = 0;
  const sets = 400;
  for (let s = 0; s < sets; ++s) {
    const x = Array.from({ length: 256 }, () => Math.exp(rand()));
    const e = runningEstimate(x);
    if (e.lo[255] <= Math.E - 1 && Math.E - 1 <= e.hi[255]) covered += 1;
  }
  // binomial: 0.95 +- 4 standard errors of 400 sets
  assert.ok(Math.abs(covered / sets - 0.95) < 4 * Math.sqrt(0.95 * 0.05 / sets), `${covered} of ${sets}`);
});

test('replaying the first k points is the estimator when the core says so', () => {
  assert.equal(replayIsEstimator({ sampler: 'independent', replay_is_estimate: true }), true);
  assert.equal(replayIsEstimator({ sampler: 'stratified', strata: [16, 16], replay_is_estimate: false }), false);
  // no knowledge of samplers or maps here: without the core's word, no band
  assert.equal(replayIsEstimator({ sampler: 'independent', strata: [] }), false);
  assert.equal(replayIsEstimator({ sampler: 'vegas', map_edges: [[0, 1]] }), false);
  assert.equal(replayIsEstimator(undefined), false);
});

test('a box of d > 2 axes is shown on the chosen pair of axes', () => {
  const samples = { domain: 'box', dimension: 4, estimators: [{ x: [[0.1], [0.2], [2.5], [0.4]] }] };
  const v = domainView(samples, null, [2, 3]);
  assert.deepEqual(v.axes, [2, 3]);
  assert.deepEqual(v.labels, ['x3', 'x4']);
  assert.match(v.note, /axes 3 and 4 of 4/);
  assert.deepEqual(domainView(samples, null, [1, 1]).axes, [0, 1], 'a pair of one axis twice falls back');
  assert.deepEqual(domainView(samples, null, [0, 9]).axes, [0, 1]);
});

