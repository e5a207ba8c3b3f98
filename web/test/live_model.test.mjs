// The live view's pure parts (web/src/live/model.js): bands, the pass schedule, merging bands
// into levels (pixels, relative MSE, seconds), tone mapping, the error colours, the wipe, zoom
// and the prediction, and the reducer.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  splitRows, workerOfBand, nextSpp, createCollector, relativeMse, estimatorSeconds, toneMap, srgbEncode,
  errorColor, errorMap, wipeFromPointer, wipeClip, commonSpp, zoomStep, fitZoom, predictionText, predictSeconds,
  duration, oneLine, liveWorkers, alignPoints, PREDICT_AT, defaultEstimators, sessionOptions, initialLive, liveReducer, liveActive, LONG_SECONDS,
  belowReferenceNoise, relmseText, relmseRatio, compareText, shortNumber,
} from '../src/live/model.js';

test('row bands cover every row exactly once, in order, sizes within one row', () => {
  for (const h of [1, 2, 3, 7, 16, 144, 180, 576, 1024]) {
    for (const k of [1, 2, 3, 4, 8, 16]) {
      const bands = splitRows(h, k);
      assert.equal(bands.length, Math.min(h, k), `h ${h} k ${k}`);
      const seen = new Uint8Array(h);
      let row = 0;
      for (const [b, e] of bands) {
        assert.equal(b, row, 'bands follow each other');
        assert.ok(e > b, 'no empty band');
        for (let r = b; r < e; ++r) seen[r] += 1;
        row = e;
      }
      assert.equal(row, h);
      assert.ok(seen.every((v) => v === 1), `h ${h} k ${k}: every row once`);
      const sizes = bands.map(([b, e]) => e - b);
      assert.ok(Math.max(...sizes) - Math.min(...sizes) <= 1);
    }
  }
  assert.deepEqual(splitRows(0, 4), []);
  assert.deepEqual(splitRows(10, 3), [[0, 4], [4, 7], [7, 10]]);
  assert.deepEqual([0, 1, 2, 3, 4].map((i) => workerOfBand(i, 2)), [0, 1, 0, 1, 0]);
});

test('the pass schedule doubles from 1 spp', () => {
  assert.equal(nextSpp(0), 1);
  assert.equal(nextSpp(1), 2);
  assert.equal(nextSpp(64), 128);
  const schedule = [];
  for (let s = nextSpp(0); s <= 100; s = nextSpp(s)) schedule.push(s);
  assert.deepEqual(schedule, [1, 2, 4, 8, 16, 32, 64]);
});

test('workers: hardwareConcurrency, at most 4, an override wins', () => {
  assert.equal(liveWorkers(2), 2);
  assert.equal(liveWorkers(16), 4);
  assert.equal(liveWorkers(undefined), 1);
  assert.equal(liveWorkers(16, 2), 2);
  assert.equal(liveWorkers(2, 9), 4);
  assert.deepEqual(defaultEstimators(['a', 'b', 'c', 'd', 'e']), ['a', 'b', 'c', 'd']);
  const o = sessionOptions({ estimators: ['bsdf'], sampler: 'padded_sobol', longSide: 256, rows: [0, 10], referenceData: 'QQ==', seed: 3 });
  assert.deepEqual(o, { estimators: ['bsdf'], pixel_sampler: 'padded_sobol', long_side: 256, rows: [0, 10],
    live_reference: 'available', pixels: true, threads: 1, reference_data: 'QQ==', seed: 3 });
  assert.equal('reference_data' in sessionOptions({ estimators: [], sampler: 'independent', longSide: 128, rows: [0, 1] }), false);
});

