// The page's plots, drawn from the state (what main.js calls): the four study charts (variance
// or MSE against N, error against time per estimate, the z-score histogram, the coverage against
// N), the sample view and the charts of its weights, their legends, and PNG exports. A pure
// render of the state: it reads state.run and state.samples and writes only into the plot
// containers and legends. The parts, in plot/:
//   axes.js          tick labels, log10 values, axis texts (pure; no uPlot, no DOM)
//   chart.js         uPlot charts by key, the plot elements, shared log scales (imports uPlot)
//   legend.js        colours, legend lists, the estimators hidden by a legend click
//   variance.js, time.js, calibration.js   the study plots
//   samples.js, sample_panels.js, weights.js   the sample view and its charts
//   png.js           a chart as a PNG file
import { dom, resizeAll, applyHiddenAll, drop, empty, setText } from './plot/chart.js';
import { setLegend, toggleFromLegend, setHiddenEstimators, isHidden } from './plot/legend.js';
import { renderVariance } from './plot/variance.js';
import { varianceNote, timeNote } from './claims.js';
import { renderTime } from './plot/time.js';
import { renderCalibration, renderCoverage, COVERAGE_NOTE } from './plot/calibration.js';
import { mountSampleControls, renderSampleViews } from './plot/samples.js';

export { plotPng, lastPngLegend } from './plot/png.js';
export { hiddenEstimators } from './plot/legend.js';
export { guideLabels } from './plot/time.js';

/** Hides exactly the estimators `names` in every plot and legend (a shared link's view). */
export function setHidden(names) {
  setHiddenEstimators(names);
  for (const item of document.querySelectorAll('.legend li[data-series]')) {
    item.classList.toggle('off', isHidden(item.dataset.series));
    const b = item.querySelector('button.toggle');
    if (b) b.setAttribute('aria-pressed', String(!isHidden(item.dataset.series)));
  }
  applyHiddenAll();
}

let mounted = false;

/** Remembers the plot and legend elements and redraws on resize. */
export function initPlots(elements) {
  Object.assign(dom, elements);
  mounted = true;
  if (typeof ResizeObserver === 'function') {
    const ro = new ResizeObserver(resizeAll);
    for (const k of ['variance', 'time', 'calibration', 'coverage', 'overlay', 'misweights', 'weights']) if (dom[k]) ro.observe(dom[k]);
  }
  for (const [k, ul] of Object.entries(dom)) {
    if (!k.startsWith('legend-') || !ul) continue;
    // the name buttons take Enter and Space
    ul.addEventListener('click', (e) => {
      if (toggleFromLegend(e)) applyHiddenAll();
    });
  }
  mountSampleControls();
}

/** The titles and notes of the plots before a run, for the kind of scene shown. */
function emptyTexts(render) {
  setText('variance-title', render ? 'Relative MSE against spp' : 'Variance against N');
  setText('variance-note', varianceNote(render ? 'render' : 'integral'));
  setText('time-title', render ? 'Error against time per image' : 'Error against run time');
  setText('time-kind-note', timeNote(render ? 'render' : 'integral').lead);
  setText('time-adaptive-note', timeNote(render ? 'render' : 'integral').adaptive);
  setText('coverage-note', COVERAGE_NOTE[render ? 'render' : 'integral']);
}

/** Draws everything of state.run and state.samples. */
export function renderPlots(state) {
  if (!mounted) return;
  renderSampleViews(state);
  const run = state.run;
  if (!run.order.length) {
    emptyTexts(state.sceneInfo && state.sceneInfo.kind === 'render');
    for (const k of ['variance', 'time', 'calibration', 'coverage']) {
      drop(k);
      if (!dom[k].querySelector('.empty')) empty(dom[k], 'Press Run to start a study.');
      setLegend(k, dom[`legend-${k}`], []);
    }
    return;
  }
  // Every estimator of the run has a series from the start (empty until its first level).
  const records = {};
  for (const n of run.order) records[n] = run.records[n] || { name: n, levels: [], fit: null, warnings: [] };
  renderVariance(state, run, records);
  renderTime(state, run, records);
  renderCalibration(state, run, records);
  renderCoverage(state, run, records);
}
