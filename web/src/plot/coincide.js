// Curves that coincide on a plot (one hides the other): the f/p overlay's densities when two
// estimators share p (uniform and stratified: p = 1) or a density matches f / ∫|f|, and weight
// histograms that are the same. The page then draws the later curve dashed over the earlier
// one and says so in the legend. Pure: no DOM (web/test/coincide.test.mjs).

/** The dash pattern of the k-th curve of a group of coinciding curves (0: solid, the first). */
export const COINCIDE_DASHES = Object.freeze([[], [7, 5], [2, 4], [10, 4, 2, 4]]);

/**
 * Two value arrays on the same grid coincide when they have their finite values at the same
 * places, at least one, and each pair differs by at most `rel` times `scale` (default: the
 * larger magnitude of the two arrays; a plot passes the height of its y range, so that a curve
 * less than a line's width away counts as the same).
 */
export function sameCurve(a, b, rel = 1e-3, scale = null) {
  if (!Array.isArray(a) || !Array.isArray(b) || a.length !== b.length) return false;
  const ok = (v) => typeof v === 'number' && Number.isFinite(v);
  let scaleOf = 0;
  let finite = 0;
  for (let i = 0; i < a.length; ++i) {
    if (ok(a[i]) !== ok(b[i])) return false;
    if (!ok(a[i])) continue;
    finite += 1;
    scaleOf = Math.max(scaleOf, Math.abs(a[i]), Math.abs(b[i]));
  }
  if (!finite) return false;
  const tol = rel * (typeof scale === 'number' && scale > 0 ? scale : scaleOf);
  for (let i = 0; i < a.length; ++i) if (ok(a[i]) && Math.abs(a[i] - b[i]) > tol) return false;
  return true;
}

/**
 * For each curve ({name, y}), the curve it coincides with, drawn before it: {of: the first
 * earlier curve's name (the group's solid one) or null, rank: its place in that group (0 for
 * a curve no earlier one matches)}; `rel` and `scale` as for sameCurve. The ranks pick
 * COINCIDE_DASHES.
 */
export function coincidences(curves, rel = 1e-3, scale = null) {
  const out = [];
  for (let i = 0; i < curves.length; ++i) {
    let of = null;
    let rank = 0;
    for (let j = 0; j < i; ++j) {
      if (out[j].of === null && sameCurve(curves[i].y, curves[j].y, rel, scale)) {
        of = curves[j].name;
        rank = 1 + out.filter((o) => o.of === of).length;
        break;
      }
    }
    out.push({ name: curves[i].name, of, rank });
  }
  return out;
}
