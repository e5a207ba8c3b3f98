// The page's claims (web/src/claims/) against result JSON where each claim is false as well as
// where it is true. Fixtures: web/test/fixtures/claims/*.json, CLI results trimmed by trim.py
// (commands in fixtures/claims/README.md); synthetic records where a case needs one property.
import test from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';
import {
  levelExactness, recordExactness, orderClaim, conservativeClaim, coverageText, coincidentGroups,
  coincidentNote, withinText, alarmSummary, flagPersistence, equalTimeClaim, seLogMse, timeSlopeClaim,
  varianceNote, timeNote, legendLines, FLAG_WORDS, flagTitle, flagShort, pWords, tailWords, densityWords,
  methodWords, inputErrorWords, chi2Sf, trigamma, fitLine, infiniteVariance, fixedCost, tailText,
  relativeMseText, atReferenceNoise, referenceNoiseWords, referenceFloorOf,
} from '../src/claims.js';
import { collectWarnings, calibrationSeries, coverageSeries, varianceSeries, zScores } from '../src/series.js';

const here = dirname(fileURLToPath(import.meta.url));
function fixture(name) {
  const d = JSON.parse(readFileSync(join(here, 'fixtures', 'claims', `${name}.json`), 'utf8'));
  const records = Object.fromEntries(d.estimators.map((e) => [e.name, e]));
  return { exact: d.scene.exact, reps: d.settings.reps, records, order: d.estimators.map((e) => e.name),
    ladder: d.estimators[0].levels.map((l) => l.n) };
}
const stiff = fixture('stiff_peak_1e-8');
const singular = fixture('singular_power_0.9');
const diskThird = fixture('disk_third');
const diskQuarter = fixture('disk_quarter');
const vegasCorner = fixture('vegas_corner_peak');
const exp1d = fixture('exp_1d');

// ---------------------------------------------------------------------------------------------
// 1. Exact: agreement is not exactness.

test('levelExactness: replicates that agree on a wrong value are not exact', () => {
  const exact = 2.5066282746310004e-8;
  // The case: every replicate 0 for a nonzero integral, flagged as agreeing to round-off.
  assert.equal(levelExactness({ exact_to_roundoff: true, mean: 0, variance: 0, mse: 6.283e-16 }, exact), 'no');
  assert.equal(levelExactness({ exact_to_roundoff: true, mean: 7e-215, values_underflow: true }, exact), 'no');
  assert.equal(levelExactness({ exact_to_roundoff: true, mean: 1.0000001 }, 1), 'no', 'off by 1e-7');
  assert.equal(levelExactness({ exact_to_roundoff: true, mean: 1, no_estimate_runs: 2 }, 1), 'no');
  assert.equal(levelExactness({ exact_to_roundoff: false, mean: 1, variance: 0 }, 1), 'no');
  // True where it holds: a matched pdf on the stiff peak equals the exact value at every N.
  const matched = stiff.records.importance_matched;
  assert.ok(matched.levels.length >= 10);
  for (const l of matched.levels) assert.equal(levelExactness(l, stiff.exact), 'exact', `N = ${l.n}`);
  assert.equal(recordExactness(matched, stiff.exact).all, 'exact');
  // disk_quarter's exact estimators too, at every N
  const exactOnes = diskQuarter.order.filter((n) => recordExactness(diskQuarter.records[n], diskQuarter.exact).all === 'exact');
  assert.ok(exactOnes.length >= 1, 'disk_quarter has an exact estimator');
});

test('levelExactness: without the exact value, agreement is only agreement', () => {
  const l = { exact_to_roundoff: true, mean: 0.5, variance: 0 };
  assert.equal(levelExactness(l, null), 'agree');
  assert.equal(levelExactness({ ...l, deterministic: true }, null), 'agree');
  const c = orderClaim({ levels: [l, { ...l, n: 32 }], fit: { valid: false } }, { exact: null });
  assert.doesNotMatch(c.text, /\bexact\b/);
  assert.match(c.text, /zero spread/);
});

