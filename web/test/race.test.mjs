// Tests of web/src/race.js: the race to a requested accuracy (times to the target, their median
// intervals, the rank-sum test and the stated winner). Statistical checks use a fixed-seed
// generator and tolerances in binomial standard errors.
import { test } from 'node:test';
import assert from 'node:assert/strict';

import {
  parsePositive, raceOptions, withoutStopping, sceneTolerance, medianInterval, normalUpperTail,
  mannWhitney, raceRows, formatSeconds,
} from '../src/race.js';
import { raceClaim } from '../src/claims/race.js';

// The verdict's words (claims/race.js) with an isolated page's clock: 5 us steps, floor 100 us.
const FINE = { stepMs: 0.005, isolated: true };
const raceVerdict = (result) => raceClaim(result, { clock: FINE });

// A fixed-seed uniform generator on (0, 1) (splitmix-style 32-bit hash of a counter).
function rng(seed) {
  let s = seed >>> 0;
  return () => {
    s = (s + 0x9e3779b9) >>> 0;
    let z = s;
    z = Math.imul(z ^ (z >>> 16), 0x85ebca6b) >>> 0;
    z = Math.imul(z ^ (z >>> 13), 0xc2b2ae35) >>> 0;
    z = (z ^ (z >>> 16)) >>> 0;
    return (z + 0.5) / 2 ** 32;
  };
}

// A stopping result as the C API gives it (docs/result-schema.md), runs from {met, seconds}.
function estimator(name, runs) {
  return {
    name,
    runs: runs.map(([met, seconds], i) => ({
      estimate: 1, std_error: 1e-4, met, reason: met ? 'tolerance_met' : 'max_seconds',
      n: 1024 * (i + 1), evaluations: 2048 * (i + 1), seconds, within_tolerance: met,
    })),
    warnings: [],
  };
}

test('parsePositive and raceOptions: tolerances, runs and the time budget, every error named', () => {
  assert.equal(parsePositive('1e-3'), 1e-3);
  assert.equal(parsePositive(' .5 '), 0.5);
  for (const bad of ['0', '-1', 'abc', '1e', '', 'Infinity', '1e999']) assert.equal(parsePositive(bad), null, bad);

  const ok = raceOptions({ relTol: '1e-3', absTol: '', runs: '10', maxSeconds: '2' });
  assert.deepEqual(ok, { ok: true, options: { rel_tol: 1e-3, reps: 10, max_seconds: 2 } });
  assert.deepEqual(raceOptions({ relTol: '', absTol: '1e-5', runs: '4', maxSeconds: '0.5' }).options,
    { abs_tol: 1e-5, reps: 4, max_seconds: 0.5 });

  const bad = raceOptions({ relTol: '1.5', absTol: 'x', runs: '1', maxSeconds: '0' });
  assert.equal(bad.ok, false);
  assert.deepEqual(Object.keys(bad.errors).sort(), ['absTol', 'maxSeconds', 'relTol', 'runs']);
  assert.match(raceOptions({ relTol: '', absTol: '', runs: '10', maxSeconds: '2' }).errors.relTol, /relative or an absolute/);
});

test('withoutStopping and sceneTolerance: a scene that asks for stopping still runs as an N ladder', () => {
  const scene = { name: 's', f: 'x', rel_tol: 0.01, max_seconds: 3, estimators: ['uniform'] };
  assert.deepEqual(withoutStopping(scene), { name: 's', f: 'x', estimators: ['uniform'] });
  assert.equal(scene.rel_tol, 0.01, 'the input is not changed');
  assert.deepEqual(sceneTolerance(scene), { relTol: '0.01', absTol: '' });
  assert.deepEqual(sceneTolerance({ abs_tol: -1 }), { relTol: '', absTol: '' });
});

test('medianInterval: order statistics and their exact binomial level', () => {
  const x = Array.from({ length: 10 }, (_, i) => i + 1);
  const ci = medianInterval(x);
  // n = 10: P(B <= 1) = 11/1024, so [x_(2), x_(9)] with level 1 - 22/1024
  assert.deepEqual([ci.lo, ci.hi], [2, 9]);
  assert.ok(Math.abs(ci.level - (1 - 22 / 1024)) < 1e-12);
  const small = medianInterval([1, 2, 3, 4, 5]);
  assert.deepEqual([small.lo, small.hi], [1, 5]);
  assert.ok(Math.abs(small.level - (1 - 2 / 32)) < 1e-12, 'n = 5 cannot reach 95%: its own level is given');
  assert.equal(medianInterval([]), null);
});

test('medianInterval covers the true median at least at its stated level (fixed seed)', () => {
  const u = rng(7);
  const trials = 4000;
  for (const n of [9, 16, 31]) {
    let covered = 0;
    let level = 0;
    for (let t = 0; t < trials; ++t) {
      const x = Array.from({ length: n }, () => -Math.log(u())).sort((a, b) => a - b); // Exp(1), median ln 2
      const ci = medianInterval(x);
      level = ci.level;
      if (ci.lo <= Math.LN2 && Math.LN2 <= ci.hi) ++covered;
    }
    const se = Math.sqrt((level * (1 - level)) / trials);
    assert.ok(Math.abs(covered / trials - level) < 4 * se, `n = ${n}: ${covered / trials} against ${level}`);
  }
});

