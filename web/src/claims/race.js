// What the race card may say about a stopping result (issue 38, items 6 and 8): who reached the
// target first, by how much, and why a row is where it is. The statistics (raceRows' medians and
// their intervals, the rank-sum test) are web/src/race.js's; the words are decided here, from the
// data, so that none of them contradicts the numbers beside it:
//  (a) the clock: a median under its floor (20 steps: clock.js) gets no ratio, the rows under it
//      are not ordered among themselves and no winner is named from them; "did not reach it" is
//      said only of rows whose median is +Infinity (most runs ran out), never of a ratio;
//  (b) the answers: with an exact value, a winner's runs that met the target must also be within
//      the tolerance of the exact value, up to the misses 95% error bars allow by chance;
//  (c) conservative error bars stop late by design: the row says so with its actual error, and
//      the verdict says so when such a row ranks behind one whose error bar is not conservative;
//  (d) why a run did not reach the target, in words, in the row.
// Pure: no DOM (web/test/claims_race_clock.test.mjs, web/test/race.test.mjs).
import { raceRows, mannWhitney, formatSeconds, RACE_ALPHA } from '../race.js';
import { clockClaim, clockText } from './clock.js';
import { CLOCK_STEPS_FITTED } from '../series/time.js';
import { CONSERVATIVE_METHOD_WORDS } from './errorbars.js';

/** The share of runs whose answer may miss the exact value by more than the tolerance by
 *  chance: the tolerance is a 95% half-width. */
export const MISS_RATE = 0.05;
/** A miss count is "within the allowance" while P(Bin(R, MISS_RATE) >= k) >= this. */
export const MISS_LEVEL = 0.1;
/** The actual error must be this many times under the tolerance before a row's error bar is said
 *  to stop it late: a calibrated 95% error bar gives a median |error| about 3 to 4 times under. */
export const CONSERVATIVE_RATIO = 10;

/** The largest k with P(Bin(runs, MISS_RATE) >= k) >= MISS_LEVEL: the misses of the exact value
 *  that calibrated 95% error bars give by chance (0 for no runs). */
export function missAllowance(runs, rate = MISS_RATE, level = MISS_LEVEL) {
  if (!(runs > 0)) return 0;
  let below = 0; // P(B < k)
  let pmf = (1 - rate) ** runs; // P(B = 0)
  let k = 0;
  for (; k < runs; ++k) {
    // P(B >= k + 1) = 1 - P(B <= k)
    below += pmf;
    if (1 - below < level) break;
    pmf *= ((runs - k) / (k + 1)) * (rate / (1 - rate));
  }
  return k;
}

const REASON_WORDS = Object.freeze({
  n_max: 'ran out of N',
  max_seconds: 'ran out of time',
  no_error_bar: 'no error bar',
  untrusted_error_bar: 'its error bar could not be trusted',
  all_zero: 'every point gave 0',
  tolerance_met: 'reached the target',
});

/** A stopping run's reason code in words (an unknown code with its underscores as spaces). */
export function reasonWords(code) {
  return REASON_WORDS[code] || String(code ?? 'unknown reason').replace(/_/g, ' ');
}

const METHOD_WORDS = CONSERVATIVE_METHOD_WORDS;

/** Does the estimator's error bar overstate its spread by design (the core's word)? */
export function conservativeBar(e) {
  return Boolean(e) && (e.error_bars_conservative === true || Object.prototype.hasOwnProperty.call(METHOD_WORDS, e.error_method));
}

function median(xs) {
  const s = xs.filter(Number.isFinite).sort((a, b) => a - b);
  if (!s.length) return null;
  const h = Math.floor(s.length / 2);
  return s.length % 2 ? s[h] : (s[h - 1] + s[h]) / 2;
}

/** Two significant digits, exponent without '+' for large and small values ("4.4e5", "3.9e-9"). */
function sig2(v) {
  if (!Number.isFinite(v)) return String(v);
  const a = Math.abs(v);
  if (a !== 0 && (a < 1e-3 || a >= 1e4)) return v.toExponential(1).replace('e+', 'e');
  return String(Number(v.toPrecision(2)));
}

function ratioText(r) {
  return `${r >= 10 ? Math.round(r) : Number(r.toPrecision(2))}×`;
}

function pText(p) {
  if (p === null || p === undefined) return '—';
  return p < 1e-4 ? p.toExponential(0) : String(Number(p.toPrecision(2)));
}

function list(names) {
  if (names.length < 2) return names.join('');
  return `${names.slice(0, -1).join(', ')} and ${names[names.length - 1]}`;
}

/** The tolerance the runs were judged against: max(abs_tol, rel_tol |exact|) as the core's
 *  within_tolerance; else the runs' own targets' median. */
function toleranceOf(result, exact, runs) {
  const s = (result && result.stopping) || {};
  if (Number.isFinite(exact)) {
    const t = Math.max(Number(s.abs_tol) || 0, (Number(s.rel_tol) || 0) * Math.abs(exact));
    if (t > 0) return t;
  }
  return median(runs.map((r) => r.target));
}