test('the stiff peak: uniform is never called exact, in the series, the plots or the verdict', () => {
  const vs = varianceSeries(stiff.records, stiff.order, stiff.exact);
  const uniform = vs.series.find((s) => s.name === 'uniform');
  assert.equal(uniform.exact, null);
  assert.ok(uniform.exactAt.every((k) => k === false), 'no exact mark for uniform');
  const matched = vs.series.find((s) => s.name === 'importance_matched');
  assert.equal(matched.exact, 'exact');
  // Forge the core: uniform's levels flagged exact_to_roundoff (mean 0, MSE > 0).
  const forged = structuredClone(stiff.records);
  for (const l of forged.uniform.levels) l.exact_to_roundoff = true;
  const v = equalTimeClaim(forged, ['uniform', 'importance_matched'], { exact: stiff.exact, floorSeconds: 0 });
  assert.doesNotMatch(v.text, /uniform (and \w+ )?(is|are) exact/);
  assert.equal(v.winner, 'importance_matched');
  assert.match(v.text, /^importance_matched is exact at every N \(every replicate equals the exact value/);
  const forgedSeries = varianceSeries(forged, ['uniform'], stiff.exact).series[0];
  assert.ok(forgedSeries.exactAt.every((k) => k === false));
  assert.ok(forgedSeries.y.every((y) => y > 0), 'its MSE is plotted');
  // z: uniform's zero error bars with a wrong answer are counted, not taken for exact runs
  const zs = zScores(forged.uniform.levels, stiff.exact);
  assert.equal(zs.exactRuns, 0);
  assert.ok(zs.zeroSe > 0);
});

// ---------------------------------------------------------------------------------------------
// 2. Orders: a slope only where a power law holds.

function ladderFit(orders, { p, suffix = null, order = -1, se = 0.03 } = {}) {
  return { valid: true, order, order_se: se, p_value: p, n_first: 16, n_last: 65536, suffix };
}

test('orderClaim: a curve that goes up and down has no order', () => {
  const r = { levels: [{ n: 16 }], warnings: [], fit: ladderFit(null, { p: 7e-95, order: -4.317, se: 0.667 }) };
  const c = orderClaim(r);
  assert.equal(c.number, null);
  assert.doesNotMatch(c.text, /4\.3/);
  assert.match(c.text, /no power law/);
  assert.match(c.text, /p = 7\.0e-95/);
  // with a tail range that passes: that range's order, and the range said
  const s = orderClaim({ ...r, fit: { ...r.fit, suffix: { order: -1.002, order_se: 0.05, n_first: 1024, n_last: 65536, p_value: 0.4 } } });
  assert.equal(s.number, '-1.002 ± 0.050');
  assert.match(s.text, /from N = 1024/);
  // a line that fits: the CLI's number
  const ok = orderClaim({ ...r, fit: ladderFit(null, { p: 0.93, order: -1.503, se: 0.028 }) });
  assert.equal(ok.text, '-1.503 ± 0.028');
  assert.equal(ok.holds, true);
  // a result without the chi-square: the page says it cannot tell
  const old = orderClaim({ ...r, fit: { valid: true, order: -1.5, order_se: 0.03 } });
  assert.equal(old.holds, null);
  assert.match(old.text, /not checked/);
});

test('orderClaim: the fixtures, where the core reports the fit\'s chi-square', () => {
  // vegas_corner_peak: the variance goes up and down for the VEGAS family
  for (const name of ['vegas_sobol', 'vegas_plus', 'vegas_stratified']) {
    const r = vegasCorner.records[name];
    assert.equal(typeof r.fit.p_value, 'number', `${name}: the core reports p`);
    const c = orderClaim(r);
    if (r.fit.p_value < 1e-3 && !r.fit.suffix) assert.equal(c.number, null, name);
    if (c.number !== null) assert.ok(r.fit.p_value >= 1e-3 || r.fit.suffix, `${name}: a number needs a fit that holds`);
  }
  // disk_third's stratified estimators follow a line
  for (const name of ['stratified_concentric', 'uniform']) {
    const r = diskThird.records[name];
    assert.equal(typeof r.fit.p_value, 'number');
    assert.ok(r.fit.p_value >= 1e-3, `${name}: p = ${r.fit.p_value}`);
    assert.match(orderClaim(r).text, /^-1\.\d{3} ± 0\.\d{3}$/);
  }
});

test('orderClaim: no order under an infinite variance', () => {
  for (const name of ['uniform', 'stratified', 'importance_half']) {
    const r = singular.records[name];
    assert.ok(infiniteVariance(r), `${name} carries heavy_tail at warning`);
    const c = orderClaim(r);
    assert.equal(c.number, null, name);
    assert.match(c.text, /infinite/);
  }
  // a heavy tail at info only (finite variance, an erratic 4th moment): the order stands
  const r = { levels: [{ n: 16 }], warnings: [{ code: 'heavy_tail_4', severity: 'info' }], fit: ladderFit(null, { p: 0.3 }) };
  assert.notEqual(orderClaim(r).number, null);
  // and exact: nothing to fit
  assert.equal(orderClaim(stiff.records.importance_matched, { exact: stiff.exact }).text, 'exact: nothing to fit');
});

test('chi2Sf, trigamma and fitLine against known values', () => {
  assert.ok(Math.abs(chi2Sf(3.841458820694124, 1) - 0.05) < 1e-9);
  assert.ok(Math.abs(chi2Sf(18.307038053275146, 10) - 0.05) < 1e-9);
  assert.ok(Math.abs(chi2Sf(2, 2) - Math.exp(-1)) < 1e-12);
  assert.ok(chi2Sf(449, 5) < 1e-90 && chi2Sf(449, 5) > 0);
  assert.ok(Math.abs(trigamma(1) - Math.PI ** 2 / 6) < 1e-9);
  assert.ok(Math.abs(trigamma(0.5) - Math.PI ** 2 / 2) < 1e-9);
  const xs = [1, 2, 3, 4, 5];
  const line = fitLine(xs, xs.map((x) => 2 - 0.5 * x), 0.1);
  assert.ok(Math.abs(line.slope + 0.5) < 1e-12);
  assert.ok(line.p > 0.999);
  const bent = fitLine(xs, [0, 1, 0, 1, 0], 0.01);
  assert.ok(bent.p < 1e-10);
});

// ---------------------------------------------------------------------------------------------
// 3. Conservative error bars: "by design" only where this run shows it.

test('conservativeClaim: low coverage or far z are said, not "by design"', () => {
  const strat = conservativeClaim(singular.records.stratified, { exact: singular.exact, reps: singular.reps });
  assert.equal(strat.holds, false);
  assert.doesNotMatch(strat.coverageText, /above 0\.95/);
  assert.doesNotMatch(strat.text, /as designed/);
  assert.match(strat.text, /not in this run: coverage 0\.\d+ at N = \d+/);
  const polar = conservativeClaim(diskThird.records.stratified_polar, { exact: diskThird.exact, reps: diskThird.reps });
  const lowest = Math.min(...diskThird.records.stratified_polar.levels.map((l) => l.coverage95));
  if (lowest < 0.95 - 1.96 * Math.sqrt(0.95 * 0.05 / diskThird.reps)) {
    assert.equal(polar.holds, false);
    assert.match(polar.text, new RegExp(`coverage ${String(lowest).slice(0, 4)}`));
  } else {
    assert.equal(polar.holds, true);
  }
  const vs = conservativeClaim(vegasCorner.records.vegas_stratified, { exact: vegasCorner.exact, reps: vegasCorner.reps });
  const far = zScores(vegasCorner.records.vegas_stratified.levels, vegasCorner.exact).z.filter((z) => Math.abs(z) > 5).length;
  assert.ok(far > 0, 'vegas_stratified has z beyond 5 in this fixture');
  assert.equal(vs.holds, false);
  assert.doesNotMatch(vs.text, /narrower than N\(0, 1\)/);
  assert.match(vs.text, new RegExp(`${far} z beyond ±5`));
  // the stiff peak's stratified: coverage 0
  assert.equal(conservativeClaim(stiff.records.stratified, { exact: stiff.exact, reps: stiff.reps }).holds, false);
});

test('conservativeClaim: where the run shows it, it is said; without the core\'s word, nothing', () => {
  const lh = conservativeClaim(exp1d.records.latin_hypercube, { exact: exp1d.exact, reps: exp1d.reps });
  assert.equal(lh.holds, true);
  assert.match(lh.text, /as designed/);
  assert.match(lh.coverageText, /at or above 0\.95/);
  assert.equal(conservativeClaim({ ...exp1d.records.latin_hypercube, error_bars_conservative: false }), null);
  assert.equal(conservativeClaim(exp1d.records.uniform, { exact: exp1d.exact }), null);
  assert.equal(conservativeClaim(undefined), null);
  // without the exact value: only the spread is checked, and the words say so
  const blind = conservativeClaim(exp1d.records.latin_hypercube, { exact: null, reps: 32 });
  assert.equal(blind.holds, null);
  assert.match(blind.text, /without the exact value/);
});

test('coverage legend: the N it names is the N it was measured at; coinciding lines are named', () => {
  assert.equal(coverageText([256, 512, 1024], [0.9, 0.97, null]), '0.97 at N = 512');
  assert.equal(coverageText([1, 2], [null, null]), '—');
  const cs = coverageSeries(exp1d.records, exp1d.order, exp1d.ladder);
  const groups = coincidentGroups(cs.series);
  const ones = cs.series.filter((s) => s.y.every((v) => v === 1)).map((s) => s.name);
  if (ones.length > 1) assert.ok(groups.some((g) => ones.every((n) => g.includes(n))), 'the lines at 1 are one group');
  assert.equal(coincidentGroups([{ name: 'a', y: [1, 0.9] }, { name: 'b', y: [1, 0.95] }]).length, 0);
  const g = coincidentGroups([{ name: 'a', y: [1, 1] }, { name: 'b', y: [1, 1] }, { name: 'c', y: [null, null] }, { name: 'd', y: [null, null] }]);
  assert.deepEqual(g, [['a', 'b']], 'empty series do not coincide');
  assert.match(coincidentNote('b', g), /same line as a/);
  assert.equal(coincidentNote('c', g), null);
});

test('calibration legend counts say over which N', () => {
  const cs = calibrationSeries(exp1d.records, exp1d.order, exp1d.exact);
  assert.match(withinText(cs.series[0]), /^\d+% within ±1\.96 \(\d+ z, all N\)$/);
  const one = calibrationSeries(exp1d.records, exp1d.order, exp1d.exact, 1024);
  assert.match(withinText(one.series[0], 1024), /N = 1024\)$/);
});

