// Splitting a run over workers (by estimator, or a render estimator by replicate), collecting
// the parts, and the result of a run cut short.
// Pure: no DOM and no uPlot (web/test/series.test.mjs runs it under Node); web/src/series.js
// re-exports it.

/** Deals `names` round-robin into at most k non-empty groups (one per worker), order kept. */
export function splitEstimators(names, k) {
  const groups = Array.from({ length: Math.max(1, Math.min(k, names.length)) }, () => []);
  names.forEach((n, i) => groups[i % groups.length].push(n));
  return groups.filter((g) => g.length);
}

/**
 * How a render run's estimators are dealt over k workers: [{estimators, part, parts}]. While
 * there are at least as many estimators as workers, each worker studies a group of them
 * (part 0 of 1). With fewer, every estimator's replicates are split over its share of the
 * workers (replicate r to part r % parts; at most `reps` parts), so that one estimator's
 * images use every core; the parts' results are merged by the render core (mergeParts).
 */
export function splitRenderWork(names, k, reps) {
  if (names.length >= k || !(reps >= 2)) {
    return splitEstimators(names, k).map((estimators) => ({ estimators, part: 0, parts: 1 }));
  }
  const parts = Math.max(1, Math.min(Math.floor(k / names.length), reps));
  return names.flatMap((name) => Array.from({ length: parts }, (_, part) => ({ estimators: [name], part, parts })));
}

/**
 * Gathers the parts of one estimator group split by replicate and hands on whole levels and a
 * whole result. `merge(parts)` returns a promise of the merged result (the render core's
 * mergeParts, in a worker); `onLevel(line)` gets a progress line like an unsplit study's once
 * every part has finished that level (its fit and warnings over the levels so far), and
 * `onResult(result)` the merged result once every part has returned. Merges run one after
 * another, so lines come in order and before the result.
 */
export function splitCollector({ parts, merge, onLevel, onResult, onError = () => {} }) {
  const lines = Array.from({ length: parts }, () => []);
  const results = Array(parts).fill(null);
  let merged = 0; // levels handed on
  let chain = Promise.resolve();
  let failed = false;
  const queue = (task) => {
    chain = chain.then(task).catch((e) => {
      if (!failed) onError(e);
      failed = true;
    });
  };
  // A level line of each part as a result of its levels so far (what mergeParts reads).
  const asResult = (partLines) => {
    const last = partLines[partLines.length - 1];
    return {
      ...last,
      estimators: last.estimators.map((e, i) => {
        const { level, ...meta } = e;
        return { ...meta, levels: partLines.map((l) => l.estimators[i].level) };
      }),
    };
  };
  const flushLevels = () => {
    while (lines.every((l) => l.length > merged)) {
      const index = merged++;
      const parts = lines.map((l) => asResult(l.slice(0, index + 1)));
      queue(async () => {
        const m = await merge(parts);
        onLevel({
          ...m,
          estimators: m.estimators.map(({ levels, ...meta }) => ({ ...meta, level: levels[index] })),
        });
      });
    }
  };
  return {
    level(part, line) {
      if (!line || line.kind === 'render_reference') return;
      lines[part].push(line);
      flushLevels();
    },
    result(part, result) {
      results[part] = result;
      if (results.every((r) => r)) queue(async () => onResult(await merge(results)));
    },
    /** A promise that settles when the merges queued so far have. */
    settled: () => chain,
  };
}

/**
 * A result object (docs/result-schema.md) from the levels streamed so far, for exporting a
 * run that was cancelled (its workers were terminated, so they returned no result): the
 * estimators are the streamed records, the scene block what core.sceneInfo said of the scene.
 */
export function partialResult(run, info, version = null) {
  const render = run.kind === 'render';
  let scene;
  if (!info) {
    scene = { name: run.sceneName };
  } else if (render) {
    scene = {
      name: info.name, description: info.description, kind: 'render', width: run.settings ? run.settings.width : info.width,
      height: run.settings ? run.settings.height : info.height, triangles: info.triangles, lights: info.lights,
      accel: info.accel, warnings: info.warnings, exact: null,
    };
  } else {
    scene = { name: info.name, description: info.description, domain: info.domain, dimension: info.dimension, exact: info.exact };
  }
  return {
    version: 1,
    ...(render ? { kind: 'render' } : {}),
    mcplay: version,
    scene,
    settings: {
      ...(run.settings || {}),
      threads: run.threads || run.workers,
      ...(render ? { n_name: run.nName, error_name: run.errorName } : {}),
    },
    cancelled: run.status !== 'done',
    wall_time_s: run.elapsed !== null && run.elapsed !== undefined ? run.elapsed / 1000 : null,
    estimators: run.order.filter((n) => run.records[n]).map((n) => run.records[n]),
    ...(render && run.referencePng ? { reference_png: run.referencePng } : {}),
  };
}
