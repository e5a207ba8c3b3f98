// Pure functions from the core's result / level JSON (docs/result-schema.md) to what the plots
// draw: aligned x/y arrays for uPlot (null where a series has no point), confidence bands,
// reference slopes, z-scores and their histogram, and the merge of the per-worker results.
// No DOM and no uPlot: web/test/series.test.mjs runs this under Node.
// The functions live by idea in web/src/series/; this module re-exports them for the page.

export * from './series/numbers.js';
export * from './series/records.js';
export * from './series/variance.js';
export * from './series/time.js';
export * from './series/calibration.js';
export * from './series/text.js';
export * from './series/split.js';
export * from './series/samples.js';
