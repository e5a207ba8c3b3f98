// Diagnostics and text: severities and titles of the core's flags, the warnings of a run, and the
// number formats of the page.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.
import { ladder, positive } from './numbers.js';

/** Severities most severe first; a warning without one (an older result) counts as "warning". */
export const SEVERITIES = ['error', 'warning', 'info'];
export function severityOf(w) {
  return SEVERITIES.includes(w && w.severity) ? w.severity : 'warning';
}

/**
 * Every warning of the records, grouped by (estimator, scope, code): estimator-level flags
 * once, level flags with the list of N where they were raised and the message of the first;
 * errors first, then warnings, then info (in record order within a severity).
 */
/**
 * The N of a collapsed diagnostic as text: every level of the ladder ("every N, 16 … 65536"), a
 * run of consecutive ladder steps ("N = 16 … 1024, 7 levels") or a list.
 */
export function nText(ns, steps = [], name = 'N') {
  if (!ns.length) return '';
  const sorted = [...new Set(ns)].sort((a, b) => a - b);
  if (sorted.length === 1) return `${name} = ${sorted[0]}`;
  const idx = sorted.map((n) => steps.indexOf(n));
  const consecutive = idx.every((k, i) => k >= 0 && (i === 0 || k === idx[i - 1] + 1));
  if (consecutive && sorted.length >= 3) {
    const range = `${sorted[0]} … ${sorted[sorted.length - 1]}`;
    return sorted.length === steps.length ? `every ${name}, ${range}` : `${name} = ${range} (${sorted.length} levels)`;
  }
  return `${name} = ${sorted.join(', ')}`;
}

export function collectWarnings(records, order) {
  const out = [];
  for (const name of order) {
    const r = records[name];
    if (!r) continue;
    for (const w of r.warnings || []) {
      out.push({ estimator: name, scope: 'estimator', severity: severityOf(w), code: w.code, message: w.message, n: [] });
    }
    const byCode = new Map();
    for (const l of r.levels) {
      for (const w of l.warnings || []) {
        if (!byCode.has(w.code)) {
          const item = { estimator: name, scope: 'level', severity: severityOf(w), code: w.code, message: w.message, n: [] };
          byCode.set(w.code, item);
          out.push(item);
        }
        byCode.get(w.code).n.push(l.n);
      }
    }
  }
  const rank = (w) => SEVERITIES.indexOf(w.severity);
  return out.map((w, i) => [w, i]).sort((a, b) => rank(a[0]) - rank(b[0]) || a[1] - b[1]).map(([w]) => w);
}

/** x with 3 decimals exactly as C's printf("%.3f") writes it (ties to even, -0.000 kept). */
export function fixed3(x) {
  if (!Number.isFinite(x)) return String(x);
  // toFixed rounds an exact tie (a binary value ending in exactly 5 at the 4th decimal, such as
  // 1.0625) away from zero; glibc's printf rounds it to even. Other values round alike.
  const digits = Math.abs(x).toFixed(20);
  let s;
  if (/^\d+\.\d{3}50*$/.test(digits)) {
    const [int, frac] = digits.split('.');
    let k = BigInt(int + frac.slice(0, 3));
    if (k % 2n === 1n) k += 1n;
    const t = k.toString().padStart(4, '0');
    s = `${t.slice(0, -3)}.${t.slice(-3)}`;
  } else {
    s = Math.abs(x).toFixed(3);
  }
  return x < 0 || Object.is(x, -0) ? `-${s}` : s;
}

/** The core's fitted order as the CLI prints it: "-1.040 ± 0.028", or why there is none. */
export function fitText(fit) {
  if (!fit || !fit.valid || typeof fit.order !== 'number') {
    return fit && fit.note ? `no fit (${fit.note})` : 'no fit yet';
  }
  const se = typeof fit.order_se === 'number' ? ` ± ${fixed3(fit.order_se)}` : '';
  return `${fixed3(fit.order)}${se}`;
}

/** A number for tables: 4 significant digits, exponent form when very small or large. */
export function fmt(v, digits = 4) {
  if (v === null || v === undefined) return '—';
  if (typeof v !== 'number') return String(v);
  if (!Number.isFinite(v)) return String(v);
  if (v === 0) return '0';
  const a = Math.abs(v);
  if (a < 1e-3 || a >= 1e6) return v.toExponential(digits - 1);
  return Number(v.toPrecision(digits)).toString();
}

/** [lo, hi] in whole decades around the positive finite values (for log axes). */
export function decadeRange(values, fallback = [1e-6, 1]) {
  let min = Infinity;
  let max = -Infinity;
  for (const v of values) {
    if (positive(v) === null) continue;
    if (v < min) min = v;
    if (v > max) max = v;
  }
  if (!(min <= max)) return fallback.slice();
  // Number('1e-5') is the double nearest 10^-5; 10 ** -5 is not always.
  let lo = Math.floor(Math.log10(min) + 1e-9);
  let hi = Math.ceil(Math.log10(max) - 1e-9);
  if (hi <= lo) {
    lo -= 1;
    hi += 1;
  }
  return [Number(`1e${lo}`), Number(`1e${hi}`)];
}