// ---------------------------------------------------------------------------------------------
// 4. Words, not codes.

test('every flag code the core documents has words; chips never show a code', () => {
  const doc = readFileSync(join(here, '..', '..', 'docs', 'result-schema.md'), 'utf8');
  const known = ['no_estimate', 'nonfinite_estimate', 'nonfinite_variance', 'zero_error_bar', 'nonfinite', 'zero_pdf_samples',
    'skewed_weights', 'low_ess', 'exact_outside_ci', 'heavy_tail', 'heavy_tail_4', 'pdf_support', 'level_drift',
    'iterations_disagree', 'error_bars_understate', 'error_bars_unstable', 'replicate_far_off', 'values_underflow',
    'bias_dominates', 'conservative_error_bars', 'float32_accumulator', 'below_reference_noise', 'reference_noise',
    'slow_convergence', 'pixel_error_bars', 'few_pixel_errors', 'rare_large_errors', 'tolerance_not_met',
    'fireflies', 'black_reference', 'no_lights', 'degenerate_lights', 'gltf'];
  for (const code of known) {
    assert.ok(doc.includes(`\`${code}\``), `${code} is documented`);
    assert.ok(FLAG_WORDS[code], `${code} has words`);
    assert.notEqual(flagShort(code), code);
    assert.doesNotMatch(flagShort(code), /_/, code);
    assert.notEqual(flagTitle(code), code);
  }
  assert.doesNotMatch(flagShort('made_up_code'), /_/);
  assert.doesNotMatch(flagTitle('made_up_code'), /made_up_code/);
  // every code in the fixtures has words
  for (const f of [stiff, singular, diskThird, vegasCorner, exp1d]) {
    for (const w of collectWarnings(f.records, f.order)) assert.ok(FLAG_WORDS[w.code], w.code);
  }
});

