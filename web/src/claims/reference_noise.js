// A relative MSE below the reference's own noise is not a number the data support: the core
// subtracts the reference's per-pixel variance from each image's error [RousselleKnausZwicker11]
// and marks a level whose relative MSE is negative or below the reference's relative-MSE floor
// (`below_reference_noise`; the floor is the result's scene.reference.relative_mse_floor, or a
// part's reference_summary.relative_mse_floor: docs/render-scenes.md, "The reference's noise").
// Such a value is shown as "at the reference's noise (below X)", X the floor, never as a number:
// the study's tables and equal-time verdict use these functions, and the live view can too.
// Pure (no DOM): web/test/claims.test.mjs runs it under Node.
import { fmt } from '../series/text.js';

function floorOk(floor) {
  return typeof floor === 'number' && Number.isFinite(floor) && floor > 0;
}

/**
 * Is a relative MSE at the reference's noise? `below` the core's own verdict (a level's
 * below_reference_noise) when known, else judged from the value: not above `floor` (a negative
 * value included).
 */
export function atReferenceNoise(value, { floor = null, below = null } = {}) {
  if (below === true || below === false) return below;
  if (typeof value !== 'number' || !Number.isFinite(value)) return false;
  return value <= 0 || (floorOk(floor) && value < floor); // the core's below_reference_noise
}

/** The words for a relative MSE at the reference's noise: "at the reference's noise (below X)";
 *  `root`: the relative RMSE's, below sqrt(X). Without a known floor, no "below". */
export function referenceNoiseWords(floor = null, { root = false, digits = 2 } = {}) {
  if (!floorOk(floor)) return 'at the reference\'s noise';
  return `at the reference's noise (below ${fmt(root ? Math.sqrt(floor) : floor, digits)})`;
}

/**
 * A relative MSE (or, `root`, a relative RMSE) as the page shows it: its number, or the words
 * of referenceNoiseWords when it is at the reference's noise (`below`, `floor` as in
 * atReferenceNoise; the root's value is compared as its square).
 */
export function relativeMseText(value, { floor = null, below = null, root = false, digits = 4 } = {}) {
  const squared = root && typeof value === 'number' ? value * value : value;
  if (atReferenceNoise(squared, { floor, below })) return referenceNoiseWords(floor, { root });
  return fmt(value, digits);
}

/** The reference's relative-MSE floor of a render result (whole, or a part), or null. */
export function referenceFloorOf(result) {
  if (!result) return null;
  const ref = result.scene && result.scene.reference;
  const v = ref && typeof ref.relative_mse_floor === 'number' ? ref.relative_mse_floor
    : result.reference_summary ? result.reference_summary.relative_mse_floor : null;
  return floorOk(v) ? v : null;
}
