// What the page may say about an estimator's error bars: conservative "by design" only where
// this run's coverage and z-scores show it; coverage at the N it was measured; which curves
// coincide and hide each other.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { fmt } from '../series/text.js';
import { zScores } from '../series/calibration.js';
import { levelExactness } from './exact.js';

const Z95 = 1.959963984540054;
/** A z beyond this is an interval far too narrow, whatever the design. */
export const Z_FAR = 5;

/** The error methods whose bars are wider than the estimator's spread by design, in words
 *  (the core's error_method_conservative). */
export const CONSERVATIVE_METHOD_WORDS = Object.freeze({
  collapsed_strata: 'collapsed strata: neighbouring cells paired',
  iid_conservative: 'the iid formula, wider than this design\'s spread',
});

/** Why an estimator's error bars are wider than its spread by design (the core's
 *  error_bars_conservative and error_method), or null. */
export function conservativeWhy(record) {
  if (!record || record.error_bars_conservative !== true) return null;
  return CONSERVATIVE_METHOD_WORDS[record.error_method] || 'wider than the estimator\'s spread by design';
}

/** The lower edge of the binomial 95% band of the coverage of R replicates around 0.95. */
export function coverageBandLow(reps) {
  return 0.95 - Z95 * Math.sqrt(0.95 * 0.05 / Math.max(reps, 1));
}

const FAILING = new Set(['exact_outside_ci', 'error_bars_understate', 'replicate_far_off']);

/**
 * The conservative-error-bar claim of an estimator, or null when its error bars are not
 * conservative by design: {text (calibration legend), coverageText (coverage legend), holds
 * (true: this run shows it; false: it does not, and the text says what it shows; null: without
 * the exact value the page can check only the spread), evidence}.
 */
export function conservativeClaim(record, { exact = null, reps = null, nName = 'N' } = {}) {
  const why = conservativeWhy(record);
  if (!why) return null;
  const known = typeof exact === 'number' && Number.isFinite(exact);
  const levels = (record.levels || []).filter((l) => levelExactness(l, exact) === 'no');
  // Exact (or only agreeing) at every level: no error bar to judge, nothing to claim.
  if (!levels.length) return null;
  const zs = zScores(levels, known ? exact : null);
  const far = zs.z.filter((z) => Math.abs(z) > Z_FAR).length;
  const flaggedAt = levels.filter((l) => (l.warnings || []).some((w) => FAILING.has(w.code))).map((l) => l.n);
  const flagged = [...new Set(levels.flatMap((l) => (l.warnings || []).map((w) => w.code)).filter((c) => FAILING.has(c)))];
  const low = [];
  let lowest = null;
  if (known) {
    for (const l of levels) {
      if (typeof l.coverage95 !== 'number') continue;
      const band = coverageBandLow(reps || l.reps || 32);
      if (l.coverage95 < band) low.push(l.n);
      if (!lowest || l.coverage95 < lowest.coverage) lowest = { coverage: l.coverage95, n: l.n };
    }
  }
  const evidence = { far, zCount: zs.z.length, low, lowest, flagged };
  const shows = [];
  if (low.length) shows.push(`coverage ${fmt(lowest.coverage, 3)} at ${nName} = ${lowest.n}${low.length > 1 ? ` (below the 95% band at ${low.length} ${nName})` : ''}`);
  if (far) shows.push(`${far} z beyond ±${Z_FAR}`);
  if (!shows.length && flagged.length) shows.push(`the core flags its error bars as too small at ${nName} = ${flaggedAt.join(', ')}`);
  if (shows.length) {
    const text = `error bars meant to be conservative (${why}), but not in this run: ${shows.join(', ')}`;
    return { text, coverageText: text, holds: false, evidence };
  }
  if (!known) {
    return { text: `conservative error bars by design (${why}); without the exact value only their spread is checked: no z beyond ±${Z_FAR}`,
      coverageText: null, holds: null, evidence };
  }
  return { text: `conservative error bars (${why}): z narrower than N(0, 1), as designed`,
    coverageText: `conservative error bars (${why}): at or above 0.95 within its band at every ${nName}, as designed`,
    holds: true, evidence };
}

/** The coverage legend's number: the last measured coverage, at the N where it was measured. */
export function coverageText(x, y, nName = 'N') {
  for (let i = y.length - 1; i >= 0; i--) {
    if (y[i] !== null && y[i] !== undefined) return `${fmt(y[i], 3)} at ${nName} = ${x[i]}`;
  }
  return '—';
}

/** Groups of series (by name) whose y values coincide at every x (within `tol`): drawn on
 *  top of each other, all but the last drawn are hidden. Returns [[names...], ...]. */
export function coincidentGroups(series, tol = 1e-9) {
  const groups = [];
  const used = new Set();
  const same = (a, b) => a.length === b.length && a.some((v) => v !== null && v !== undefined)
    && a.every((v, i) => (v === null || v === undefined) ? (b[i] === null || b[i] === undefined)
      : (typeof b[i] === 'number' && Math.abs(v - b[i]) <= tol * Math.max(1, Math.abs(v))));
  for (let i = 0; i < series.length; i++) {
    if (used.has(i)) continue;
    const g = [series[i].name];
    for (let j = i + 1; j < series.length; j++) {
      if (!used.has(j) && same(series[i].y, series[j].y)) {
        g.push(series[j].name);
        used.add(j);
      }
    }
    if (g.length > 1) groups.push(g);
  }
  return groups;
}

/** The legend note of a series that coincides with others ("same line as a and b"), or null. */
export function coincidentNote(name, groups) {
  const g = groups.find((x) => x.includes(name));
  if (!g) return null;
  return `same line as ${g.filter((n) => n !== name).join(' and ')} (drawn on top of each other)`;
}

/** The calibration legend's count: "93% within ±1.96 (416 z, all N)". */
export function withinText(s, which = 'all', nName = 'N') {
  if (!s.total) return null;
  return `${(100 * s.within2 / s.total).toFixed(0)}% within ±1.96 (${s.total} z, ${which === 'all' ? `all ${nName}` : `${nName} = ${which}`})`;
}
