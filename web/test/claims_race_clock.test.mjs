// Tests of web/src/claims/clock.js and web/src/claims/race.js (issue 38, items 6 and 8; survey
// 8.3 rows 16, 19, 20, 21): each claim once where the data make it false (the words must not
// appear) and once where they make it true. Fixtures: stopping results of the native CLI,
// trimmed to the fields raceClaim reads (web/test/fixtures/claims/race_*.json, each with the
// command that made it); the tests derive their variants (a coarse clock's rounding, wrong
// answers) from them and check properties computed here, not copied outputs.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';

import { clockClaim, clockFloor, clockText } from '../src/claims/clock.js';
import { raceClaim, missAllowance, reasonWords, CONSERVATIVE_RATIO } from '../src/claims/race.js';

const fixture = (name) => JSON.parse(readFileSync(new URL(`./fixtures/claims/${name}`, import.meta.url), 'utf8'));
const EXP = fixture('race_exp_1d.json');
const FINE = { stepMs: 0.005, isolated: true }; // Chromium, cross-origin isolated
const COARSE = { stepMs: 0.1, isolated: false }; // Chromium on a plain static host

const median = (xs) => {
  const s = xs.slice().sort((a, b) => a - b);
  const h = Math.floor(s.length / 2);
  return s.length % 2 ? s[h] : (s[h - 1] + s[h]) / 2;
};
const only = (result, names) => ({ ...result, estimators: result.estimators.filter((e) => names.includes(e.name)) });
/** The runs' seconds as a clock of `stepMs` reads them (rounded down to whole steps). */
const quantised = (result, stepMs) => ({
  ...result,
  estimators: result.estimators.map((e) => ({
    ...e, runs: e.runs.map((r) => ({ ...r, seconds: Math.floor(r.seconds / (stepMs / 1000)) * (stepMs / 1000) })),
  })),
});
/** A named estimator's runs changed by fn(run, i); within_tolerance recomputed as the core does. */
function withRuns(result, name, fn) {
  const tol = Math.max(result.stopping.abs_tol || 0, result.stopping.rel_tol * Math.abs(result.scene.exact));
  return {
    ...result,
    estimators: result.estimators.map((e) => (e.name !== name ? e : {
      ...e,
      runs: e.runs.map((r, i) => {
        const run = fn({ ...r }, i, tol);
        return { ...run, within_tolerance: Math.abs(run.estimate - result.scene.exact) <= tol };
      }),
    })),
  };
}
/** Medians of the met runs' seconds (Infinity when most runs did not meet), from the result. */
const medianTimes = (result) => Object.fromEntries(result.estimators.map((e) => {
  const t = e.runs.map((r) => (r.met ? r.seconds : Infinity));
  return [e.name, t.filter(Number.isFinite).length * 2 > t.length ? median(t.filter(Number.isFinite).concat(t.filter((x) => !Number.isFinite(x)))) : Infinity];
}));

// ---------------------------------------------------------------------------------------------
// Row 16: clockClaim

test('clockClaim: no banner on an isolated page with a 5 us clock (row 16, false)', () => {
  const c = clockClaim(FINE);
  assert.equal(c.banner, null);
  assert.ok(Math.abs(c.floorSeconds - 20 * 0.005e-3) < 1e-15, 'floor = 20 steps');
  assert.doesNotMatch(c.text, /not cross-origin isolated|could not be measured/);
  assert.match(c.timeNote, /5 µs/);
  assert.match(c.raceNote, /5 µs/);
  assert.equal(clockFloor(FINE), c.floorSeconds);
  assert.equal(clockFloor(c), c.floorSeconds, 'a claim passes its own floor through');
});

