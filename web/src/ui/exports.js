// Export buttons: results as CSV / JSON, plots as PNG, the comparison's link; and the button
// that keeps a finished run to compare the next ones with. Events only
// dispatch; main.js produces the files (CSV through core.format in a worker).
import { keptFor } from '../state.js';

const $ = (id) => document.getElementById(id);

export function mountExports(store) {
  const { dispatch } = store;
  $('export-csv').addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'csv' } }));
  $('export-json').addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'json' } }));
  $('copy-link').addEventListener('click', () => dispatch({ type: 'link/copy' }));
  // One button keeps the finished run for comparison, or clears the run kept.
  $('keep-run').addEventListener('click', () => {
    dispatch({ type: $('keep-run').dataset.kept === 'true' ? 'compare/clear' : 'compare/keep', payload: {} });
  });
  $('export-samples').addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'samples' } }));
  for (const b of document.querySelectorAll('button[data-png]')) {
    b.addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'png', plot: b.dataset.png } }));
  }
}

export function syncExports(state) {
  const run = state.run;
  const has = run.order.some((n) => run.records[n] && run.records[n].levels.length);
  $('export-csv').disabled = !has;
  $('export-json').disabled = !has;
  for (const b of document.querySelectorAll('button[data-png]')) b.disabled = !has;
  $('export-samples').disabled = !state.samples.data;
  const kept = Boolean(keptFor(state));
  const keep = $('keep-run');
  keep.dataset.kept = String(kept);
  keep.textContent = kept ? 'Clear the kept run' : 'Keep to compare';
  keep.disabled = !kept && run.status !== 'done';
}
