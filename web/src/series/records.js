// Streaming and merging: level JSON applied to a run's records as it arrives, the progress of a
// run, and the merge of the results of the workers that ran parts of one study.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.

/**
 * Folds one progress object of the core's level callback ({level_index, n, estimators: [{name,
 * ...estimator fields, level, fit}]}) into `records` (name -> {name, ...estimator fields,
 * levels: [...]}, the shape of result.estimators[k]); returns a new object, `records` unchanged.
 */
export function applyLevel(records, progress) {
  const out = { ...records };
  for (const e of progress.estimators || []) {
    const { level, ...meta } = e;
    const prev = out[e.name];
    const levels = prev ? prev.levels.filter((l) => l.n !== level.n) : [];
    levels.push(level);
    levels.sort((a, b) => a.n - b.n);
    out[e.name] = { ...meta, levels };
  }
  return out;
}

/** Share of the run's work done: levels finished weighted by their N (the cost of a level). */
export function progressOf(records, order, nLadder) {
  const perEstimator = nLadder.reduce((s, n) => s + n, 0);
  if (!order.length || !perEstimator) return 0;
  const inLadder = new Set(nLadder);
  let done = 0;
  for (const name of order) {
    const r = records[name];
    if (r) for (const l of r.levels) if (inLadder.has(l.n)) done += l.n;
  }
  return Math.min(1, done / (perEstimator * order.length));
}

// What makes two results parts of one study. A render study's scene block carries the time its
// worker took to render the reference (each worker renders the same reference, from the same
// random stream): that is not part of the key.
function studyKey(r) {
  const s = r.settings || {};
  let scene = r.scene;
  if (r.kind === 'render' && scene && scene.reference) {
    const { seconds: _seconds, ...reference } = scene.reference;
    scene = { ...scene, reference };
  }
  return JSON.stringify([r.version, r.kind, scene, s.n_min, s.n_max, s.reps, s.seed, s.accumulator,
    s.width, s.height]);
}

/**
 * One result from the results of several workers, each run with options.estimators = a subset
 * (every estimator has its own random streams, so the split does not change any number; in a
 * render study every worker also renders the same reference, and the first part's scene block
 * and reference image are kept).
 * The estimators come in `order` (names; any others after them); settings.threads is the sum
 * of the workers' threads, wall_time_s the longest worker's (they ran side by side), and the
 * merge is cancelled if any part was. Throws if the parts are not of one study.
 */
export function mergeResults(partials, order = null) {
  if (!Array.isArray(partials) || !partials.length) throw new Error('mergeResults: no results to merge');
  const first = partials[0];
  const key = studyKey(first);
  const byName = new Map();
  for (const r of partials) {
    if (studyKey(r) !== key) {
      throw new Error('mergeResults: the parts are results of different studies (scene or settings differ)');
    }
    for (const e of r.estimators) {
      if (byName.has(e.name)) throw new Error(`mergeResults: estimator '${e.name}' is in two parts`);
      byName.set(e.name, e);
    }
  }
  const names = (order || []).filter((n) => byName.has(n));
  for (const n of byName.keys()) if (!names.includes(n)) names.push(n);
  return {
    ...first,
    cancelled: partials.some((r) => r.cancelled),
    settings: {
      ...first.settings,
      threads: partials.reduce((s, r) => s + ((r.settings && r.settings.threads) || 1), 0),
    },
    wall_time_s: Math.max(...partials.map((r) => r.wall_time_s || 0)),
    estimators: names.map((n) => byName.get(n)),
  };
}