test('the collector places bands by rows and merges relative MSE from the band sums', () => {
  const width = 3;
  const height = 5;
  const bands = splitRows(height, 3); // [0,2) [2,4) [4,5)
  const c = createCollector({ width, height, bands, workers: 2 });
  const band = (i, v, error, seconds) => {
    const [b, e] = bands[i];
    return { spp: 4, rgb: new Float32Array((e - b) * width * 3).fill(v), error, seconds, pass_seconds: seconds / 2 };
  };
  assert.equal(c.add(0, 2, band(2, 3, { sum: 1, terms: 3 }, 0.5)), null);
  assert.equal(c.add(0, 0, band(0, 1, { sum: 2, terms: 6 }, 1.0)), null);
  assert.equal(c.pendingLevels(), 1);
  const level = c.add(0, 1, band(1, 2, { sum: 3, terms: 6 }, 1.5));
  assert.equal(c.pendingLevels(), 0);
  assert.equal(level.spp, 4);
  // (1 + 2 + 3) / (3 + 6 + 6), not the mean of the bands' ratios
  assert.equal(level.relmse, 6 / 15);
  assert.notEqual(level.relmse, (1 / 3 + 2 / 6 + 3 / 6) / 3);
  assert.equal(level.seconds, 3 / 2);
  assert.equal(level.passSeconds, 3 / 4);
  for (let row = 0; row < height; ++row) {
    const want = row < 2 ? 1 : row < 4 ? 2 : 3;
    for (let k = 0; k < width * 3; ++k) assert.equal(level.rgb[row * width * 3 + k], want, `row ${row}`);
  }
  // a band without a reference: the level has no relative MSE (but its image)
  c.add(1, 0, band(0, 1, null, 1));
  c.add(1, 1, band(1, 1, { sum: 1, terms: 1 }, 1));
  assert.equal(c.add(1, 2, band(2, 1, { sum: 1, terms: 1 }, 1)).relmse, null);
  // a band twice, or of the wrong size, is refused
  c.add(0, 0, { spp: 8, rgb: new Float32Array(2 * width * 3), error: null, seconds: 0 });
  assert.throws(() => c.add(0, 0, { spp: 8, rgb: new Float32Array(2 * width * 3), error: null, seconds: 0 }), /twice/);
  assert.throws(() => c.add(0, 1, { spp: 8, rgb: new Float32Array(5), error: null, seconds: 0 }), /expected 18/);
  assert.equal(relativeMse([{ sum: 1, terms: 2 }, { sum: 3, terms: 2 }]), 1);
  assert.equal(relativeMse([{ sum: 1, terms: 2 }, null]), null);
  assert.equal(relativeMse([{ sum: 0, terms: 0 }]), null);
  assert.equal(estimatorSeconds([1, 2, 3, 4], 2), 5);
});

test('tone mapping: exposure, clamping, sRGB like the core, not a number black', () => {
  const out = new Uint8ClampedArray(4 * 4);
  toneMap(new Float32Array([0, 0.5, 1, 2, -1, NaN, 0.0031308, 0.25, 0.18, 0.5, 0.5, 0.5]), out, 0);
  assert.deepEqual([...out.slice(0, 4)], [0, Math.round(srgbEncode(0.5) * 255), 255, 255]);
  assert.deepEqual([...out.slice(4, 8)], [255, 0, 0, 255]);
  assert.equal(out[8], Math.round(12.92 * 0.0031308 * 255));
  assert.equal(out[9], 137); // sRGB of 0.25
  // exposure +1 doubles: 0.25 shows as 0.5
  const two = new Uint8ClampedArray(4);
  toneMap(new Float32Array([0.25, 0.25, 0.25]), two, 1);
  assert.equal(two[0], Math.round(srgbEncode(0.5) * 255));
  assert.equal(out[12], Math.round(srgbEncode(0.5) * 255));
});

test('error colours: log scale 1e-3 dark blue to 1 yellow, magenta for not a number', () => {
  assert.deepEqual(errorColor(1e-5), errorColor(1e-3));
  assert.deepEqual(errorColor(1e-3), [18, 5, 77]);
  assert.deepEqual(errorColor(1), [252, 232, 38]);
  assert.deepEqual(errorColor(100), [252, 232, 38]);
  assert.deepEqual(errorColor(NaN), [255, 0, 255]);
  // monotone in green along the ramp's first half
  assert.ok(errorColor(0.01)[1] > errorColor(0.002)[1]);
  const ref = new Float32Array([1, 1, 1, 1, 1, 1]);
  const img = new Float32Array([1, 1, 1, 2, 2, 2]);
  const out = errorMap(img, ref, new Uint8ClampedArray(8));
  assert.deepEqual([...out.slice(0, 4)], [...errorColor(0), 255]);
  // |2 - 1| / (1 + 0.01): about 1, yellow
  assert.deepEqual([...out.slice(4, 8)], [...errorColor(1 / 1.01), 255]);
});