test('p-values, tail indices, densities and methods in words', () => {
  assert.equal(pWords(0), 'p < 1e-300');
  assert.equal(pWords(1e-320), 'p < 1e-300');
  assert.doesNotMatch(pWords(0), /p = 0/);
  assert.equal(pWords(0.0123), 'p = 0.012');
  assert.doesNotMatch(tailWords(52200), /52200/);
  assert.match(tailWords(52200), /light/);
  assert.match(tailWords(1.23), /infinite variance/);
  assert.match(tailWords(3.1), /4th moment/);
  assert.match(tailWords(0), /no tail estimate/);
  assert.equal(densityWords({ pdf: 'exponential(rate=-0.8) on [0, 1]', pdf_text: 'exponential density ∝ e^(0.8 x) on [0, 1]' }), 'exponential density ∝ e^(0.8 x) on [0, 1]');
  assert.equal(densityWords({ pdf: 'uniform' }), 'uniform');
  // the page's own scene path is not the reader's: the input is named instead
  const e = inputErrorWords('scene.estimators[3].pdf.shape: at position 2: expected an expression', 'p');
  assert.doesNotMatch(e, /scene|estimators\[/);
  assert.match(e, /^p, the density: at position 2: expected an expression$/);
  assert.match(inputErrorWords("scene.f: at position 7: unknown function 'sinn'", 'f'), /^f, the integrand: at position 7/);
  for (const m of ['iid', 'iid_conservative', 'collapsed_strata', 'paired_strata', 'randomizations', 'parts_sum', 'regression', 'walsh_bound', 'none']) {
    assert.doesNotMatch(methodWords(m), /_/, m);
  }
});

// ---------------------------------------------------------------------------------------------
// 5. Alarms: red only for what persists.

test('alarmSummary: flags at small N only are not a red banner', () => {
  const a = alarmSummary(diskThird.records, diskThird.order);
  const zeroBars = collectWarnings(diskThird.records, diskThird.order).filter((w) => w.code === 'zero_error_bar');
  assert.ok(zeroBars.length > 0 && zeroBars.every((w) => w.n.every((n) => n <= 32)), 'the fixture has zero error bars at N <= 32 only');
  assert.notEqual(a.severity, 'error');
  assert.equal(a.counts.errors, 0, a.text);
  assert.match(a.text, /small N only \(N ≤ \d+\)/);
  for (const w of zeroBars) assert.equal(flagPersistence(w, diskThird.records[w.estimator]), 'small_n');
  // an isolated flag among many levels is counted with the number of levels checked
  const isolated = collectWarnings(diskThird.records, diskThird.order)
    .filter((w) => w.severity !== 'info' && flagPersistence(w, diskThird.records[w.estimator]) === 'isolated');
  if (isolated.length) assert.match(a.text, /levels checked/);
});

test('alarmSummary: an error at every N is red', () => {
  const a = alarmSummary(stiff.records, stiff.order);
  assert.equal(a.severity, 'error');
  assert.ok(a.parts[0].who.includes('uniform'));
  // a level flag at the largest N persists
  const r = { levels: [{ n: 16 }, { n: 32 }, { n: 64 }, { n: 128 }, { n: 256 }] };
  assert.equal(flagPersistence({ scope: 'level', code: 'error_bars_understate', n: [256] }, r), 'persistent');
  assert.equal(flagPersistence({ scope: 'level', code: 'error_bars_understate', n: [64] }, r), 'isolated');
  assert.equal(flagPersistence({ scope: 'level', code: 'zero_error_bar', n: [16, 32] }, r), 'small_n');
  // a fact is no chance: an exact value outside the interval at one level persists, as does a
  // threshold test that fired at two levels
  assert.equal(flagPersistence({ scope: 'level', code: 'exact_outside_ci', n: [64] }, r), 'persistent');
  assert.equal(flagPersistence({ scope: 'level', code: 'exact_outside_ci', n: [16, 32] }, r), 'persistent');
  assert.equal(flagPersistence({ scope: 'level', n: [16, 64, 128] }, r), 'persistent', 'half the levels or more');
  // the first levels of a longer ladder are small N; one scattered level above them is isolated
  const long = { levels: [16, 32, 64, 128, 256, 512, 1024, 2048, 4096].map((n) => ({ n })) };
  assert.equal(flagPersistence({ scope: 'level', code: 'low_ess', n: [16, 32, 64] }, long), 'small_n');
  assert.equal(flagPersistence({ scope: 'level', code: 'error_bars_understate', n: [1024] }, long), 'isolated');
  assert.equal(flagPersistence({ scope: 'level', code: 'error_bars_understate', n: [512, 1024] }, long), 'persistent');
  const isolated = alarmSummary({ a: { levels: long.levels.map((l) => ({ ...l, warnings: l.n === 1024 ? [{ code: 'error_bars_understate', severity: 'error' }] : [] })) } }, ['a']);
  assert.equal(isolated.severity, 'note');
  assert.match(isolated.text, /1 isolated level flag among 9 levels checked/);
});

// ---------------------------------------------------------------------------------------------
// 6. Equal time: no winner the data or the clock cannot support.

const timedLevel = (variance, time, over = {}) => ({
  n: 4096, reps: 32, mean: 1, variance, variance_ci95: [variance * 0.65, variance * 1.7], time_mean_s: time,
  time_std_s: time * 0.1, time_median_s: time, time_median_ci95_s: [time * 0.95, time * 1.05], ...over,
});
const rec = (name, l, warnings = []) => ({ name, levels: [l], fit: null, warnings });

test('equalTimeClaim: a winner only when the efficiencies differ beyond their uncertainty', () => {
  const clear = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3)), b: rec('b', timedLevel(1e-6, 1e-3)) }, ['a', 'b']);
  assert.equal(clear.winner, 'b');
  assert.match(clear.text, /^Equal-time winner .*: b, 100× as efficient as the next, a \(z = /);
  const close = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3)), b: rec('b', timedLevel(1.2e-4, 0.9e-3)) }, ['a', 'b']);
  assert.equal(close.winner, null);
  assert.match(close.text, /^No significant difference at equal time between/);
});

