// The sampler lab's display mappings, pure (no DOM): values to colours, the heat maps' grids,
// the spectrum's brightness, and RGBA pixel buffers a canvas puts as they are. Nothing here is
// a statistic: the counts, densities and powers are the core's.

// Viridis at 9 stops (perceptually uniform, readable in grey and under colour blindness).
const VIRIDIS = [
  [68, 1, 84], [71, 44, 122], [59, 81, 139], [44, 113, 142], [33, 144, 141],
  [39, 173, 129], [92, 200, 99], [170, 220, 50], [253, 231, 37],
];
// A blue-white-red diverging map (ColorBrewer RdBu, reversed: blue below, red above).
const DIVERGING = [
  [33, 102, 172], [67, 147, 195], [146, 197, 222], [209, 229, 240], [247, 247, 247],
  [253, 219, 199], [244, 165, 130], [214, 96, 77], [178, 24, 43],
];
/** Where there is nothing to show (an expected count of zero, a value that is not a number). */
export const NO_VALUE = Object.freeze([200, 200, 200]);

function lerpStops(stops, t) {
  const x = Math.min(1, Math.max(0, t)) * (stops.length - 1);
  const i = Math.min(stops.length - 2, Math.floor(x));
  const f = x - i;
  return stops[i].map((c, k) => Math.round(c + f * (stops[i + 1][k] - c)));
}

/** t in [0, 1] (clipped) to a viridis colour [r, g, b]; not a number gives NO_VALUE. */
export function sequentialColor(t) {
  return Number.isFinite(t) ? lerpStops(VIRIDIS, t) : NO_VALUE.slice();
}

/** The residual map's fixed scale: |r| = RESIDUAL_SCALE standardised residuals and beyond are
 *  full blue or red, whatever the largest residual of the map (noise stays pale beside a wild
 *  bin, and two maps compare by colour). */
export const RESIDUAL_SCALE = 5;

/** Where a standardised residual sits on the diverging map, in [0, 1] (0.5: white): the signed
 *  power |r / RESIDUAL_SCALE|^1.5, so that noise (|r| <= 2: 25% of the way) stays pale and
 *  structure (|r| >= RESIDUAL_SCALE) saturates. */
export function residualPosition(r) {
  const a = Math.min(1, Math.abs(r) / RESIDUAL_SCALE) ** 1.5;
  return 0.5 + 0.5 * Math.sign(r) * a;
}

/** A standardised residual to a diverging colour on the fixed scale: 0 white, -RESIDUAL_SCALE
 *  and below full blue, +RESIDUAL_SCALE and above full red; not a number gives NO_VALUE. */
export function residualColor(r) {
  if (!Number.isFinite(r)) return NO_VALUE.slice();
  return lerpStops(DIVERGING, residualPosition(r));
}

/**
 * The heat map of a flattened array over `bins` = [nx] or [nx, ny]: {nx, ny, at(i, j)} with i
 * the first coordinate (the column, left to right) and j the second (the row, drawn bottom to
 * top); the first coordinate varies fastest in `values` (index i + nx j). Throws when the
 * length is not nx ny.
 */
export function heatGrid(values, bins) {
  const nx = bins[0];
  const ny = bins.length > 1 ? bins[1] : 1;
  if (!Array.isArray(values) || values.length !== nx * ny) {
    throw new Error(`heat map: ${values && values.length} values for ${nx} x ${ny} bins`);
  }
  return { nx, ny, at: (i, j) => values[i + nx * j] };
}

/**
 * The maps of a warp test over its first two natural coordinates: {bins: [nx, ny], observed,
 * expected}. A 1-D or 2-D result as it is; a 3-D one summed over its third coordinate (the
 * marginal counts, which the page says it shows). Flat indices i0 + n0 (i1 + n1 i2).
 */
export function mapCounts(result) {
  const b = result.bins;
  if (b.length < 3) return { bins: b.slice(), observed: result.observed, expected: result.expected, summed: false };
  const [n0, n1, n2] = b;
  const observed = new Array(n0 * n1).fill(0);
  const expected = new Array(n0 * n1).fill(0);
  for (let k = 0; k < n2; ++k) {
    for (let i = 0; i < n0 * n1; ++i) {
      observed[i] += result.observed[i + n0 * n1 * k];
      expected[i] += result.expected[i + n0 * n1 * k];
    }
  }
  return { bins: [n0, n1], observed, expected, summed: true };
}

/** The largest finite value of several arrays (the shared scale of observed and expected). */
export function sharedMax(...arrays) {
  let m = 0;
  for (const a of arrays) for (const v of a || []) if (Number.isFinite(v) && v > m) m = v;
  return m;
}

/** The standardised residuals (o - e) / sqrt(e) of each bin, null where e = 0: the display of
 *  the core's counts (a result that carries "residuals" is shown as it is). */
export function residuals(result) {
  if (Array.isArray(result.residuals) && result.residuals.length === result.observed.length) return result.residuals;
  return result.observed.map((o, k) => {
    const e = result.expected[k];
    return e > 0 ? (o - e) / Math.sqrt(e) : null;
  });
}

/**
 * RGBA pixels (Uint8ClampedArray, width nx, height ny) of a grid of values through `color`
 * (value -> [r, g, b]); the row j = 0 is the bottom row of the image.
 */
export function gridPixels(grid, color) {
  const { nx, ny } = grid;
  const px = new Uint8ClampedArray(nx * ny * 4);
  for (let j = 0; j < ny; ++j) {
    for (let i = 0; i < nx; ++i) {
      const [r, g, b] = color(grid.at(i, j));
      const k = ((ny - 1 - j) * nx + i) * 4;
      px[k] = r;
      px[k + 1] = g;
      px[k + 2] = b;
      px[k + 3] = 255;
    }
  }
  return px;
}

/** The brightness of a power P of the spectrum: t = (log10 P + 1) / 2 clipped to [0, 1], so
 *  P = 0.1 is black, P = 1 (independent points) mid-grey, P = 10 white. */
export function spectrumBrightness(power) {
  if (!(power > 0)) return 0;
  return Math.min(1, Math.max(0, (Math.log10(power) + 1) / 2));
}

/**
 * The spectrum's S x S powers (row ky + S/2, column kx + S/2, as the core returns them) as
 * grey RGBA pixels, ky growing upwards (the image's top row is the largest ky).
 */
export function spectrumPixels(power, size) {
  if (!Array.isArray(power) || power.length !== size * size) {
    throw new Error(`spectrum: ${power && power.length} values for ${size} x ${size}`);
  }
  const grid = { nx: size, ny: size, at: (i, j) => power[j * size + i] };
  return gridPixels(grid, (p) => {
    const g = Math.round(255 * spectrumBrightness(p));
    return [g, g, g];
  });
}