test('the wipe: pointer to percent, clip-path, the spp both images have', () => {
  assert.equal(wipeFromPointer(150, 100, 200), 25);
  assert.equal(wipeFromPointer(50, 100, 200), 0);
  assert.equal(wipeFromPointer(400, 100, 200), 100);
  assert.equal(wipeFromPointer(150, 100, 0), 50);
  assert.equal(wipeClip(25), 'inset(0 0 0 25%)');
  assert.equal(wipeClip(-3), 'inset(0 0 0 0%)');
  assert.equal(wipeClip(33.333), 'inset(0 0 0 33.33%)');
  assert.equal(commonSpp([1, 2, 4, 8], [1, 2, 4]), 4);
  assert.equal(commonSpp([1, 2], [1, 2, 4, 8]), 2);
  assert.equal(commonSpp([], [1]), null);
  assert.equal(commonSpp(null, [1, 2]), 2);
  assert.equal(commonSpp([4, 8], null), 8);
});

test('zoom steps and the default zoom', () => {
  assert.equal(zoomStep(1, 1), 2);
  assert.equal(zoomStep(1, -1), 1);
  assert.equal(zoomStep(16, 1), 16);
  assert.equal(zoomStep(5, 1), 8);
  assert.equal(fitZoom(128, 2, 1200), 4);
  assert.equal(fitZoom(1024, 4, 1200), 1);
});

test('the prediction to 64 spp from the first passes, and its words', () => {
  assert.equal(PREDICT_AT, 4);
  assert.equal(predictSeconds(0.2, 0.05), 0.2 + 60 * 0.05);
  const short = predictionText(0.2, 0.05, 256, 144);
  assert.equal(short.long, false);
  assert.match(short.text, /^256 × 144 pixels: 4 spp took 200 ms and each further spp takes about 50 ms, so 64 spp will take about 3\.2 s\.$/);
  const long = predictionText(4, 2, 1024, 576);
  assert.equal(long.seconds, 124);
  assert.equal(long.long, 124 > LONG_SECONDS);
  assert.match(long.text, /about 2 min 4 s\. Paused/);
  assert.equal(predictionText(4, 0.1, 1, 1).long, false);
  // after the first pass (1 spp took 2 s): 64 of them; said, and paused, at once
  const early = predictionText(2, 2, 1024, 1024, 1);
  assert.equal(early.seconds, 128);
  assert.equal(early.pause, true);
  assert.match(early.text, /^1024 × 1024 pixels: 1 spp took 2\.0 s, so 64 spp will take about 2 min 8 s\. Paused/);
  // the closer figure later does not pause a view the reader resumed
  const later = predictionText(8, 1.5, 1024, 1024, 4, false);
  assert.equal(later.long, true);
  assert.equal(later.pause, false);
  assert.doesNotMatch(later.text, /Paused/);
  assert.equal(duration(0.0004), '1 ms');
  assert.equal(duration(42), '42 s');
  assert.equal(duration(7200), '2.0 h');
  assert.equal(oneLine('options.long_side: 5000 is beyond 4096\n  detail'), 'options.long_side: 5000 is beyond 4096');
});

test('the reducer: a view starts, takes levels (curves only with a relative MSE), pauses, ends; old views are ignored', () => {
  let s = initialLive();
  s = liveReducer(s, { type: 'live/start', payload: { id: 1, order: ['bsdf', 'mis_power'], colors: { bsdf: 2, mis_power: 6 }, workers: 2, startedAt: 100 } });
  assert.equal(s.status, 'starting');
  assert.equal(liveActive(s), true);
  assert.deepEqual([s.view.wipeA, s.view.wipeB], ['bsdf', 'mis_power']);
  s = liveReducer(s, { type: 'live/opened', payload: { id: 1, size: { width: 256, height: 144 } } });
  assert.equal(s.status, 'running');
  s = liveReducer(s, { type: 'live/level', payload: { id: 1, estimator: 'bsdf', spp: 1, seconds: 0.1, relmse: null, now: 350 } });
  assert.equal(s.firstImageMs, 250);
  assert.deepEqual(s.estimators.bsdf.points, []);
  s = liveReducer(s, { type: 'live/level', payload: { id: 1, estimator: 'bsdf', spp: 2, seconds: 0.2, relmse: 0.5, now: 400 } });
  assert.deepEqual(s.estimators.bsdf.points, [{ spp: 2, seconds: 0.2, relmse: 0.5 }]);
  assert.deepEqual(s.estimators.bsdf.levels, [1, 2]);
  assert.equal(s.firstImageMs, 250);
  const stale = liveReducer(s, { type: 'live/level', payload: { id: 0, estimator: 'bsdf', spp: 4, seconds: 1, relmse: 0.1, now: 1 } });
  assert.equal(stale, s);
  s = liveReducer(s, { type: 'live/prediction', payload: { id: 1, prediction: { long: true, pause: false, text: 'long' } } });
  assert.equal(s.status, 'running');
  s = liveReducer(s, { type: 'live/prediction', payload: { id: 1, prediction: { long: true, pause: true, text: 'long' } } });
  assert.equal(s.status, 'paused');
  s = liveReducer(s, { type: 'live/resume', payload: { id: 1 } });
  assert.equal(s.status, 'running');
  s = liveReducer(s, { type: 'live/cancel', payload: { id: 1 } });
  assert.equal(s.status, 'cancelled');
  assert.equal(liveActive(s), false);
  s = liveReducer(s, { type: 'live/error', payload: { id: 1, message: 'options.long_side: 9999 beyond 4096\nmore' } });
  assert.equal(s.message, 'options.long_side: 9999 beyond 4096');
});

