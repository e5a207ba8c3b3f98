// Export buttons: results as CSV / JSON, plots as PNG, the comparison's link. Events only
// dispatch; main.js produces the files (CSV through core.format in a worker).
const $ = (id) => document.getElementById(id);

export function mountExports(store) {
  const { dispatch } = store;
  $('export-csv').addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'csv' } }));
  $('export-json').addEventListener('click', () => dispatch({ type: 'export/request', payload: { format: 'json' } }));
  $('copy-link').addEventListener('click', () => dispatch({ type: 'link/copy' }));
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
}