test('clockClaim: a banner with the measured numbers when not isolated; unknown clock compares nothing (row 16, true)', () => {
  const c = clockClaim(COARSE);
  assert.ok(c.banner);
  assert.match(c.banner, /not cross-origin isolated/);
  assert.match(c.banner, /COOP\/COEP/);
  assert.match(c.banner, /steps by 0\.1 ms/);
  assert.match(c.banner, /under 2 ms/);
  assert.match(c.banner, /no winner is named/);
  assert.ok(Math.abs(c.floorSeconds - 2e-3) < 1e-15);
  assert.equal(c.severity, 'warning');
  assert.doesNotMatch(c.raceNote + c.timeNote, /few microseconds/, 'the static claim it replaces');
  // an isolated page whose clock is coarse anyway gets a banner too, without blaming isolation
  const iso = clockClaim({ stepMs: 0.1, isolated: true });
  assert.ok(iso.banner);
  assert.doesNotMatch(iso.banner, /not cross-origin isolated/);
  // a non-isolated page whose clock is fine: said, without claiming a coarse step
  const fine = clockClaim({ stepMs: 0.005, isolated: false });
  assert.ok(fine.banner);
  assert.match(fine.banner, /5 µs/);
  assert.doesNotMatch(fine.banner, /steps by (only )?0\.1 ms/);
  for (const stepMs of [null, 0, undefined, NaN]) {
    const u = clockClaim({ stepMs, isolated: true });
    assert.equal(u.floorSeconds, null, String(stepMs));
    assert.match(u.banner, /could not be measured: no timing is compared/);
  }
  assert.equal(clockText(0.005), '5 µs');
  assert.equal(clockText(2), '2 ms');
});

// ---------------------------------------------------------------------------------------------
// Row 19: the race and the clock

test('raceClaim, coarse clock: a 0 s median is not "the only one to reach it"; no ratio, no winner (row 19, false)', () => {
  // stratified's runs take 20-35 us: a 0.1 ms clock reads them as 0 s
  const coarse = quantised(only(EXP, ['uniform', 'stratified', 'importance']), COARSE.stepMs);
  const times = medianTimes(coarse);
  assert.equal(times.stratified, 0, 'the fixture: stratified reads as 0 s on this clock');
  assert.ok(Object.values(times).every(Number.isFinite), 'the fixture: every estimator met the target in most runs');
  const c = raceClaim(coarse, { exact: coarse.scene.exact, clock: COARSE });
  assert.equal(c.winner, null);
  assert.doesNotMatch(c.text, /did not|only one to reach/);
  assert.doesNotMatch(c.text, /∞|Infinity/);
  assert.match(c.text, /under 2 ms/);
  assert.match(c.text, /no winner is named/);
  for (const r of c.ranked) {
    if (r.median < 2e-3) {
      assert.ok(r.tooFast, r.name);
      assert.equal(r.ratio, null, `${r.name}: no ratio under the floor`);
      assert.equal(r.vsFastest, null, `${r.name}: not compared`);
    }
    assert.ok(r.ratio === null || Number.isFinite(r.ratio), `${r.name}: no infinite ratio`);
  }
  // importance takes 1.4 ms: also under 2 ms, so the two are not ordered
  assert.deepEqual(c.evidence.tooFast.slice().sort(), ['importance', 'stratified']);
  assert.match(c.text, /cannot order them/);
  // rows whose runs all met the target are never said to have missed it
  for (const r of c.ranked) if (r.met === r.runs) assert.doesNotMatch(c.text, new RegExp(`${r.name}[^.]*did not reach`));
  // an unknown clock: nothing compared
  const unknown = raceClaim(only(EXP, ['uniform', 'importance']), { exact: EXP.scene.exact, clock: { stepMs: null } });
  assert.equal(unknown.winner, null);
  assert.match(unknown.text, /clock could not be measured/);
  assert.equal(raceClaim(only(EXP, ['uniform', 'importance']), { exact: EXP.scene.exact }).winner, null, 'no clock given: unknown');
});

