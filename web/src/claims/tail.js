// The tail of an estimator's weights in words, from the core's severity rather than the tail
// index alone: Hill's index over the few largest weights of one level is noisy (a render
// estimator's per-pixel samples give 1.1-1.6 on Veach's scene, whose MIS weights are bounded),
// so "infinite variance" is said only where the core raises heavy_tail at warning or error, and
// an index at or below 2 under a flag at info (a render estimator's bounded contributions:
// src/render/contribution_bound.*) or no flag is said to look heavy, with the core's reason.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { fmt } from '../series/text.js';
import { heavyTailAlarm } from './fit.js';
import { tailWords } from './words.js';

function fourthMomentAlarm(record) {
  return ((record && record.warnings) || []).some((w) => w.code === 'heavy_tail_4'
    && (w.severity === 'warning' || w.severity === 'error'));
}

/** The bound the core found on a render estimator's contributions, or null. */
function bound(record) {
  const b = record && record.contribution_bound;
  return b && b.bounded === true ? b : null;
}

/** The tail of `record`'s weights at `level` (its tail_index) in words. */
export function tailText(record, level) {
  const index = level ? level.tail_index : null;
  if (typeof index !== 'number' || !Number.isFinite(index) || index <= 0 || index > 4) return tailWords(index);
  const b = bound(record);
  const bounded = b ? `the contributions are bounded${b.reason ? ` (${b.reason})` : ''}` : null;
  if (index <= 2) {
    if (heavyTailAlarm(record)) return tailWords(index);
    return bounded ? `looks heavy (tail index ${fmt(index, 3)}), but the variance is finite: ${bounded}`
      : `looks heavy (tail index ${fmt(index, 3)}), but the core raises no alarm: no persistent sign of an infinite variance`;
  }
  if (fourthMomentAlarm(record)) return tailWords(index);
  return `looks heavy in the 4th moment (tail index ${fmt(index, 3)}), but the core raises no alarm${bounded ? `: ${bounded}` : ''}`;
}