test('the curves: every estimator\'s points on the x values of all, null where it has none', () => {
  const estimators = {
    a: { points: [{ spp: 2, seconds: 0.1, relmse: 1 }, { spp: 4, seconds: 0.3, relmse: 0.5 }] },
    b: { points: [{ spp: 4, seconds: 0.2, relmse: 0.25 }, { spp: 8, seconds: 0.4, relmse: 0 }] },
  };
  // a relative MSE of 0 is at the reference's noise: no number, a ring (its x index listed)
  assert.deepEqual(alignPoints(['a', 'b'], estimators, 'spp'),
    { xs: [2, 4, 8], ys: [[1, 0.5, null], [null, 0.25, null]], noise: [[], [2]] });
  assert.deepEqual(alignPoints(['a', 'b'], estimators, 'seconds'),
    { xs: [0.1, 0.2, 0.3, 0.4], ys: [[1, null, 0.5, null], [null, 0.25, null, null]], noise: [[], [3]] });
  assert.deepEqual(alignPoints(['c'], estimators, 'spp'), { xs: [], ys: [[]], noise: [[]] });
});

// Synthetic levels shaped as Veach's scene gave them (issue 48): mis_balance 3.4e-3 at 32 spp,
// then 1.0e-4 at 64 spp, 28x under a floor of 2.8e-3; bsdf 1.1 and 0.55.
const FLOOR = 2.8e-3;
function veachLike() {
  let s = initialLive();
  s = liveReducer(s, { type: 'live/start', payload: { id: 1, order: ['bsdf', 'mis_balance'], colors: {}, workers: 2, startedAt: 0 } });
  s = liveReducer(s, { type: 'live/reference', payload: { id: 1, reference: { status: 'ready', floor: FLOOR } } });
  for (const [estimator, spp, relmse] of [['bsdf', 32, 1.1], ['mis_balance', 32, 3.4e-3], ['bsdf', 64, 0.55], ['mis_balance', 64, 1.0e-4]]) {
    s = liveReducer(s, { type: 'live/level', payload: { id: 1, estimator, spp, seconds: spp / 10, relmse, now: 1 } });
  }
  return s;
}

test('a relative MSE below the reference\'s noise is never a number, on either side of the floor', () => {
  // the rule both ways: above the floor a number, below it (or at or below zero) none
  assert.equal(belowReferenceNoise(3.4e-3, FLOOR), false);
  assert.equal(belowReferenceNoise(1.0e-4, FLOOR), true);
  assert.equal(belowReferenceNoise(-2e-5, FLOOR), true);
  assert.equal(belowReferenceNoise(0, null), true);
  assert.equal(belowReferenceNoise(1e-9, null), false); // no floor known: only non-positive values
  assert.equal(belowReferenceNoise(null, FLOOR), false);
  assert.equal(relmseText(3.4e-3, FLOOR), '0.0034');
  assert.equal(relmseText(1.0e-4, FLOOR), 'at the reference\'s noise (below 0.0028)');
  assert.equal(relmseText(-2e-5, FLOOR), 'at the reference\'s noise (below 0.0028)');
  assert.equal(relmseText(-2e-5, null), 'at the reference\'s noise');
  assert.equal(relmseText(1.0e-4, 2.8e-5), '1.00e-4');
  assert.doesNotMatch(relmseText(1.0e-4, FLOOR), /1\.0*e-4|0\.0001/);
  assert.equal(shortNumber(2.8e-7, 2), '2.8e-7');
  assert.equal(shortNumber(1234567, 3), '1.23e+6');
});

