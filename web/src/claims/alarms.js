// The banner above the plots: how many errors and warnings the run has, told apart by whether
// they persist. A flag raised at the largest N an estimator reached, or at half its levels or
// more, describes the estimator; one raised only in the lower half of its levels (small N), or at a few
// scattered levels among many checked (a test at p < 1e-3 repeated over every level fires now
// and then by chance), is listed below but does not turn the banner red.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { collectWarnings } from '../series/text.js';

/** Level flags that describe too few points at a small N (the points saw little of f): at the
 *  lower levels only, they are "small N". */
const SMALL_N_CODES = new Set(['zero_error_bar', 'low_ess', 'skewed_weights', 'nonfinite']);
/** Level flags from a test at a p-value threshold, repeated at every level: one such level among
 *  many may be chance. Any other level flag (an exact value outside the interval, values that
 *  underflow) is a fact at that level. */
const CHANCE_CODES = new Set(['error_bars_understate', 'error_bars_unstable', 'iterations_disagree',
  'conservative_error_bars', 'replicate_far_off']);

/**
 * Classifies each collected warning: 'persistent' (estimator-level; raised at the largest N the
 * estimator reached, or at half its levels or more; or a fact that no chance explains),
 * 'small_n' (a few-points flag raised only in the lower half of the levels) or 'isolated' (a
 * threshold test that fired at a single level, not the largest).
 */
export function flagPersistence(w, record) {
  if (w.scope !== 'level') return 'persistent';
  const ns = (record.levels || []).map((l) => l.n);
  const largest = ns.length ? ns[ns.length - 1] : null;
  if (w.n.includes(largest) || w.n.length * 2 >= ns.length) return 'persistent';
  const lowerHalf = ns.slice(0, Math.floor(ns.length / 2));
  if (SMALL_N_CODES.has(w.code) && w.n.every((n) => lowerHalf.includes(n))) return 'small_n';
  if (CHANCE_CODES.has(w.code) && w.n.length === 1) return 'isolated';
  return 'persistent';
}

/**
 * The banner: {severity ('error', 'warning', 'note' or null when there is nothing), parts:
 * [{severity, text, who}], text, counts}. Only persistent errors make it an error.
 */
export function alarmSummary(records, order, { nName = 'N' } = {}) {
  const warnings = collectWarnings(records, order);
  const levelsChecked = order.reduce((k, name) => k + ((records[name] && records[name].levels.length) || 0), 0);
  const groups = { error: [], warning: [], small: [], isolated: [] };
  for (const w of warnings) {
    if (w.severity === 'info') continue;
    const kind = flagPersistence(w, records[w.estimator]);
    if (kind === 'persistent') groups[w.severity === 'error' ? 'error' : 'warning'].push(w);
    else groups[kind === 'small_n' ? 'small' : 'isolated'].push(w);
  }
  const who = (list) => [...new Set(list.map((w) => w.estimator))].join(', ');
  const plural = (k, word) => `${k} ${word}${k === 1 ? '' : 's'}`;
  const parts = [];
  if (groups.error.length) parts.push({ severity: 'error', text: plural(groups.error.length, 'error'), who: who(groups.error) });
  if (groups.warning.length) parts.push({ severity: 'warning', text: plural(groups.warning.length, 'warning'), who: who(groups.warning) });
  if (groups.small.length) {
    const upTo = Math.max(...groups.small.flatMap((w) => w.n));
    parts.push({ severity: 'note', text: `${plural(groups.small.length, 'flag')} at small ${nName} only (${nName} ≤ ${upTo})`, who: who(groups.small) });
  }
  if (groups.isolated.length) {
    const levels = groups.isolated.reduce((k, w) => k + w.n.length, 0);
    parts.push({ severity: 'note',
      text: `${plural(levels, 'isolated level flag')} among ${levelsChecked} levels checked (tests repeated at every level fire now and then by chance)`,
      who: who(groups.isolated) });
  }
  const severity = groups.error.length ? 'error' : groups.warning.length ? 'warning' : parts.length ? 'note' : null;
  const text = parts.map((p) => `${p.text} (${p.who})`).join('; ');
  return { severity, parts, text, counts: { errors: groups.error.length, warnings: groups.warning.length,
    small: groups.small.length, isolated: groups.isolated.length, levelsChecked } };
}
