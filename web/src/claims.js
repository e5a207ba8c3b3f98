// Every sentence, label and badge the page derives from a result comes from here: each claim is
// checked against the numbers it describes (web/test/claims.test.mjs tests each where it must
// not be said as well as where it must), and where the page cannot know, the words say so.
// Pure: no DOM and no uPlot. The views import from this module only.

export * from './claims/words.js';
export * from './claims/exact.js';
export * from './claims/fit.js';
export * from './claims/tail.js';
export * from './claims/reference_noise.js';
export * from './claims/errorbars.js';
export * from './claims/alarms.js';
export * from './claims/equal_time.js';
export * from './claims/time_slope.js';
export * from './claims/render.js';
export * from './claims/legend_lines.js';
export * from './claims/stats.js';
export * from './claims/clock.js';
export * from './claims/race.js';