test('raceClaim, fine clock: the same estimators timed above the floor get a winner and a ratio (row 19, true)', () => {
  const fine = only(EXP, ['uniform', 'importance', 'latin_hypercube']);
  const times = medianTimes(fine);
  const fastest = Object.keys(times).sort((a, b) => times[a] - times[b])[0];
  assert.equal(fastest, 'importance', 'the fixture');
  assert.ok(times.importance >= 20 * FINE.stepMs / 1000, 'the fixture: above the 5 us clock\'s floor');
  const c = raceClaim(fine, { exact: fine.scene.exact, clock: FINE });
  assert.equal(c.winner, 'importance');
  assert.match(c.text, /^importance reaches the target first: \d+× faster than the next, uniform \(rank-sum p = /);
  const next = c.ranked[1];
  assert.ok(Math.abs(next.ratio - times.uniform / times.importance) < 1e-9, 'ratio of the medians');
  // the same data on the coarse clock: importance's 1.4 ms median is under 2 ms, so no winner
  const coarse = raceClaim(fine, { exact: fine.scene.exact, clock: COARSE });
  assert.ok(times.importance < 2e-3, 'the fixture');
  assert.equal(coarse.winner, null);
  assert.match(coarse.text, /^importance reaches the target in under 2 ms/);
  assert.match(coarse.text, /The others take longer: uniform [\d.]+ ms, latin_hypercube [\d.]+ ms\./);
});

// ---------------------------------------------------------------------------------------------
// Row 20: conservative error bars

test('raceClaim: latin_hypercube stops on its conservative bar, with its actual error and ratio (row 20, true)', () => {
  const r = only(EXP, ['uniform', 'importance', 'latin_hypercube']);
  const latin = r.estimators.find((e) => e.name === 'latin_hypercube');
  assert.equal(latin.error_bars_conservative, true, 'the fixture');
  const tol = r.stopping.rel_tol * Math.abs(r.scene.exact);
  const err = median(latin.runs.filter((x) => x.met).map((x) => Math.abs(x.estimate - r.scene.exact)));
  assert.ok(tol / err > 1e4, `the fixture: actual error ${err} far under ${tol}`);
  const c = raceClaim(r, { exact: r.scene.exact, clock: FINE });
  assert.equal(c.ranked[c.ranked.length - 1].name, 'latin_hypercube', 'ranked last');
  const note = c.rowNotes.latin_hypercube.join(' ');
  assert.match(note, /stops on its own conservative error bar \(the iid formula/);
  assert.match(note, /at N = 524288/);
  assert.match(note, /it is last for its error bar, not its accuracy/);
  // the numbers are the data's: the error and the ratio to 2 digits
  const m = note.match(/actual error was ([\d.e+-]+), ([\d.e+-]+)× under the tolerance/);
  assert.ok(m, note);
  assert.ok(Math.abs(Number(m[1]) / err - 1) < 0.06, `${m[1]} against ${err}`);
  assert.ok(Math.abs(Number(m[2]) / (tol / err) - 1) < 0.06, `${m[2]} against ${tol / err}`);
  // the verdict says it: latin_hypercube ranks behind uniform, whose bar is not conservative
  assert.match(c.text, /latin_hypercube stops on its own conservative error bar/);
  // uniform's iid bar: no such note
  assert.deepEqual(c.rowNotes.uniform, []);
  assert.doesNotMatch(c.text, /uniform stops on its own/);
});

test('raceClaim: no "stops late for its bar" when its actual error is near the tolerance, or unknown (row 20, false)', () => {
  // latin_hypercube's answers moved to 0.4 tolerance off the exact value: a bar about right
  const near = withRuns(only(EXP, ['uniform', 'latin_hypercube']), 'latin_hypercube',
    (run, i, tol) => ({ ...run, estimate: EXP.scene.exact + (i % 2 ? 0.4 : -0.4) * tol }));
  const c = raceClaim(near, { exact: near.scene.exact, clock: FINE });
  const note = c.rowNotes.latin_hypercube.join(' ');
  assert.doesNotMatch(note, /stops on its own|not its accuracy/);
  assert.doesNotMatch(c.text, /not its accuracy/);
  assert.match(note, /only 2\.5× under the tolerance/);
  assert.ok(2.5 < CONSERVATIVE_RATIO);
  // without the exact value: no actual error is claimed
  const blind = raceClaim(only(EXP, ['uniform', 'latin_hypercube']), { exact: null, clock: FINE });
  const b = blind.rowNotes.latin_hypercube.join(' ');
  assert.doesNotMatch(b, /actual error was/);
  assert.match(b, /conservative by design/);
  assert.match(b, /without the exact value/);
});

// ---------------------------------------------------------------------------------------------
// Row 21: answers that miss the exact value

test('missAllowance: the largest k with P(Bin(R, 0.05) >= k) >= 0.1', () => {
  const tail = (n, k) => {
    let s = 0;
    for (let j = k; j <= n; ++j) {
      let c = 1;
      for (let i = 1; i <= j; ++i) c *= (n - j + i) / i;
      s += c * 0.05 ** j * 0.95 ** (n - j);
    }
    return s;
  };
  for (const n of [1, 2, 6, 10, 32, 100]) {
    const k = missAllowance(n);
    assert.ok(tail(n, k) >= 0.1, `n = ${n}: P(B >= ${k})`);
    assert.ok(k === n || tail(n, k + 1) < 0.1, `n = ${n}: P(B >= ${k + 1})`);
  }
  assert.equal(missAllowance(6), 1);
  assert.equal(missAllowance(0), 0);
});

test('raceClaim: the fastest whose answers miss the target in 4 of 6 runs is not the winner (row 21, false)', () => {
  const base = only(EXP, ['uniform', 'importance']);
  const wrong = withRuns(base, 'importance', (run, i, tol) => (i < 4 ? { ...run, estimate: EXP.scene.exact + 3 * tol } : run));
  const imp = wrong.estimators.find((e) => e.name === 'importance');
  assert.equal(imp.runs.filter((x) => x.met && !x.within_tolerance).length, 4, 'the variant');
  const c = raceClaim(wrong, { exact: wrong.scene.exact, clock: FINE });
  assert.equal(c.winner, null);
  assert.doesNotMatch(c.text, /reaches the target first/);
  assert.match(c.text, /^importance is fastest but its answers missed the target in 4 of 6 runs/);
  assert.match(c.rowNotes.importance.join(' '), /missed the target in 4 of 6 runs/);
  // two misses are already more than 6 runs allow by chance (1)
  const two = withRuns(base, 'importance', (run, i, tol) => (i < 2 ? { ...run, estimate: EXP.scene.exact - 3 * tol } : run));
  assert.equal(raceClaim(two, { exact: two.scene.exact, clock: FINE }).winner, null);
});

test('raceClaim: the fastest within the tolerance in 6 of 6 (or 5 of 6) runs is the winner (row 21, true)', () => {
  const base = only(EXP, ['uniform', 'importance']);
  assert.ok(base.estimators.every((e) => e.runs.every((r) => r.within_tolerance)), 'the fixture');
  const c = raceClaim(base, { exact: base.scene.exact, clock: FINE });
  assert.equal(c.winner, 'importance');
  assert.deepEqual(c.rowNotes.importance, []);
  const one = withRuns(base, 'importance', (run, i, tol) => (i === 0 ? { ...run, estimate: EXP.scene.exact + 3 * tol } : run));
  assert.equal(raceClaim(one, { exact: one.scene.exact, clock: FINE }).winner, 'importance', 'one miss in 6 is chance');
  // without the exact value nothing can be checked: the times decide
  assert.equal(raceClaim(withRuns(base, 'importance', (run, i, tol) => ({ ...run, estimate: EXP.scene.exact + 3 * tol })),
    { exact: null, clock: FINE }).winner, 'importance');
});

// ---------------------------------------------------------------------------------------------
// Item 4 in the race: reasons in words, visible in the row

test('raceClaim: runs that did not reach the target say why in words, never as a code', () => {
  const r = withRuns(only(EXP, ['uniform', 'importance']), 'uniform',
    (run, i) => (i < 2 ? { ...run, met: false, reason: i ? 'n_max' : 'max_seconds' } : run));
  const c = raceClaim(r, { exact: r.scene.exact, clock: FINE });
  const u = c.ranked.find((x) => x.name === 'uniform');
  assert.equal(u.reachedText, '4/6 (ran out of time, ran out of N)');
  assert.doesNotMatch(u.reachedText, /_/);
  assert.equal(reasonWords('untrusted_error_bar'), 'its error bar could not be trusted');
  assert.equal(reasonWords('no_error_bar'), 'no error bar');
  assert.equal(reasonWords('all_zero'), 'every point gave 0');
  assert.doesNotMatch(reasonWords('some_new_code'), /_/);
  // most runs out: "did not reach" is said of it, as the data show
  const out = withRuns(only(EXP, ['uniform', 'importance']), 'uniform', (run, i) => (i < 4 ? { ...run, met: false, reason: 'max_seconds' } : run));
  const o = raceClaim(out, { exact: out.scene.exact, clock: FINE });
  assert.equal(o.ranked[1].median, Infinity);
  assert.match(o.text, /the only one to reach it in most runs \(uniform did not\)/);
});
