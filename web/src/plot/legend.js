// Which estimator is which in every plot: its colour, the legend lists under the plots (plain
// DOM, text only, never HTML from data) and the estimators the reader hid by clicking their
// legend entry (every plot follows: chart.js applies the set to each chart). No uPlot here.
import { severityOf, SEVERITIES } from '../series.js';
import { flagShort, flagTitle } from '../claims.js';
import { colorAt } from '../palette.js';
import { el } from '../dom.js';

// Estimators the reader hid by clicking their legend entry.
const hiddenSeries = new Set();

/** True when the estimator `name` is hidden. */
export function isHidden(name) {
  return hiddenSeries.has(name);
}

/** True when a chart series belongs to a hidden estimator: its label is the estimator's name,
 *  or the name and a suffix ("uniform 95% high"). */
export function hidesLabel(label) {
  for (const name of hiddenSeries) if (label === name || label.startsWith(`${name} `)) return true;
  return false;
}

/** The estimators hidden in the plots (a shared link's; for tests: window.mcplayDebug). */
export function hiddenEstimators() {
  return [...hiddenSeries];
}

/** Hides exactly the estimators `names` (a shared link's); the charts follow on their next draw. */
export function setHiddenEstimators(names) {
  hiddenSeries.clear();
  for (const n of names) hiddenSeries.add(n);
}

/**
 * A click on an estimator's legend entry hides it in every plot (or shows it again); with Shift
 * or Alt, it isolates it (every other estimator hidden), and the same again shows them all.
 * Updates every legend; returns true when the hidden set changed (the charts then follow it).
 */
export function toggleFromLegend(e) {
  const li = e.target.closest('li[data-series]');
  if (!li) return false;
  const name = li.dataset.series;
  const all = [...new Set([...document.querySelectorAll('.legend li[data-series]')].map((x) => x.dataset.series))];
  if (e.shiftKey || e.altKey) {
    const isolated = all.every((n) => (n === name) !== hiddenSeries.has(n));
    hiddenSeries.clear();
    if (!isolated) for (const n of all) if (n !== name) hiddenSeries.add(n);
  } else if (hiddenSeries.has(name)) {
    hiddenSeries.delete(name);
  } else {
    hiddenSeries.add(name);
  }
  for (const item of document.querySelectorAll('.legend li[data-series]')) {
    item.classList.toggle('off', hiddenSeries.has(item.dataset.series));
    const b = item.querySelector('button.toggle');
    if (b) b.setAttribute('aria-pressed', String(!hiddenSeries.has(item.dataset.series)));
  }
  return true;
}

/** The colour of an estimator in a run's plots (run.colors: its index in the scene). */
export function colorOf(run, name) {
  return colorAt(run.colors && name in run.colors ? run.colors[name] : run.order.indexOf(name));
}

/** The colour of an estimator in the sample views (its index in the scene shown). */
export function sceneColor(state, name) {
  const names = state.sceneInfo && state.sceneInfo.estimators ? state.sceneInfo.estimators : [];
  const i = names.indexOf(name);
  return colorAt(i < 0 ? 0 : i);
}

export function swatch(color, dashed = false) {
  return el('span', {
    className: 'swatch',
    style: dashed ? `background: repeating-linear-gradient(90deg, ${color} 0 4px, transparent 4px 7px)` : `background: ${color}`,
  });
}

// A flag beside its estimator: plain words (claims/words.js), the code and the core's sentence in
// the diagnostics list below, which the words point to.
function badge(w) {
  const severity = severityOf(w);
  return el('span', { className: `badge${severity === 'error' ? ' badge-error' : ''}`,
    title: `${flagTitle(w.code, severity)}: ${w.message}`, dataset: { severity, code: w.code } }, flagShort(w.code, severity));
}

/** An estimator's level flags of severity error or warning (one per code) that its own
 *  estimator-level warnings do not already say: shown beside the plot they concern. */
export function levelFlags(r) {
  const own = new Set((r.warnings || []).map((w) => w.code));
  const seen = new Map();
  for (const l of r.levels || []) {
    for (const w of l.warnings || []) {
      const sev = severityOf(w);
      if ((sev === 'error' || sev === 'warning') && !own.has(w.code) && !seen.has(w.code)) seen.set(w.code, w);
    }
  }
  return [...seen.values()].sort((a, b) => SEVERITIES.indexOf(severityOf(a)) - SEVERITIES.indexOf(severityOf(b)));
}

const legendSigs = {};

/**
 * Fills the legend `ul` of plot `key` (rebuilt only when `items` change): one entry per item
 * {name, color, dashed?, ref?, data?, parts}, a part being text, {text, className}, {fit, name}
 * (a [data-fit] span) or {warning} (a badge).
 */
export function setLegend(key, ul, items) {
  const sig = JSON.stringify(items);
  if (legendSigs[key] === sig && ul.childElementCount === items.length) return;
  legendSigs[key] = sig;
  // An estimator's entry: its name is a toggle button (hide or show it in every plot).
  const nameOf = (it) => {
    if (it.ref) return el('span', { className: 'name ref' }, it.name);
    const b = el('button', { type: 'button', className: 'name toggle', title: 'click: hide or show in every plot; Shift+click: show only this one' }, it.name);
    b.setAttribute('aria-pressed', String(!hiddenSeries.has(it.name)));
    return b;
  };
  ul.replaceChildren(...items.map((it) => el('li', {
    dataset: { ...(it.data || {}), ...(it.ref ? {} : { series: it.name }) },
    ...(it.ref ? {} : { className: hiddenSeries.has(it.name) ? 'off' : '' }),
  },
    swatch(it.color, it.dashed),
    nameOf(it),
    ...(it.parts || []).map((p) => (typeof p === 'string' ? p : p.fit !== undefined
      ? el('span', { className: 'fit', dataset: { fit: p.name } }, p.fit)
      : p.warning ? badge(p.warning) : el('span', { className: p.className || '' }, p.text))))));
}
