// The estimator panels: for each selected estimator of an integration scene, what it is (its
// formula and density), the order its variance should reach, what to look for, and, once a run
// has fitted it, the order it did reach. Text only, never HTML from data.
import { KIND, kindOf } from '../state.js';
import { explainEstimator } from '../explain.js';
import { colorAt } from '../palette.js';
import { orderClaim } from '../claims.js';
import { el } from '../dom.js';

const $ = (id) => document.getElementById(id);

let lastSig = null;

/** What the run measured for an estimator: its fitted order where a power law holds, or why
 *  there is none (claims/fit.js), or nothing yet. */
function measured(record, exact) {
  if (!record || !Array.isArray(record.levels) || !record.levels.length) return null;
  const c = orderClaim(record, { exact });
  if (c.number === null) return c.text;
  if (c.note && c.note.startsWith('from N')) return `variance ∝ N^(${c.number}) ${c.note}; ${c.text.slice(c.text.indexOf('(') + 1, -1)}`;
  return `variance ∝ N^(${c.number}), fitted over the N of the run${c.holds === null ? ' (not checked for a power law)' : ''}`;
}

export function renderExplain(state) {
  const section = $('explain-section');
  const info = state.sceneInfo;
  const render = kindOf(info) === KIND.RENDER;
  const details = info && Array.isArray(info.estimator_details) ? info.estimator_details : [];
  const run = state.run;
  const fits = state.selected.map((n) => measured(run.records[n], run.exact));
  const sig = JSON.stringify([state.sceneId, render, state.selected, details.length, fits]);
  if (sig === lastSig) return;
  lastSig = sig;
  section.hidden = render || !details.length;
  if (section.hidden) return;
  const all = info.estimators || [];
  const cards = state.selected.map((name, i) => {
    const d = details.find((e) => e.name === name) || { name };
    const x = explainEstimator(d, info.dimension);
    return el('article', { className: 'explain-card', dataset: { estimator: name } },
      el('h3', {}, el('span', { className: 'swatch', style: `background:${colorAt(all.indexOf(name))}` }), ` ${name}: `,
        el('span', { className: 'method' }, x.title)),
      el('p', { className: 'formula' }, el('code', {}, x.formula)),
      x.density ? el('p', { className: 'small muted' }, `density: ${d.pdf_text || x.density}`) : null,
      el('p', {}, el('strong', {}, 'Should reach: '), `variance ∝ ${x.order}`),
      fits[i] ? el('p', { className: 'measured' }, el('strong', {}, 'Reached: '), fits[i]) : null,
      x.look ? el('p', { className: 'small' }, x.look) : null);
  });
  $('explain-list').replaceChildren(...cards);
}
