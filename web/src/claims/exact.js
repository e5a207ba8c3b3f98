// When the page may call an estimator exact. The core's exact_to_roundoff says that the
// replicates agree to round-off (f/p constant on the points); that is not "exact": a point set
// that saw nothing of f agrees on 0, and values whose squares underflow agree too. With the exact
// value known, an exact estimator must also equal it; without it, agreement proves nothing.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.

/** Relative distance from the exact value that still counts as round-off: compensated sums of
 *  up to 2^24 terms stay far inside it, and any real error of a Monte Carlo estimate at the
 *  page's N is far outside. */
export const ROUNDOFF_RELATIVE = 1e-9;

function isNumber(v) {
  return typeof v === 'number' && Number.isFinite(v);
}

/**
 * What a level is: 'exact' (its replicates agree to round-off and, the exact value known, equal
 * it), 'agree' (they agree to round-off but the exact value is unknown, or the points are a
 * deterministic set: agreement proves nothing) or 'no'.
 */
export function levelExactness(level, exact = null) {
  if (!level || level.exact_to_roundoff !== true) return 'no';
  if (level.values_underflow === true || (level.no_estimate_runs || 0) > 0) return 'no';
  if (!isNumber(level.mean)) return 'no';
  if (!isNumber(exact)) return 'agree';
  const scale = Math.max(Math.abs(exact), Math.abs(level.mean));
  const tol = ROUNDOFF_RELATIVE * scale;
  if (!(Math.abs(level.mean - exact) <= tol)) return 'no';
  if (isNumber(level.mse) && !(Math.sqrt(level.mse) <= tol)) return 'no';
  // Exact value 0 and every estimate 0: exact only if f/p really is 0, which a deterministic set
  // or a set that never saw f cannot show; the core then reports no exact_to_roundoff anyway.
  if (scale === 0 && level.deterministic === true) return 'agree';
  return 'exact';
}

/**
 * An estimator's exactness over its levels: `at` per level, `all` ('exact', 'agree' or null
 * when not every level is the same), and `any` (some level is exact).
 */
export function recordExactness(record, exact = null) {
  const levels = (record && record.levels) || [];
  const at = levels.map((l) => levelExactness(l, exact));
  const all = at.length && at.every((k) => k === at[0]) && at[0] !== 'no' ? at[0] : null;
  return { at, all, any: at.includes('exact'), anyAgree: at.includes('agree') };
}

/** The words for an estimator whose every level is exact or agrees (null otherwise). */
export function exactnessText(kind) {
  if (kind === 'exact') return 'exact: every replicate equals the exact value to round-off, at every N';
  if (kind === 'agree') {
    return 'zero spread at every N: every replicate gives the same value; without the exact value '
      + 'the page cannot tell an exact estimator from a shared wrong answer';
  }
  return null;
}