/** A conservative row's actual error at its stop: the median over its met runs of
 *  |estimate - exact| and of tolerance / |estimate - exact|, at its median N. */
function actualError(e, row, result, exact) {
  if (!Number.isFinite(exact)) return null;
  const met = (e.runs || []).filter((r) => r.met && Number.isFinite(r.estimate));
  if (!met.length) return null;
  const tol = toleranceOf(result, exact, met);
  const errors = met.map((r) => Math.abs(r.estimate - exact));
  const error = median(errors);
  if (!(tol > 0) || error === null) return null;
  const ratio = error > 0 ? tol / error : Infinity;
  return { error, tolerance: tol, ratio, n: row.n, runs: met.length };
}

/**
 * The race's claim from a stopping result: {winner, ranked, text, rowNotes, tied, short,
 * severity, holds, evidence}. `exact` is the scene's exact value (null: unknown), `clock` a
 * clockClaim or its input {stepMs, isolated} (missing: an unknown clock, so no time is
 * compared). Each ranked row is raceRows' row with: tooFast (median under the clock's floor, or
 * any finite median when the clock is unknown), ratio and vsFastest (against the fastest row the
 * clock can time; null when not comparable), reachedText ("4/6 (ran out of time)"), misses and
 * allowance (met runs farther than the tolerance from the exact value, and how many chance
 * allows), conservative, actual (a conservative row's actual error) and notes (sentences).
 */