test('equalTimeClaim: the clock', () => {
  const records = { a: rec('a', timedLevel(1e-4, 1e-4)), b: rec('b', timedLevel(1e-6, 1e-4)) };
  // 0.1 ms steps: 20 steps = 2 ms, both runs under it
  const coarse = equalTimeClaim(records, ['a', 'b'], { floorSeconds: 2e-3 });
  assert.equal(coarse.winner, null);
  assert.match(coarse.text, /too fast for this clock/);
  assert.equal(equalTimeClaim(records, ['a', 'b'], { floorSeconds: 1e-4 }).winner, 'b', '5 us steps: 100 us is timed');
  assert.equal(equalTimeClaim(records, ['a', 'b'], { clockKnown: false }).winner, null);
  // a median interval of zero width (the clock did not move) is no certainty
  const flat = { a: rec('a', timedLevel(1e-4, 1e-3, { time_median_ci95_s: [1e-3, 1e-3] })), b: rec('b', timedLevel(1e-6, 1e-3)) };
  const v = equalTimeClaim(flat, ['a', 'b']);
  assert.equal(v.winner, null);
  assert.match(v.text, /cannot be tested/);
});

test('equalTimeClaim: MSE uncertainty from the bias, infinite variances left out', () => {
  // b: a bias of 0.1 over a spread of 1e-3: its MSE 1e-2 is known to about 2 se(b) / b
  const l = timedLevel(1e-6, 1e-3, { mse: 1e-2 + 1e-6, bias: 0.1 });
  assert.ok(Math.abs(seLogMse(l) - 2 * Math.sqrt(1e-6 / 32) / 0.1) < 1e-4);
  const biased = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3, { mse: 1e-4, bias: 0 })), b: rec('b', l) }, ['a', 'b'], { exact: 1 });
  assert.equal(biased.winner, 'a');
  const heavy = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3)), b: rec('b', timedLevel(1e-8, 1e-3), [{ code: 'heavy_tail', severity: 'warning' }]) }, ['a', 'b']);
  assert.notEqual(heavy.winner, 'b');
  assert.match(heavy.text, /b \(infinite variance/);
  // the singular fixture: no winner among the heavy-tailed
  const s = equalTimeClaim(singular.records, ['uniform', 'stratified', 'importance_half'], { exact: singular.exact });
  assert.equal(s.winner, null);
});

// ---------------------------------------------------------------------------------------------
// 7. Time slopes: with an uncertainty, where a line fits and time grows with N.

function timedRecord(points, { reps = 32, warnings = [] } = {}) {
  return { warnings, levels: points.map(([n, t, e]) => ({ n, reps, time_median_s: t, time_mean_s: t, error: e, mean: 1 })) };
}
const ns = [1024, 2048, 4096, 8192, 16384, 32768, 65536];

test('timeSlopeClaim: under the clock floor, no slope', () => {
  const r = timedRecord(ns.map((n) => [n, 1e-4 * (n / 65536), 1 / Math.sqrt(n)]));
  const c = timeSlopeClaim(r, { floorSeconds: 2e-3 });
  assert.equal(c.slope, null);
  assert.match(c.text, /too fast for the clock/);
});

test('timeSlopeClaim: a fixed set-up cost gives no slope', () => {
  const r = timedRecord(ns.map((n) => [n, 1e-3 + 1e-9 * n, 1 / Math.sqrt(n)]));
  const c = timeSlopeClaim(r, { floorSeconds: 1e-4 });
  assert.equal(c.slope, null);
  assert.doesNotMatch(c.text, /t\^/);
  assert.match(c.text, /fixed cost/);
});

test('timeSlopeClaim: t proportional to N and error to N^-1/2 gives t^-0.5 with its uncertainty', () => {
  // the RMSE's noise over 32 replicates, drawn from a fixed sequence
  const jitter = [1.05, 0.97, 1.02, 0.99, 1.04, 0.96, 1.01];
  const r = timedRecord(ns.map((n, i) => [n, 1e-8 * n, jitter[i] / Math.sqrt(n)]));
  const c = timeSlopeClaim(r, { floorSeconds: 5e-6 });
  assert.equal(c.evidence.points, 7);
  assert.ok(Math.abs(c.slope + 0.5) < 0.05, c.text);
  assert.match(c.text, /^error ∝ t\^-0\.\d{3} ± 0\.\d{3}$/);
  assert.ok(c.se > 0 && c.se < 0.1);
});

