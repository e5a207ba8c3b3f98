// Compares two mcplay result JSON files field by field, ignoring timings, thread counts and
// the ray accelerator (each build picks brute force or the BVH by its own costs; both give the
// same hits, which test_render_accel checks).
// Estimates (per-replicate values and their means) must agree to 1e-12 relative; derived
// spreads (variances, standard errors) amplify last-bit differences of the estimates by
// mean^2 / variance, so they are held to 1e-6 relative, or to 1e-12 of the problem's scale
// (squared for variances) where they are themselves round-off (an exact estimator's
// "variance" of 1e-33 carries no digits to compare).
import { readFileSync } from 'node:fs';

const [a, b] = process.argv.slice(2).map((f) => JSON.parse(readFileSync(f, 'utf8')));
const ignored = new Set(['time_mean_s', 'time_std_s', 'time_median_s', 'time_median_ci95_s', 'time_total_s', 'training_time_mean_s', 'efficiency', 'wall_time_s', 'threads',
  'rays_per_second', 'seconds', 'file', 'accel']);
let worst = 0, worstPath = '', worstDerived = 0, worstDerivedPath = '', mismatches = [];
const scaleOf = (r) => {
  let m = Math.abs(r.scene?.exact ?? 0);
  for (const e of r.estimators ?? []) for (const l of e.levels ?? []) m = Math.max(m, Math.abs(l.mean ?? 0));
  return Math.max(m, 1e-300);
};
const scale = Math.max(scaleOf(a), scaleOf(b));
const roundoff = (diff) => diff <= 1e-12 * scale || diff <= 1e-12 * scale * scale;
const isEstimate = (path) => /\.mean$|\.replicates\.estimate\.\d+$|\.exact$/.test(path);

function walk(x, y, path) {
  if (typeof x === 'number' && typeof y === 'number') {
    const scale = Math.max(Math.abs(x), Math.abs(y));
    const rel = scale === 0 ? 0 : Math.abs(x - y) / scale;
    if (isEstimate(path)) {
      if (rel > worst) { worst = rel; worstPath = path; }
    } else if (rel > worstDerived && !roundoff(Math.abs(x - y))) { worstDerived = rel; worstDerivedPath = path; }
    return;
  }
  if (x === null || y === null || typeof x !== 'object' || typeof y !== 'object') {
    if (x !== y) mismatches.push(`${path}: ${JSON.stringify(x)} vs ${JSON.stringify(y)}`);
    return;
  }
  const keys = new Set([...Object.keys(x), ...Object.keys(y)]);
  for (const k of keys) if (!ignored.has(k)) walk(x[k], y[k], `${path}.${k}`);
}
walk(a, b, '');
const name = a.scene?.name ?? '?';
if (mismatches.length) console.log(`${name}: structural differences:\n  ${mismatches.slice(0, 5).join('\n  ')}`);
console.log(`${name}: native vs wasm, largest relative difference: estimates ${worst.toExponential(2)}` +
  `${worst ? ' (' + worstPath + ')' : ''}, derived ${worstDerived.toExponential(2)}` +
  `${worstDerived ? ' (' + worstDerivedPath + ')' : ''}`);
process.exit(mismatches.length || worst > 1e-12 || worstDerived > 1e-6 ? 1 : 0);
