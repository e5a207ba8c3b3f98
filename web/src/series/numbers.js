// Numbers the other series modules share: the N ladder, the positive values a log axis can draw,
// sorted unions of x values, rounding to 9 digits.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.

/** The core's N ladder: every power of two in [nMin, nMax]. */
export function ladder(nMin, nMax) {
  const out = [];
  if (!(nMin >= 1) || !(nMax >= nMin)) return out;
  for (let n = 1; n <= nMax; n *= 2) if (n >= nMin) out.push(n);
  return out;
}

/** v when it can sit on a log axis (a finite number > 0), else null. */
export function positive(v) {
  return typeof v === 'number' && Number.isFinite(v) && v > 0 ? v : null;
}

/** The distinct values, sorted increasingly (the x values of several series on one axis). */
export function unionSorted(values) {
  return [...new Set(values)].sort((a, b) => a - b);
}

/** v rounded to 9 decimal places (bin edges and x values free of float noise). */
export function round9(v) {
  return Math.round(v * 1e9) / 1e9;
}
