// Series colours, indexed by the estimator's position in its scene so a colour stays with its
// estimator: Okabe and Ito's colours without black and yellow [OkabeIto08], then Tol's wine,
// olive and indigo [Tol21], the second blue last but two. Never black (the colour of the
// reference curves: N(0,1), f in the overlay), none too light for lines on white, and ten that
// stay apart under simulated protanopia, deuteranopia and tritanopia (web/test/palette.test.mjs).
export const PALETTE = Object.freeze([
  '#0072B2', '#D55E00', '#009E73', '#CC79A7', '#E69F00', '#882255', '#999933', '#56B4E9', '#8C6D31', '#332288',
]);

export function colorAt(index) {
  return PALETTE[((index % PALETTE.length) + PALETTE.length) % PALETTE.length];
}

/** #rrggbb with an alpha, for band fills. */
export function withAlpha(hex, alpha) {
  const n = parseInt(hex.slice(1), 16);
  return `rgba(${(n >> 16) & 255}, ${(n >> 8) & 255}, ${n & 255}, ${alpha})`;
}
