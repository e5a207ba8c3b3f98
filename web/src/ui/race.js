// The race card: a target accuracy, how many runs and how long each may take; Race / Cancel;
// then, per estimator, each run's time to the target on a shared log axis with the median and
// its 95% interval, and the sentence that names the winner. Every word of the table and the
// verdict comes from raceClaim (claims/race.js: the clock's floor, the answers' accuracy,
// conservative error bars, the reasons in words). Events only dispatch actions; syncRace(state)
// writes the state back (never into an input being typed in) and redraws the table when the
// race's result or the clock changes. Text only, never HTML from data.
import { KIND, kindOf, raceResult } from '../state.js';
import { raceOptions, formatSeconds } from '../race.js';
import { raceClaim, clockText, pWords } from '../claims.js';
import { colorAt } from '../palette.js';
import { fmt } from '../series.js';
import { el } from '../dom.js';
import { textPx, largeText } from './text_size.js';

const $ = (id) => document.getElementById(id);

const INPUTS = { relTol: 'race-rel', absTol: 'race-abs', runs: 'race-runs', maxSeconds: 'race-seconds' };

export function mountRace(store) {
  const { dispatch } = store;
  for (const [field, id] of Object.entries(INPUTS)) {
    $(id).addEventListener('input', (e) => dispatch({ type: 'race/edit', payload: { field, value: e.target.value } }));
  }
  $('race-start').addEventListener('click', () => dispatch({ type: 'race/request' }));
  $('race-cancel').addEventListener('click', () => dispatch({ type: 'race/cancel', payload: { now: performance.now() } }));
}

let lastRace = null;
let lastKind = null;
let lastClock = null;
let lastLarge = null;

export function syncRace(state) {
  const race = state.race;
  const kind = kindOf(state.sceneInfo);
  if (kind !== lastKind) {
    lastKind = kind;
    $('race-card').hidden = kind === KIND.RENDER; // stopping at an accuracy: integrals only
  }
  for (const [field, id] of Object.entries(INPUTS)) {
    const input = $(id);
    if (document.activeElement !== input && input.value !== race.inputs[field]) input.value = race.inputs[field];
  }
  const parsed = raceOptions(race.inputs);
  const errors = parsed.ok ? {} : parsed.errors;
  for (const [field, id] of Object.entries(INPUTS)) $(id).setAttribute('aria-invalid', errors[field] ? 'true' : 'false');
  $('race-error').textContent = race.status === 'error' ? race.message : Object.values(errors).join('; ');
  const running = race.status === 'running';
  $('race-start').disabled = running || !parsed.ok || !state.scene || !state.selected.length;
  $('race-cancel').disabled = !running;
  const done = race.order.filter((n) => race.parts[n]).length;
  $('race-progress').value = race.order.length ? done / race.order.length : 0;
  $('race-status').textContent = raceStatus(race, done);
  const clock = `${state.clockStep}|${state.isolated}`;
  if (race !== lastRace || clock !== lastClock || largeText() !== lastLarge) {
    lastRace = race;
    lastClock = clock;
    lastLarge = largeText();
    drawRace(state);
  }
}

function raceStatus(race, done) {
  if (race.status === 'idle') return '';
  const of = `${done} of ${race.order.length} estimators`;
  if (race.status === 'running') return `racing: ${of} done`;
  if (race.status === 'cancelled') return `cancelled (${of} done)`;
  if (race.status === 'error') return 'failed';
  return `done in ${formatSeconds((race.elapsed || 0) / 1000)} (wall time)`;
}

function targetText(race) {
  const o = race.options || {};
  const parts = [];
  if (o.rel_tol) parts.push(`relative ${o.rel_tol}`);
  if (o.abs_tol) parts.push(`absolute ${o.abs_tol}`);
  return parts.join(' or ');
}

