// A chart as a PNG file: drawn again at twice the screen's resolution (pixel_ratio.js), with
// the plot's title, a subtitle naming the scene and the estimators, and its legend lines.
import { devicePixelRatioNow, withPixelRatio } from '../pixel_ratio.js';
import { charts, dom } from './chart.js';
import { legendLines } from '../claims.js';

/**
 * The chart `key` as a PNG data URL at `scale` times the device's resolution (drawn again at that
 * pixel ratio for the export, withPixelRatio), with its title, `subtitle` and legend; null
 * for an empty chart.
 */
export async function plotPng(key, subtitle = '', scale = 2) {
  const c = charts[key];
  if (!c || !c.u) return null;
  return withPixelRatio(scale * devicePixelRatioNow(), () => composePng(key, subtitle));
}

// The legend lines of the last PNG composed (window.mcplayDebug, for the e2e tests).
let lastLegend = [];
export function lastPngLegend() {
  return lastLegend.slice();
}

function composePng(key, subtitle) {
  const c = charts[key];
  if (!c || !c.u) return null;
  const src = c.u.ctx.canvas;
  const px = src.width / c.u.width || 1;
  const legendItems = [...(dom[`legend-${key}`] ? dom[`legend-${key}`].children : [])];
  const line = 18 * px;
  const head = (subtitle ? 46 : 28) * px;
  const out = document.createElement('canvas');
  out.width = src.width;
  // The legend's lines: hidden estimators left out, each entry wrapped to the image's width.
  const ctx = out.getContext('2d');
  ctx.font = `${12 * px}px "DejaVu Sans", sans-serif`;
  const lines = legendLines(legendItems.map((li) => ({
    text: [...li.childNodes].map((n) => n.textContent.trim()).filter(Boolean).join('  '),
    hidden: li.classList.contains('off'),
  })), { measure: (t) => ctx.measureText(t).width, width: out.width - 42 * px });
  lastLegend = lines.map((l) => l.text);
  out.height = head + src.height + (lines.length ? lines.length * line + 10 * px : 0);
  ctx.fillStyle = '#fff';
  ctx.fillRect(0, 0, out.width, out.height);
  ctx.fillStyle = '#1b1f24';
  ctx.font = `bold ${14 * px}px "DejaVu Sans", sans-serif`;
  ctx.textBaseline = 'middle';
  const title = document.getElementById(`${key}-title`);
  ctx.fillText(title ? title.textContent : key, 10 * px, 14 * px);
  if (subtitle) {
    // the scene and the estimators shown: a PNG names what it plots
    ctx.font = `${12 * px}px "DejaVu Sans", sans-serif`;
    ctx.fillText(subtitle, 10 * px, 34 * px, out.width - 20 * px);
  }
  ctx.drawImage(src, 0, head);
  ctx.font = `${12 * px}px "DejaVu Sans", sans-serif`;
  lines.forEach((l, i) => {
    const y = head + src.height + 5 * px + (i + 0.5) * line;
    if (l.first) {
      const sw = legendItems[l.item].querySelector('.swatch');
      ctx.fillStyle = sw ? getComputedStyle(sw).backgroundColor : '#000';
      ctx.fillRect(10 * px, y - 2 * px, 16 * px, 4 * px);
    }
    ctx.fillStyle = '#1b1f24';
    ctx.fillText(l.text, 32 * px, y);
  });
  return out.toDataURL('image/png');
}
