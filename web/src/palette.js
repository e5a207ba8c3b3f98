// Series colours: Okabe-Ito (distinguishable with the common colour-vision deficiencies),
// indexed by the estimator's position in its scene so a colour stays with its estimator.
export const PALETTE = Object.freeze([
  '#0072B2', '#D55E00', '#009E73', '#CC79A7', '#E69F00', '#56B4E9', '#000000', '#8C6D31', '#7F7F7F',
]);

export function colorAt(index) {
  return PALETTE[((index % PALETTE.length) + PALETTE.length) % PALETTE.length];
}

/** #rrggbb with an alpha, for band fills. */
export function withAlpha(hex, alpha) {
  const n = parseInt(hex.slice(1), 16);
  return `rgba(${(n >> 16) & 255}, ${(n >> 8) & 255}, ${n & 255}, ${alpha})`;
}
