// The sampler lab's canvases: heat maps (a grid of colours scaled up without smoothing), the
// scatter of a 2-D projection, the power spectrum image, and colour bars. The colours come from
// colors.js; this module only puts them on canvases.
import { gridPixels, spectrumPixels } from './colors.js';

const DPR = () => Math.min(2, (typeof window !== 'undefined' && window.devicePixelRatio) || 1);

/** Sizes a canvas to `css` CSS pixels square (or w x h) at the screen's pixel ratio; returns its 2-D context. */
function sized(canvas, w, h = w) {
  const r = DPR();
  if (canvas.width !== Math.round(w * r) || canvas.height !== Math.round(h * r)) {
    canvas.width = Math.round(w * r);
    canvas.height = Math.round(h * r);
  }
  canvas.style.width = `${w}px`;
  canvas.style.height = `${h}px`;
  const ctx = canvas.getContext('2d');
  ctx.setTransform(r, 0, 0, r, 0, 0);
  return ctx;
}

/** Puts RGBA pixels (nx x ny) on the canvas, scaled to fill it, one sharp square per cell. */
function putScaled(canvas, px, nx, ny, w, h) {
  const ctx = sized(canvas, w, h);
  const off = document.createElement('canvas');
  off.width = nx;
  off.height = ny;
  off.getContext('2d').putImageData(new ImageData(px, nx, ny), 0, 0);
  ctx.imageSmoothingEnabled = false;
  ctx.clearRect(0, 0, w, h);
  ctx.drawImage(off, 0, 0, w, h);
  return ctx;
}

/** A heat map of `grid` (colors.heatGrid) through `color`, `size` CSS pixels square. */
export function drawHeat(canvas, grid, color, size = 220) {
  putScaled(canvas, gridPixels(grid, color), grid.nx, grid.ny, size, size);
}

/** A horizontal colour bar through `color` over t in [0, 1] (or over [lo, hi] values). */
export function drawColorBar(canvas, color, lo = 0, hi = 1, width = 220, height = 10) {
  const n = 64;
  const px = new Uint8ClampedArray(n * 4);
  for (let i = 0; i < n; ++i) {
    const [r, g, b] = color(lo + ((hi - lo) * (i + 0.5)) / n);
    px.set([r, g, b, 255], i * 4);
  }
  putScaled(canvas, px, n, 1, width, height);
}

/** The power spectrum image (S x S powers, grey by colors.spectrumBrightness). */
export function drawSpectrum(canvas, power, size, css = 256) {
  const ctx = putScaled(canvas, spectrumPixels(power, size), size, size, css, css);
  // the origin's cross hair, faint
  ctx.strokeStyle = 'rgba(255, 159, 26, 0.55)';
  ctx.lineWidth = 1;
  ctx.beginPath();
  ctx.moveTo(css / 2, css / 2 - 6);
  ctx.lineTo(css / 2, css / 2 + 6);
  ctx.moveTo(css / 2 - 6, css / 2);
  ctx.lineTo(css / 2 + 6, css / 2);
  ctx.stroke();
}

/** The scatter of rows' coordinates a and b in the unit square (y up), with a frame. */
export function drawScatter(canvas, rows, a, b, css = 256) {
  const ctx = sized(canvas, css, css);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, css, css);
  ctx.strokeStyle = '#b8c0c8';
  ctx.strokeRect(0.5, 0.5, css - 1, css - 1);
  const dot = rows.length > 8192 ? 1 : rows.length > 1024 ? 1.5 : 2.5;
  ctx.fillStyle = '#0072B2';
  for (const row of rows) {
    const x = row[a];
    const y = row[b];
    if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
    ctx.fillRect(x * (css - 2) + 1 - dot / 2, (1 - y) * (css - 2) + 1 - dot / 2, dot, dot);
  }
}