function drawRace(state) {
  const race = state.race;
  const table = $('race-table');
  const verdictEl = $('race-verdict');
  const claim = raceClaim(raceResult(race), { exact: race.exact, clock: { stepMs: state.clockStep, isolated: state.isolated } });
  const rows = claim.ranked;
  if (!rows.length) {
    table.replaceChildren();
    verdictEl.textContent = race.status === 'running' ? `Racing to ${targetText(race)}…` : '';
    return;
  }
  const verdict = claim;
  const pending = race.order.length - rows.length;
  verdictEl.textContent = `Target: ${targetText(race)} (95% half-width), ${race.options.reps} runs each. `
    + (pending ? `${pending} estimator${pending > 1 ? 's' : ''} still running. ` : '') + verdict.text;
  verdictEl.className = `race-verdict${verdict.winner ? ' has-winner' : ''}`;
  const axis = timeAxis(rows);
  const head = el('tr', {},
    el('th', { scope: 'col', className: 'left' }, 'estimator'),
    el('th', { scope: 'col' }, axisSvg(axis, true)),
    el('th', { scope: 'col' }, 'median time [95% CI]'),
    el('th', { scope: 'col' }, 'reached'),
    race.exact === null ? null : el('th', { scope: 'col', title: 'runs that reached the target and whose estimate is within the tolerance of the exact value' }, 'within tol.'),
    el('th', { scope: 'col' }, 'median evaluations'),
    el('th', { scope: 'col' }, 'median N'),
    el('th', { scope: 'col', title: 'median time over the fastest median the clock can time, and the rank-sum test p-value against it' }, 'vs fastest'));
  const floor = claim.evidence.floorSeconds;
  const refName = claim.evidence.fastestTimed;
  const colorOf = (name) => colorAt(Math.max(0, (state.sceneInfo?.estimators || []).indexOf(name)));
  const body = verdict.ranked.map((r) => {
    const ci = r.interval;
    let ciText;
    if (r.tooFast) {
      ciText = floor === null ? 'not timed (clock unknown)' : `under ${clockText(floor * 1000)} (too fast for this clock)`;
    } else {
      ciText = Number.isFinite(r.median)
        ? `${formatSeconds(r.median)} [${formatSeconds(ci.lo)} – ${Number.isFinite(ci.hi) ? formatSeconds(ci.hi) : 'not reached'}]${ci.level < 0.95 ? ` (${Math.round(ci.level * 100)}%)` : ''}`
        : 'not reached in most runs';
    }
    let vs;
    if (r.tooFast) vs = 'not compared';
    else if (r.name === refName) vs = claim.evidence.tooFast.length ? 'fastest timed' : 'fastest';
    else if (r.vsFastest === null) vs = '—';
    else vs = `${Number.isFinite(r.ratio) ? `${fmt(r.ratio, 2)}×` : 'not reached'} (${pWords(r.vsFastest)})`;
    return el('tr', { className: r.name === verdict.winner ? 'winner' : '' },
      el('th', { scope: 'row', className: 'left' },
        el('span', { className: 'swatch', style: `background:${colorOf(r.name)}` }), ` ${r.name}`),
      el('td', {}, stripSvg(axis, r, colorOf(r.name))),
      el('td', {}, ciText),
      el('td', { className: r.met < r.runs ? 'flag' : '' }, r.reachedText),
      race.exact === null ? null : el('td', { className: r.within !== null && r.within < r.withinOf ? 'flag' : '' },
        r.within === null || !r.withinOf ? '—' : `${r.within}/${r.withinOf}`),
      el('td', {}, fmt(r.evaluations, 3)),
      el('td', {}, r.n === null ? '—' : String(r.n)),
      el('td', {}, vs));
  });
  // Each row's notes, in words, right under the table in the rows' order (read, not hovered).
  const notes = verdict.ranked.filter((r) => r.notes.length).map((r) => el('li', { dataset: { estimator: r.name } },
    el('span', { className: 'swatch', style: `background:${colorOf(r.name)}` }), ' ',
    el('strong', {}, r.name), `: ${r.notes.join('; ')}.`));
  const warnings = rows.flatMap((r) => r.warnings.map((w) => el('li', {},
    el('span', { className: `severity severity-${w.severity || 'warning'}` }, (w.severity || 'warning').toUpperCase()),
    ` ${r.name}: ${w.message}`)));
  const parts = [el('table', { className: 'levels race' }, el('thead', {}, head), el('tbody', {}, ...body))];
  if (notes.length) parts.push(el('ul', { className: 'race-notes' }, ...notes));
  if (warnings.length) parts.push(el('ul', { className: 'diagnostics' }, ...warnings));
  table.replaceChildren(...parts);
}

// ---------------------------------------------------------------------------------------------
// The strip plots: one log time axis shared by every row, whole decades around the runs.

