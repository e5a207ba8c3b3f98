// Renders the numbers and the diagnostics of state.run: the #diagnostics list (every warning
// with its code and message, estimator-level and per N) and one table per estimator whose
// flagged cells sit next to the warning that concerns them (low_ess by the effective sample
// size, heavy_tail by the tail index, level_drift by the consistency test, ...). A pure render
// of the state, text only (never HTML from data).
import { collectWarnings, fmt, severityOf, nText } from './series.js';
import { alarmSummary, densityWords, flagShort, flagTitle, orderClaim, pWords, tailText, relativeMseText,
  referenceFloorOf } from './claims.js';
import { colorAt } from './palette.js';
import { el } from './dom.js';

/** Which column (level codes) or summary item (estimator codes) a warning concerns. */
const LEVEL_COLUMN = {
  low_ess: 'ess', skewed_weights: 'share', nonfinite: 'mean', zero_pdf_samples: 'mean',
  exact_outside_ci: 'mean',
};
const ESTIMATOR_ITEM = {
  heavy_tail: 'tail', heavy_tail_4: 'tail', level_drift: 'consistency', pdf_support: 'support',
};

const COLUMNS = [
  ['n', 'N', (l) => String(l.n)],
  ['mean', 'mean', (l) => fmt(l.mean, 8)],
  ['se', 'std. error', (l) => fmt(l.std_error)],
  ['variance', 'variance', (l) => fmt(l.variance)],
  ['vci', 'variance 95% CI', (l) => (l.variance_ci95 ? `${fmt(l.variance_ci95[0], 3)} – ${fmt(l.variance_ci95[1], 3)}` : '—')],
  ['error', 'RMSE / error', (l) => fmt(l.error)],
  ['coverage', 'coverage95', (l) => fmt(l.coverage95, 3)],
  ['time', 'time/est [s]', (l) => fmt(l.time_mean_s, 3)],
  ['efficiency', 'efficiency', (l) => fmt(l.efficiency, 3)],
  ['ess', 'ESS', (l) => fmt(l.ess, 3)],
  ['share', 'max weight share', (l) => fmt(l.diagnostics ? l.diagnostics.max_weight_share : null, 3)],
  ['tail', 'tail index', (l) => (l.tail_index === null || l.tail_index === undefined ? '—' : `${fmt(l.tail_index, 3)} (k=${l.tail_k})`)],
];

// Render studies: N is spp, the variance a relative MSE against the reference, the mean the
// image's mean luminance, coverage a share of pixels; no ESS (meaningless pooled over an image).
const RENDER_LABELS = {
  n: 'spp', mean: 'mean luminance', variance: 'relative MSE', vci: 'relative MSE 95% CI',
  error: 'relative RMSE', coverage: 'pixel coverage95', time: 'time/image [s]', share: 'max sample share',
};
// A relative MSE at the reference's noise is words, never a number (claims/reference_noise.js):
// its value, interval and root.
function renderColumns(floor) {
  const below = (l) => l.below_reference_noise === true;
  const noise = {
    variance: (l) => relativeMseText(l.variance, { floor, below: below(l) }),
    vci: (l, get) => (below(l) ? '—' : get(l)),
    error: (l) => relativeMseText(l.error, { floor, below: below(l), root: true }),
  };
  return COLUMNS.filter(([key]) => key !== 'ess')
    .map(([key, label, get]) => [key, RENDER_LABELS[key] || label,
      noise[key] ? (l) => noise[key](l, get) : get]);
}

/** The reference's relative-MSE floor of a render run: the merged result's, else a worker's. */
function runFloor(run) {
  return referenceFloorOf(run.result) ?? (run.partials || []).map(referenceFloorOf).find((v) => v !== null) ?? null;
}

function columnsOf(run) {
  return run.kind === 'render' ? renderColumns(runFloor(run)) : COLUMNS;
}


/** The severity label that leads every warning: ERROR, WARNING or info. */
function severityLabel(w) {
  const s = severityOf(w);
  return el('span', { className: `severity severity-${s}` }, s === 'info' ? 'info' : s.toUpperCase());
}

// A flag in the summary: plain words; the code and the core's sentence are in the list above.
function badge(w) {
  return el('span', { className: `badge badge-${severityOf(w)}`, title: `${severityOf(w)}: ${w.message}`,
    dataset: { code: w.code } }, flagShort(w.code, severityOf(w)));
}

let lastSig = null;