test('timeSlopeClaim: a bias that does not fall, an exact estimator, a bent curve', () => {
  const bias = timedRecord(ns.map((n) => [n, 1e-8 * n, 0.1]), { warnings: [{ code: 'bias_dominates', severity: 'info' }] });
  const b = timeSlopeClaim(bias, { floorSeconds: 1e-4 });
  assert.doesNotMatch(b.text, /t\^/);
  assert.match(b.text, /bias/);
  const e = timeSlopeClaim(stiff.records.importance_matched, { exact: stiff.exact, floorSeconds: 0 });
  assert.match(e.text, /round-off/);
  const bent = timedRecord(ns.map((n, i) => [n, 1e-8 * n, i % 2 ? 1e-2 : 1e-4]));
  const c = timeSlopeClaim(bent, { floorSeconds: 1e-4 });
  assert.doesNotMatch(c.text, /t\^/);
});

// ---------------------------------------------------------------------------------------------
// 8. Render notes and PNG legends.

test('render notes: stratified pixels are said to fall faster than spp^-1; the time note is a render one', () => {
  const records = { light_area: { pixel_sampler: 'stratified' }, bsdf: { pixel_sampler: 'independent' } };
  const withStrata = varianceNote('render', records, ['light_area', 'bsdf']);
  assert.match(withStrata, /light_area \(stratified\)/);
  assert.match(withStrata, /steeper than spp⁻¹ is expected/);
  const plain = varianceNote('render', { bsdf: records.bsdf }, ['bsdf']);
  assert.doesNotMatch(plain, /expected/);
  assert.match(plain, /independent pixel samples/);
  const r = timeNote('render');
  assert.doesNotMatch(r.lead + r.adaptive, /VEGAS|per estimate/);
  assert.match(timeNote('integral').lead, /per estimate/);
  assert.match(timeNote('integral').adaptive, /VEGAS/);
});

test('legendLines: hidden entries left out, every line within the width', () => {
  const measure = (t) => 7 * t.length;
  const items = [
    { text: 'uniform order -1.036 ± 0.028 error bars too small few effective samples skewed weights' },
    { text: 'stratified hidden', hidden: true },
    { text: 'importance' },
    { text: 'x'.repeat(80) },
  ];
  const lines = legendLines(items, { measure, width: 210 });
  assert.ok(lines.every((l) => measure(l.text) <= 210), 'no line wider than the room');
  assert.ok(!lines.some((l) => /hidden/.test(l.text)));
  assert.deepEqual([...new Set(lines.map((l) => l.item))], [0, 2, 3]);
  assert.equal(lines.filter((l) => l.first).length, 3, 'one swatch per entry');
  assert.equal(lines.filter((l) => l.item === 0).map((l) => l.text).join(' '), items[0].text);
  assert.equal(lines.filter((l) => l.item === 3).map((l) => l.text).join(''), items[3].text);
});

// ---------------------------------------------------------------------------------------------
// Found by a review of the page against its data (each a case where the claim was false).

test('equalTimeClaim: exact only from some N on is not "exact at any time"', () => {
  const late = { name: 'late', warnings: [], levels: [
    timedLevel(1e-5, 1e-3, { n: 1024, mean: 1.01, mse: 1e-4, exact_to_roundoff: false }),
    timedLevel(0, 2e-3, { n: 2048, mean: 1, mse: 0, exact_to_roundoff: true }),
  ] };
  const v = equalTimeClaim({ late, a: rec('a', timedLevel(1e-4, 1e-3, { mse: 1e-4 })) }, ['a', 'late'], { exact: 1 });
  assert.doesNotMatch(v.text, /any time/);
  assert.match(v.text, /from N = 2048 on/);
});

test('timeSlopeClaim: one slow level is not a fixed cost', () => {
  const jitter = [1.05, 0.97, 1.02, 0.99, 1.04, 0.96, 1.01];
  const r = timedRecord(ns.map((n, i) => [n, (i === ns.length - 1 ? 4 : 1) * 1e-8 * n, jitter[i] / Math.sqrt(n)]));
  const c = timeSlopeClaim(r, { floorSeconds: 5e-6 });
  assert.doesNotMatch(c.text, /fixed cost/);
  assert.match(c.text, /^error ∝ t\^-0\.\d{3} ± /);
});

test('conservativeClaim: nothing to claim for an estimator exact at every N; a zero error bar at small N is no failure', () => {
  for (const name of diskQuarter.order) {
    const r = diskQuarter.records[name];
    if (recordExactness(r, diskQuarter.exact).all === 'exact') assert.equal(conservativeClaim(r, { exact: diskQuarter.exact, reps: 32 }), null, name);
  }
  const c = conservativeClaim(diskThird.records.stratified_concentric, { exact: diskThird.exact, reps: diskThird.reps });
  assert.doesNotMatch(c.text, /too small at some N/);
});

test('a heavy tail at info is not worded as a possibly infinite variance', () => {
  assert.doesNotMatch(flagShort('heavy_tail', 'info'), /infinite/);
  assert.doesNotMatch(flagTitle('heavy_tail', 'info'), /may be infinite/);
  assert.match(flagShort('heavy_tail', 'warning'), /infinite/);
});

// ---------------------------------------------------------------------------------------------
// Issue 48, item 2 (the study page): each rule where it must be said and where it must not.