test('a ratio against a level at the reference\'s noise is "at least" the ratio to the floor; none from a level at the noise', () => {
  assert.deepEqual(relmseRatio(3.4e-3, 1.1, FLOOR), { factor: 1.1 / 3.4e-3, atLeast: false });
  const r = relmseRatio(1.0e-4, 0.55, FLOOR);
  assert.equal(r.atLeast, true);
  assert.ok(Math.abs(r.factor - 0.55 / FLOOR) < 1e-9, String(r.factor)); // 196, not 5500
  assert.equal(relmseRatio(0.55, 1.0e-4, FLOOR), null);
  assert.equal(relmseRatio(1e-4, 2e-4, FLOOR), null);
});

test('Veach-like levels: the facts, the curves and the comparison say only what the reference supports', () => {
  const s = veachLike();
  const { floor } = s.reference;
  const { xs, ys, noise } = alignPoints(s.order, s.estimators, 'spp', floor);
  assert.deepEqual(xs, [32, 64]);
  assert.deepEqual(ys, [[1.1, 0.55], [3.4e-3, null]]);
  assert.deepEqual(noise, [[], [1]]);
  // no value drawn as a number lies under the floor
  assert.ok(ys.flat().filter((v) => v !== null).every((v) => v >= floor));
  const text = compareText(s.order, s.estimators, floor);
  assert.equal(text, 'At 64 spp mis_balance is at the reference\'s noise: its relative MSE is at least 196× lower than bsdf\'s; ' +
    'by how much more, the reference cannot tell.');
  assert.doesNotMatch(text, /5500/);
  // one level earlier both are measured: a plain ratio
  const at32 = { bsdf: { points: s.estimators.bsdf.points.slice(0, 1) }, mis_balance: { points: s.estimators.mis_balance.points.slice(0, 1) } };
  assert.match(compareText(s.order, at32, floor), /^At 32 spp mis_balance's relative MSE is 324× lower than bsdf's/);
  // both at the reference's noise: no ratio at all
  const both = { a: { points: [{ spp: 8, relmse: 1e-4 }] }, b: { points: [{ spp: 8, relmse: -1e-5 }] } };
  assert.equal(compareText(['a', 'b'], both, floor), 'At 8 spp every image is at the reference\'s noise: the reference cannot tell them apart.');
  assert.equal(compareText(['a'], both, floor), '');
});

test('the default estimators: the scene\'s MIS estimators and the strategies they combine, from its list', () => {
  const e = (name, strategy, more = {}) => ({ name, strategy, light_selection: 'power', light_sampling: 'solid_angle', ...more });
  // Veach's list: bsdf, light_solid_angle, light_area, mis_balance, mis_power
  const veach = [e('bsdf', 'bsdf'), e('light_solid_angle', 'light_solid_angle'), e('light_area', 'light_area'),
    e('mis_balance', 'mis_balance'), e('mis_power', 'mis_power')];
  assert.deepEqual(defaultEstimators(veach), ['bsdf', 'light_solid_angle', 'mis_balance', 'mis_power']);
  // any names: the rule reads the strategies; light sampling of the MIS's own kind (area here)
  const renamed = [e('h', 'cosine_hemisphere'), e('x', 'bsdf'), e('y', 'light_solid_angle'), e('u', 'light_area', { light_selection: 'uniform' }),
    e('z', 'light_area'), e('m', 'mis_power', { light_sampling: 'area' })];
  assert.deepEqual(defaultEstimators(renamed), ['x', 'y', 'z', 'm']);
  // one MIS estimator: it, BSDF and both light samplings before the hemisphere
  const one = [e('cosine_hemisphere', 'cosine_hemisphere'), e('bsdf', 'bsdf'), e('light_area', 'light_area'),
    e('light_solid_angle', 'light_solid_angle'), e('mis_power', 'mis_power')];
  assert.deepEqual(defaultEstimators(one), ['bsdf', 'light_area', 'light_solid_angle', 'mis_power']);
  // no MIS: the scene's first four, as before; names alone too
  assert.deepEqual(defaultEstimators(['a', 'b', 'c', 'd', 'e']), ['a', 'b', 'c', 'd']);
  assert.deepEqual(defaultEstimators([e('p', 'path'), e('q', 'path')]), ['p', 'q']);
  assert.deepEqual(defaultEstimators(null), []);
});