export function raceClaim(result, { exact = null, clock = null } = {}) {
  const ck = clock && Object.prototype.hasOwnProperty.call(clock, 'floorSeconds') ? clock : clockClaim(clock || {});
  const floor = ck.floorSeconds;
  const step = ck.evidence ? ck.evidence.stepMs : null;
  const exactKnown = typeof exact === 'number' && Number.isFinite(exact);
  const estimators = (result && result.estimators) || [];
  const rows = raceRows(result).map((row, i) => {
    const e = estimators[i] || {};
    const runs = Array.isArray(e.runs) ? e.runs : [];
    const finite = Number.isFinite(row.median);
    const judged = exactKnown ? runs.filter((r) => r.met && typeof r.within_tolerance === 'boolean') : [];
    const misses = judged.length ? judged.filter((r) => !r.within_tolerance).length : null;
    const allowance = judged.length ? missAllowance(judged.length) : null;
    const reasonText = row.reasons.map(reasonWords);
    return {
      ...row,
      tooFast: finite && (floor === null || row.median < floor),
      ratio: null,
      vsFastest: null,
      reasonText,
      reachedText: `${row.met}/${row.runs}${row.met < row.runs ? ` (${reasonText.join(', ')})` : ''}`,
      misses,
      judged: judged.length,
      allowance,
      accurate: misses === null ? null : misses <= allowance,
      conservative: conservativeBar(e),
      method: e.error_method ?? null,
      actual: conservativeBar(e) ? actualError(e, row, result, exact) : null,
      notes: [],
    };
  });
  const finite = rows.filter((r) => Number.isFinite(r.median)).sort((x, y) => x.median - y.median);
  const out = rows.filter((r) => !Number.isFinite(r.median));
  const ranked = [...finite, ...out];
  const fast = finite.filter((r) => r.tooFast);
  const timed = finite.filter((r) => !r.tooFast);
  // Every comparison is against the fastest row the clock can time.
  const ref = timed[0] || null;
  if (ref) {
    for (const r of [...timed.slice(1), ...out]) {
      r.vsFastest = mannWhitney(ref.times, r.times).p;
      r.ratio = Number.isFinite(r.median) ? r.median / ref.median : null;
    }
  }
  const floorText = floor === null ? null : clockText(floor * 1000);
  const stepText = step === null ? null : clockText(step);

  // Row notes: the clock, the answers, the reasons a run stopped short, conservative error bars.
  for (const r of ranked) {
    if (r.tooFast) {
      r.notes.push(floor === null
        ? 'the clock could not be measured: its time is not compared'
        : `median under ${floorText} (${CLOCK_STEPS_FITTED} steps of this clock's ${stepText}): too fast for this clock to compare`);
    }
    if (r.accurate === false) {
      r.notes.push(`its answers missed the target in ${r.misses} of ${r.judged} runs (95% error bars allow ${r.allowance} by chance)`);
    }
  }
  const nonConservativeAhead = (r) => {
    if (r.tooFast) return null; // the clock cannot say what is ahead of it
    return ranked.find((q) => q !== r && !q.conservative && Number.isFinite(q.median)
      && (!Number.isFinite(r.median) || q.median < r.median)) || null;
  };
  const verdictExtras = [];
  for (const r of ranked) {
    if (!r.conservative) continue;
    const how = METHOD_WORDS[r.method] || 'wider than the estimator\'s spread by design';
    const ahead = nonConservativeAhead(r);
    const a = r.actual;
    if (a && a.ratio >= CONSERVATIVE_RATIO && r.accurate !== false) {
      const last = ranked[ranked.length - 1] === r && ranked.length > 1;
      const where = ahead
        ? (last ? 'it is last for its error bar, not its accuracy' : `it ranks behind ${ahead.name} for its error bar, not its accuracy`)
        : 'its error bar, not its accuracy, sets when it stops';
      const at = a.n !== null ? ` at N = ${a.n}` : '';
      const note = `stops on its own conservative error bar (${how}):${at} its actual error was ${sig2(a.error)}, `
        + `${a.ratio === Infinity ? 'exactly 0' : `${sig2(a.ratio)}×`} under the tolerance; ${where}`;
      r.notes.push(note);
      if (ahead) verdictExtras.push(`${r.name} ${note}.`);
    } else if (a) {
      // The data do not show this run stopping late: its error is about what its bar says.
      r.notes.push(`its error bar is conservative by design (${how}), but here its actual error${a.n !== null ? ` at N = ${a.n}` : ''} `
        + `was ${sig2(a.error)}, only ${sig2(a.ratio)}× under the tolerance`);
    } else {
      const note = `its error bar is conservative by design (${how}), so it can stop later than its accuracy requires`
        + (exactKnown ? ' (no run met the target, so its actual error there is unknown)' : ' (without the exact value, its actual error is unknown)');
      r.notes.push(note);
      if (ahead && !exactKnown) verdictExtras.push(`${r.name}'s ${note.replace(/^its /, '')}.`);
    }
  }

  let winner = null;
  let tied = [];
  let text;
  if (!rows.length) {
    text = '';
  } else if (!finite.length) {
    text = 'No estimator reached the target in most of its runs within the budget.';
  } else if (fast.length) {
    // The fastest median is under the floor (or the clock is unknown): no winner from it.
    const names = fast.map((r) => r.name);
    if (floor === null) {
      text = 'The clock could not be measured, so the times are not compared and no winner is named.';
    } else if (fast.length === 1) {
      text = `${names[0]} reaches the target in under ${floorText} (median), fewer than ${CLOCK_STEPS_FITTED} steps of this clock (${stepText}): `
        + 'the clock cannot time it, so no ratio and no winner is named.';
    } else {
      text = `${list(names)} reach the target in under ${floorText} (median), fewer than ${CLOCK_STEPS_FITTED} steps of this clock (${stepText}): `
        + 'this clock cannot order them, so no ratio and no winner is named.';
    }
    if (floor !== null && timed.length) {
      text += ` ${timed.length === 1 ? 'The other takes' : 'The others take'} longer: ${timed.map((r) => `${r.name} ${formatSeconds(r.median)}`).join(', ')}.`;
    }
    if (out.length) text += ` ${list(out.map((r) => r.name))} did not reach it in most runs.`;
  } else {
    const best = ref;
    tied = ranked.slice(1).filter((r) => !(r.vsFastest < RACE_ALPHA)).map((r) => r.name);
    if (ranked.length === 1) {
      winner = best.name;
      text = `${best.name} reached the target in ${best.met} of ${best.runs} runs.`;
    } else if (!tied.length) {
      const second = ranked[1];
      const how = Number.isFinite(second.median)
        ? `${ratioText(second.ratio)} faster than the next, ${second.name} (rank-sum p = ${pText(second.vsFastest)})`
        : `the only one to reach it in most runs (${ranked.length > 2 ? `${second.name} and the others` : second.name} did not)`;
      winner = best.name;
      text = `${best.name} reaches the target first: ${how}.`;
    } else {
      const names = [best.name, ...tied];
      tied = names;
      text = `No significant difference between ${names.join(', ')} (rank-sum p >= ${RACE_ALPHA} against the fastest median, ${best.name}).`;
    }
    if (winner && best.accurate === false) {
      text = ranked.length === 1
        ? `${best.name} reached the target in ${best.met} of ${best.runs} runs, but its answers missed the target in ${best.misses} of ${best.judged} runs `
          + `(95% error bars allow ${best.allowance} by chance).`
        : `${best.name} is fastest but its answers missed the target in ${best.misses} of ${best.judged} runs `
          + `(95% error bars allow ${best.allowance} by chance), so no winner is named.`;
      winner = null;
    }
  }
  if (verdictExtras.length) text += ` ${verdictExtras.join(' ')}`;
  const rowNotes = Object.fromEntries(ranked.map((r) => [r.name, r.notes.slice()]));
  return {
    winner,
    tied,
    ranked,
    text,
    rowNotes,
    short: winner ? `${winner} first` : 'no winner named',
    severity: 'note',
    holds: winner ? true : null,
    evidence: {
      floorSeconds: floor,
      stepMs: step,
      exact: exactKnown ? exact : null,
      fastest: ranked.length ? ranked[0].name : null,
      fastestTimed: ref ? ref.name : null,
      tooFast: fast.map((r) => r.name),
      medians: Object.fromEntries(ranked.map((r) => [r.name, r.median])),
    },
  };
}