/** A copy of a record with its heavy_tail flag at `severity` (none: removed). */
function withHeavyTail(r, severity) {
  const warnings = (r.warnings || []).filter((w) => w.code !== 'heavy_tail');
  if (severity) warnings.push({ code: 'heavy_tail', severity, message: 'tail index 1.2' });
  return { ...r, warnings };
}

test('time legend: no order under an infinite variance, as the MSE legend; an order at info', () => {
  for (const name of ['uniform', 'stratified', 'importance_half']) {
    const r = singular.records[name];
    const c = timeSlopeClaim(r, { exact: singular.exact, floorSeconds: 0, measure: 'mse' });
    assert.equal(c.slope, null, name);
    assert.doesNotMatch(c.text, /t\^/, `${name}: ${c.text}`);
    assert.match(c.text, /MSE is infinite/);
    assert.equal(c.text, orderClaim(r, { exact: singular.exact, measure: 'MSE' }).text, 'the same words as the MSE legend');
  }
  // the same points without the flag at warning (at info) get their slope
  const jitter = [1.05, 0.97, 1.02, 0.99, 1.04, 0.96, 1.01];
  const r = timedRecord(ns.map((n, i) => [n, 1e-8 * n, jitter[i] / Math.sqrt(n)]), { warnings: [{ code: 'heavy_tail', severity: 'info' }] });
  assert.match(timeSlopeClaim(r, { floorSeconds: 5e-6 }).text, /^error ∝ t\^-0\.\d{3} ± /);
  assert.doesNotMatch(timeSlopeClaim(withHeavyTail(r, 'warning'), { floorSeconds: 5e-6 }).text, /t\^/);
});

test('variance plot: no chi-square band around an infinite variance; the band where it is finite', () => {
  const bands = (records, order) => varianceSeries(records, order, singular.exact).series;
  for (const s of bands(singular.records, ['uniform', 'stratified'])) {
    assert.equal(s.infinite, true);
    assert.ok(s.y.some((v) => v !== null), `${s.name} keeps its points`);
    assert.ok(s.lo.every((v) => v === null) && s.hi.every((v) => v === null), `${s.name}: no band`);
  }
  const finite = { uniform: withHeavyTail(singular.records.uniform, 'info') };
  const [s] = bands(finite, ['uniform']);
  assert.equal(s.infinite, false);
  assert.ok(s.lo.some((v) => v !== null) && s.hi.some((v) => v !== null), 'a finite variance keeps its band');
});

/** Timed levels at N = ns: seconds t(n, i), error 1/sqrt(n), and a 95% timing interval of
 *  +-`rel` (none when rel is null, as render levels have). */
function timedLevels(t, rel = 0.05) {
  return { warnings: [], levels: ns.map((n, i) => {
    const s = t(n, i);
    return { n, reps: 32, time_median_s: s, time_mean_s: s, error: 1 / Math.sqrt(n), mean: 1,
      ...(rel === null ? {} : { time_median_ci95_s: [s * (1 - rel), s * (1 + rel)] }) };
  }) };
}
// The per-sample cost of levels that merely scatter (timing noise on a busy machine), a fixed
// sequence: up to 4x apart, no trend in N.
const SCATTER = [1, 2.5, 0.6, 1.8, 0.7, 2.2, 1.0];
const WOBBLE = [1.04, 0.97, 1.02, 0.99, 1.03, 0.96, 1.01];

test('fixedCost: shown where the time at small N is flat and above the proportional line, not where it scatters', () => {
  for (const rel of [0.05, null]) {
    const fixed = timedLevels((n, i) => (1e-3 + 1e-9 * n) * WOBBLE[i], rel);
    const c = timeSlopeClaim(fixed, { floorSeconds: 1e-4 });
    assert.equal(c.slope, null);
    assert.match(c.text, /a fixed cost dominates/, `intervals ${rel}`);
    assert.ok(c.evidence.fixedCost.z > 3);
    // the timings merely scatter: no fixed cost named, whatever the intervals say
    for (const seq of [SCATTER, SCATTER.slice().reverse()]) {
      const noisy = timedLevels((n, i) => 1e-8 * n * seq[i], rel);
      const d = timeSlopeClaim(noisy, { floorSeconds: 1e-7 });
      assert.equal(d.slope, null);
      assert.doesNotMatch(d.text, /fixed cost dominates/, `intervals ${rel}: ${d.text}`);
      assert.match(d.text, /varies 4.2× between levels, and no fixed cost shows/);
      assert.equal(d.evidence.fixedCost.shown, false);
    }
  }
  // one slow level at the smallest N is no fixed cost either
  const pts = (f) => ns.map((n, i) => ({ n, t: f(n, i), sdLog: null }));
  assert.equal(fixedCost(pts((n, i) => 1e-8 * n * (i === 0 ? 3 : WOBBLE[i]))).shown, false);
  assert.equal(fixedCost(pts((n, i) => 1e-8 * n * WOBBLE[i])).shown, false, 'proportional time');
  assert.equal(fixedCost(pts((n, i) => (2e-5 + 1e-8 * n) * WOBBLE[i])).shown, true, 'dominant at N = 1024 only');
  assert.equal(fixedCost(pts((n, i) => (2e-6 + 1e-8 * n) * WOBBLE[i])).shown, false, 'a fixed cost that never dominates');
});