const STRIP_W = 300;
const STRIP_H = 20;
const PAD_LEFT = 18; // room for the first decade's label
const PAD_RIGHT = 40; // room for the last decade's label and the ∞ of runs that ran out

function timeAxis(rows) {
  let lo = Infinity;
  let hi = -Infinity;
  for (const r of rows) {
    for (const t of [...r.times, ...r.usedSeconds]) {
      if (Number.isFinite(t) && t > 0) {
        lo = Math.min(lo, t);
        hi = Math.max(hi, t);
      }
    }
  }
  if (!(lo <= hi)) [lo, hi] = [1e-3, 1];
  const a = Math.floor(Math.log10(lo));
  const b = Math.max(a + 1, Math.ceil(Math.log10(hi)));
  const censoredX = STRIP_W - 6;
  // A time of 0 (a run shorter than the clock's resolution) is drawn at the axis's left end.
  const x = (t) => PAD_LEFT + ((Math.max(a, Math.log10(t)) - a) / (b - a)) * (STRIP_W - PAD_LEFT - PAD_RIGHT);
  // a label every `step` decades, at most five
  return { a, b, x, censoredX, step: Math.ceil((b - a + 1) / 5) };
}

const SVG_NS = 'http://www.w3.org/2000/svg';
function svg(tag, attrs = {}, ...children) {
  const e = document.createElementNS(SVG_NS, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  for (const c of children) if (c) e.append(c);
  return e;
}

function axisSvg(axis) {
  // the labels' size (16 in large-text mode) sets the axis's height: ticks below the labels
  const size = textPx(10);
  const h = size + 8;
  const s = svg('svg', { width: STRIP_W, height: h, class: 'race-axis', role: 'img', 'aria-label': 'time to the target, log scale' });
  for (let d = axis.a; d <= axis.b; ++d) {
    const x = axis.x(10 ** d);
    s.append(svg('line', { x1: x, x2: x, y1: h - 5, y2: h, stroke: '#999' }));
    if ((d - axis.a) % axis.step) continue;
    // the first label starts at its tick, so that it stays inside the axis at any text size
    const anchor = d === axis.a ? 'start' : 'middle';
    const label = svg('text', { x, y: size + 1, 'text-anchor': anchor, 'font-size': size, fill: '#555' });
    label.textContent = formatSeconds(10 ** d);
    s.append(label);
  }
  const miss = svg('text', { x: axis.censoredX, y: size + 1, 'text-anchor': 'end', 'font-size': size, fill: '#555' });
  miss.textContent = '∞';
  s.append(miss);
  return s;
}

function stripSvg(axis, row, color) {
  const mid = STRIP_H / 2;
  const s = svg('svg', { width: STRIP_W, height: STRIP_H, class: 'race-strip', role: 'img',
    'aria-label': `${row.name}: ${row.met} of ${row.runs} runs reached the target` });
  for (let d = axis.a; d <= axis.b; ++d) {
    const x = axis.x(10 ** d);
    s.append(svg('line', { x1: x, x2: x, y1: 0, y2: STRIP_H, stroke: '#eceff2' }));
  }
  const ci = row.interval;
  if (Number.isFinite(row.median)) {
    const x0 = axis.x(ci.lo);
    const x1 = Number.isFinite(ci.hi) ? axis.x(ci.hi) : axis.censoredX;
    s.append(svg('rect', { x: x0, y: mid - 4, width: Math.max(1, x1 - x0), height: 8, fill: color, 'fill-opacity': 0.18 }));
    const xm = axis.x(row.median);
    s.append(svg('line', { x1: xm, x2: xm, y1: 1, y2: STRIP_H - 1, stroke: color, 'stroke-width': 2 }));
  }
  // one dot per run (jittered up and down so that equal times stay visible); hollow at the
  // right edge when the run ended on its budget
  row.times.forEach((t, i) => {
    const y = mid + ((i % 3) - 1) * 4;
    const finite = Number.isFinite(t);
    s.append(svg('circle', {
      cx: finite ? axis.x(t) : axis.censoredX, cy: y, r: 2.5,
      fill: finite ? color : 'none', stroke: color, 'fill-opacity': 0.75,
    }));
  });
  const title = svg('title');
  title.textContent = row.times.map((t) => (Number.isFinite(t) ? formatSeconds(t) : 'not reached')).join(', ');
  s.append(title);
  return s;
}