/** Draws the diagnostics list and the tables of state.run into `dom`. */
export function renderReport(state, dom) {
  const run = state.run;
  const sig = JSON.stringify([run.id, run.status, run.order,
    run.order.map((n) => (run.records[n] ? [run.records[n].levels.length, run.records[n].fit] : 0))]);
  if (sig === lastSig) return;
  lastSig = sig;

  const warnings = collectWarnings(run.records, run.order);
  dom.diagnostics.replaceChildren(...warnings.map((w) => el('li', {
    dataset: { estimator: w.estimator, code: w.code, scope: w.scope, severity: w.severity },
  },
  severityLabel(w), ' ',
  el('strong', {}, w.estimator), ': ',
  el('span', { className: 'flag-title' }, flagTitle(w.code, w.severity)),
  w.scope === 'level' && w.n.length ? el('span', {}, ` (${nText(w.n, run.ladder, run.kind === 'render' ? 'spp' : 'N')})`) : null,
  ' ', el('code', { className: 'flag-code' }, w.code),
  el('div', { className: 'flag-detail' }, w.message))));
  const hasRecords = run.order.some((n) => run.records[n]);
  dom.diagnosticsEmpty.textContent = !hasRecords ? 'Run a study to see its diagnostics.' : 'No warnings.';
  dom.diagnosticsEmpty.hidden = warnings.length > 0;
  // Above the plots: the errors and warnings that persist (claims/alarms.js: a flag only at the
  // smallest N, or isolated among many levels checked, is counted apart and does not turn it red),
  // who has them, and a link down to them.
  if (dom.summary) {
    const alarm = alarmSummary(run.records, run.order, { nName: run.kind === 'render' ? 'spp' : 'N' });
    const parts = [];
    alarm.parts.forEach((p, i) => {
      if (i) parts.push('; ');
      parts.push(el('span', { className: `sev sev-${p.severity}` }, p.text), ` (${p.who})`);
    });
    dom.summary.replaceChildren(...(parts.length ? ['Diagnostics: ', ...parts, ' · ', el('a', { href: '#diagnostics-title' }, 'read them')] : []));
    dom.summary.hidden = parts.length === 0;
    dom.summary.dataset.errors = String(alarm.counts.errors);
    dom.summary.dataset.severity = alarm.severity || '';
  }

  // Keep the tables the reader opened open.
  const open = new Set([...dom.levels.querySelectorAll('details[open]')].map((d) => d.dataset.for));
  dom.levels.replaceChildren(...run.order.filter((n) => run.records[n]).map((name) => {
    const r = run.records[name];
    return estimatorTable(r, run, open.has(name));
  }));
}

/** A render estimator's strategy and samplers, in a few words. */
export function renderFacts(r) {
  const parts = [`strategy ${r.strategy || '?'}`];
  if (r.light_selection) parts.push(`lights chosen by ${r.light_selection}`);
  if (r.light_sampling) parts.push(`sampled by ${r.light_sampling.replace('_', ' ')}`);
  if (r.pixel_sampler) parts.push(`${r.pixel_sampler} pixel samples`);
  if (r.pixel_allocation === 'adaptive') parts.push('spread over the pixels by their neighbours\' error');
  if (r.max_depth) parts.push(`up to ${r.max_depth} bounces`);
  if (r.candidates) parts.push(`${r.candidates} candidates resampled`);
  return parts.join(', ');
}

function estimatorTable(r, run, isOpen) {
  const last = r.levels[r.levels.length - 1] || null;
  const byItem = {};
  for (const w of r.warnings || []) (byItem[ESTIMATOR_ITEM[w.code] || 'name'] ??= []).push(w);
  const flags = (item) => (byItem[item] || []).map(badge);
  const color = colorAt(run.colors && r.name in run.colors ? run.colors[r.name] : run.order.indexOf(r.name));

  const summary = el('summary', {},
    el('span', { className: 'swatch', style: `background: ${color}` }),
    el('strong', {}, r.name), ...flags('name'),
    el('span', { className: 'muted' }, run.kind === 'render' ? renderFacts(r) : `${r.sampler || ''}${densityWords(r) ? `, density ${densityWords(r)}` : ''}`),
    el('span', {}, 'order ', el('span', { className: 'mono' }, orderClaim(r, { exact: run.kind === 'render' ? null : run.exact,
      nName: run.kind === 'render' ? 'spp' : 'N', measure: run.kind === 'render' ? 'relative MSE' : 'variance' }).text)),
    r.consistency ? el('span', {}, `level consistency ${pWords(r.consistency.p_value)}`, ...flags('consistency')) : null,
    r.support_check && r.importance ? el('span', {}, `pdf support: ${r.support_check.missed} of ${r.support_check.probes} probes missed`, ...flags('support')) : flags('support').length ? el('span', {}, ...flags('support')) : null,
    last ? el('span', {}, `tail of the weights at ${run.kind === 'render' ? 'spp' : 'N'} = ${last.n}: ${tailText(r, last)}`, ...flags('tail')) : null,
    last && run.kind !== 'render' ? el('span', {}, `ESS at N=${last.n}: ${fmt(last.ess, 3)}`) : null,
    run.kind === 'render' && typeof r.rays_per_second === 'number' ? el('span', {}, `${fmt(r.rays_per_second, 3)} rays/s`) : null,
  );
  const columns = columnsOf(run);
  const head = el('tr', {}, ...columns.map(([, label]) => el('th', { scope: 'col' }, label)));
  const rows = [];
  for (const l of r.levels) {
    const flagged = {};
    for (const w of l.warnings || []) (flagged[LEVEL_COLUMN[w.code] || 'n'] ??= []).push(w);
    rows.push(el('tr', { dataset: { n: String(l.n) } }, ...columns.map(([key, , get]) => {
      const ws = flagged[key];
      return el('td', ws ? { className: 'flag', title: ws.map((w) => `${severityOf(w)}: ${flagTitle(w.code, severityOf(w))}`).join('\n') } : {},
        ws ? `⚠ ${get(l)}` : get(l));
    })));
    for (const w of l.warnings || []) {
      rows.push(el('tr', { className: 'warn-row' }, el('td', { colSpan: columns.length },
        severityLabel(w), ` ${run.kind === 'render' ? 'spp' : 'N'} = ${l.n}: `, el('span', { className: 'flag-title' }, flagTitle(w.code, severityOf(w))),
        ` (${w.message}) `, el('code', { className: 'flag-code' }, w.code))));
    }
  }
  const details = el('details', { dataset: { for: r.name } }, summary,
    el('div', { className: 'table-wrap' },
      el('table', { className: 'levels' }, el('thead', {}, head), el('tbody', {}, ...rows))));
  details.open = isOpen;
  return details;
}