test('tail words follow the core\'s severity, not the tail index alone', () => {
  const level = { n: 64, tail_index: 1.3 };
  const bounded = { contribution_bound: { bounded: true, reason: 'multiple importance sampling with BSDF sampling' } };
  // at info (bounded contributions): finite, with the reason
  const info = { ...bounded, warnings: [{ code: 'heavy_tail', severity: 'info' }] };
  assert.doesNotMatch(tailText(info, level), /infinite variance/);
  assert.match(tailText(info, level), /variance is finite: the contributions are bounded \(multiple importance/);
  assert.doesNotMatch(tailText({ warnings: [] }, level), /^heavy: infinite/);
  assert.match(tailText({ warnings: [] }, level), /no alarm/);
  // at warning: infinite
  assert.match(tailText({ warnings: [{ code: 'heavy_tail', severity: 'warning' }] }, level), /heavy: infinite variance/);
  // the 4th moment likewise
  assert.match(tailText({ warnings: [{ code: 'heavy_tail_4', severity: 'warning' }] }, { tail_index: 3 }), /infinite 4th moment/);
  assert.match(tailText({ warnings: [{ code: 'heavy_tail_4', severity: 'info' }] }, { tail_index: 3 }), /no alarm/);
  assert.match(tailText(info, { tail_index: 52200 }), /light/);
  // and the order and the equal-time verdict: an info flag keeps both
  const r = { ...info, levels: [timedLevel(1e-6, 1e-3)], fit: ladderFit(null, { p: 0.3 }) };
  assert.notEqual(orderClaim(r).number, null);
  assert.equal(orderClaim(withHeavyTail(r, 'warning')).number, null);
  const v = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3)), b: { ...r, name: 'b' } }, ['a', 'b']);
  assert.ok(!v.left.some((x) => x.name === 'b'), 'an info flag does not leave b out');
  const w = equalTimeClaim({ a: rec('a', timedLevel(1e-4, 1e-3)), b: withHeavyTail({ ...r, name: 'b' }, 'warning') }, ['a', 'b']);
  assert.ok(w.left.some((x) => x.name === 'b'));
});

test('reference noise: a relative MSE below the reference\'s noise is words, never a number', () => {
  const floor = 1.6e-3;
  assert.equal(relativeMseText(-2.1e-5, { floor, below: true }), 'at the reference\'s noise (below 0.0016)');
  assert.equal(relativeMseText(1e-4, { floor, below: true }), 'at the reference\'s noise (below 0.0016)');
  assert.equal(relativeMseText(0.013, { floor, below: false }), '0.013');
  // the core's verdict wins; without it, the value against the floor
  assert.equal(atReferenceNoise(1e-4, { floor }), true);
  assert.equal(atReferenceNoise(-1e-6, {}), true);
  assert.equal(atReferenceNoise(0.01, { floor }), false);
  assert.equal(atReferenceNoise(1e-4, { floor, below: false }), false);
  // the root: relative RMSE below sqrt(floor)
  assert.equal(relativeMseText(0.01, { floor, root: true }), 'at the reference\'s noise (below 0.04)');
  assert.equal(relativeMseText(0.1, { floor, root: true }), '0.1');
  assert.equal(referenceNoiseWords(null), 'at the reference\'s noise');
  assert.equal(referenceFloorOf({ scene: { reference: { relative_mse_floor: floor } } }), floor);
  assert.equal(referenceFloorOf({ reference_summary: { relative_mse_floor: floor } }), floor);
  assert.equal(referenceFloorOf({ scene: { reference: { relative_mse_floor: null } } }), null);
});

test('equal time in a render study: levels at the reference\'s noise have no efficiency', () => {
  const lvl = (n, v, below, t) => ({ n, reps: 4, variance: v, mse: v, time_mean_s: t, time_std_s: 0.1 * t,
    variance_ci95: [v * 0.7, v * 1.4], below_reference_noise: below });
  // mis reaches the reference's noise at 64 spp: compared at 32, never from its number at 64
  const mis = { name: 'mis', warnings: [], levels: [lvl(16, 0.05, false, 0.2), lvl(32, 0.025, false, 0.4), lvl(64, -1e-4, true, 0.8)] };
  const bsdf = { name: 'bsdf', warnings: [], levels: [lvl(16, 5, false, 0.1), lvl(32, 2.5, false, 0.2), lvl(64, 1.2, false, 0.4)] };
  const v = equalTimeClaim({ mis, bsdf }, ['mis', 'bsdf'], { render: true, referenceFloor: 1.6e-3 });
  assert.equal(v.ranked.find((x) => x.name === 'mis').n, 32);
  assert.equal(v.ranked.find((x) => x.name === 'bsdf').n, 64);
  assert.match(v.text, /above the reference's noise/);
  assert.doesNotMatch(v.text, /zero relative MSE/);
  // at the noise at every spp: left out in those words
  const flat = { name: 'flat', warnings: [], levels: [lvl(16, 1e-5, true, 0.2)] };
  const w = equalTimeClaim({ flat, bsdf }, ['flat', 'bsdf'], { render: true, referenceFloor: 1.6e-3 });
  assert.match(w.text, /flat \(relative MSE at the reference's noise \(below 0\.0016\) at every spp\)/);
  // none at the noise: the words stay as they were
  assert.doesNotMatch(equalTimeClaim({ bsdf, b2: { ...bsdf, name: 'b2' } }, ['bsdf', 'b2'], { render: true }).text, /reference's noise/);
});