test('normalUpperTail against known quantiles', () => {
  assert.ok(Math.abs(normalUpperTail(0) - 0.5) < 1e-7);
  assert.ok(Math.abs(normalUpperTail(1.959963985) - 0.025) < 1e-8);
  assert.ok(Math.abs(normalUpperTail(5) / 2.866515719e-7 - 1) < 1e-5);
  assert.ok(Math.abs(normalUpperTail(-1) - 0.841344746) < 1e-7);
});

test('mannWhitney: separated, equal and censored samples', () => {
  const a = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10];
  const b = a.map((v) => v + 100);
  const sep = mannWhitney(a, b);
  assert.ok(sep.p < 1e-3, `p = ${sep.p}`);
  assert.equal(sep.superiority, 1);
  const same = mannWhitney(a, a.slice());
  assert.equal(same.p, 1);
  assert.equal(same.superiority, 0.5);
  // runs that never met the target tie at +Infinity: still a clear difference
  const censored = mannWhitney(a, a.map(() => Infinity));
  assert.ok(censored.p < 1e-3);
  assert.equal(mannWhitney([], a).p, null);
});

test('mannWhitney rejects equal distributions at about its level, and unequal ones often (fixed seed)', () => {
  const u = rng(11);
  const trials = 3000;
  const draw = (n, shift) => Array.from({ length: n }, () => -Math.log(u()) * shift);
  let nullRejects = 0;
  let powerRejects = 0;
  for (let t = 0; t < trials; ++t) {
    if (mannWhitney(draw(10, 1), draw(10, 1)).p < 0.05) ++nullRejects;
    if (mannWhitney(draw(10, 1), draw(10, 4)).p < 0.05) ++powerRejects;
  }
  const se = Math.sqrt((0.05 * 0.95) / trials);
  // the normal approximation with a continuity correction is a little conservative at n = 10
  assert.ok(nullRejects / trials < 0.05 + 3 * se, `size ${nullRejects / trials}`);
  assert.ok(nullRejects / trials > 0.02, `size ${nullRejects / trials}`);
  assert.ok(powerRejects / trials > 0.6, `power ${powerRejects / trials}`);
});

test('raceRows: censored runs, medians, evaluations and the within-tolerance count', () => {
  const result = {
    kind: 'stopping',
    estimators: [
      estimator('fast', Array.from({ length: 10 }, (_, i) => [true, 0.001 * (i + 1)])),
      estimator('mostly_out', Array.from({ length: 10 }, (_, i) => [i < 4, 0.01 * (i + 1)])),
    ],
  };
  const [fast, out] = raceRows(result);
  assert.equal(fast.met, 10);
  assert.equal(fast.within, 10);
  assert.ok(Math.abs(fast.median - 0.0055) < 1e-15);
  assert.deepEqual([fast.interval.lo, fast.interval.hi], [fast.times[1], fast.times[8]]);
  assert.equal(fast.evaluations, (2048 * 5 + 2048 * 6) / 2);
  assert.equal(out.met, 4);
  assert.equal(out.median, Infinity, 'most runs did not meet the target');
  assert.equal(out.evaluations, null);
  assert.deepEqual(out.reasons, ['max_seconds']);
});

test('raceClaim with a fine clock: a clear winner, a tie, and nobody', () => {
  const u = rng(3);
  const times = (scale) => Array.from({ length: 12 }, () => [true, scale * (1 + u())]);
  const clear = raceVerdict({ estimators: [estimator('slow', times(0.1)), estimator('quick', times(0.01))] });
  assert.equal(clear.winner, 'quick');
  assert.deepEqual(clear.ranked.map((r) => r.name), ['quick', 'slow']);
  assert.ok(clear.ranked[1].ratio > 5);
  assert.match(clear.text, /^quick reaches the target first: [\d.]+× faster than the next, slow \(rank-sum p = /);

  const tie = raceVerdict({ estimators: [estimator('a', times(0.01)), estimator('b', times(0.01)), estimator('c', times(1))] });
  assert.equal(tie.winner, null);
  assert.deepEqual(tie.tied.slice().sort(), ['a', 'b']);
  assert.match(tie.text, /^No significant difference between /);

  const censored = raceVerdict({ estimators: [
    estimator('never', Array.from({ length: 10 }, () => [false, 2])),
    estimator('only', times(0.5).slice(0, 10)),
  ] });
  assert.equal(censored.winner, 'only');
  assert.match(censored.text, /the only one to reach it in most runs/);

  const none = raceVerdict({ estimators: [estimator('never', [[false, 2], [false, 2]])] });
  assert.equal(none.winner, null);
  assert.match(none.text, /No estimator reached the target/);
});

test('formatSeconds', () => {
  assert.equal(formatSeconds(2.5), '2.5 s');
  assert.equal(formatSeconds(0.0123), '12 ms');
  assert.equal(formatSeconds(0.000456), '456 µs');
  assert.equal(formatSeconds(Infinity), '—');
});
