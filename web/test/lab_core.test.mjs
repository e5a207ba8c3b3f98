// Tests of web/core.js's sampler-lab wrappers against the wasm build, under Node's test runner:
//   MCPLAY_WASM_DIR=build-wasm node --test web/test/lab_core.test.mjs
// (MCPLAY_WASM_DIR holds mcplay_web.mjs + .wasm, default build-wasm, relative to the repository
// root). Each wrapper: a documented answer, and one error as McplayError with the core's message.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { loadCore, McplayError, Status } from '../core.js';
import { fileRequest } from '../src/lab/model.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WASM_DIR = path.resolve(ROOT, process.env.MCPLAY_WASM_DIR || 'build-wasm');
const SIN2D = JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', 'sin_product_2d.json'), 'utf8'));

let corePromise = null;
function getCore() {
  corePromise ??= (async () => {
    const mjs = path.join(WASM_DIR, 'mcplay_web.mjs');
    const wasm = path.join(WASM_DIR, 'mcplay_web.wasm');
    for (const f of [mjs, wasm]) if (!fs.existsSync(f)) throw new Error(`wasm module not found: ${f} (make build-wasm, or set MCPLAY_WASM_DIR)`);
    const { default: create } = await import(pathToFileURL(mjs).href);
    return loadCore(create, { wasmBinary: fs.readFileSync(wasm) });
  })();
  return corePromise;
}

function assertMcplayError(fn, status, re) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof McplayError, `expected McplayError, got ${e && e.name}: ${e && e.message}`);
    assert.equal(e.status, status, `status ${e.status} (${e.message})`);
    assert.match(e.message, re);
    return true;
  });
}

test('points: n rows of dim coordinates in [0, 1), the same for the same seed; an unknown sampler is refused', async () => {
  const core = await getCore();
  const p = core.points({ sampler: 'sobol', n: 64, dim: 3, seed: 5 });
  assert.equal(p.sampler, 'sobol');
  assert.equal(p.randomization, 'owen');
  assert.equal(p.points.length, 64);
  for (const row of p.points) {
    assert.equal(row.length, 3);
    for (const v of row) assert.ok(v >= 0 && v < 1, String(v));
  }
  assert.deepEqual(core.points({ sampler: 'sobol', n: 64, dim: 3, seed: 5 }).points, p.points);
  const plain = core.points({ sampler: 'sobol', n: 4, dim: 1, seed: 1, randomization: 'none' });
  assert.deepEqual(plain.points, [[0], [0.5], [0.75], [0.25]]);
  assertMcplayError(() => core.points({ sampler: 'nope', n: 4 }), Status.ARGUMENT, /^request\.sampler: unknown sampler 'nope'/);
});

test('analyzePoints: measures beside the independent-points expectation, the spectrum; a bad CSV row named', async () => {
  const core = await getCore();
  const a = core.analyzePoints({ sampler: { sampler: 'sobol', n: 256, dim: 2, seed: 1 }, spectrum: { axes: [0, 1], size: 64 } });
  assert.equal(a.n, 256);
  assert.equal(a.dim, 2);
  assert.ok(a.l2_star_discrepancy > 0 && a.l2_star_discrepancy < a.expected_iid.l2_star_discrepancy,
    `Sobol' ${a.l2_star_discrepancy} against independent ${a.expected_iid.l2_star_discrepancy}`);
  assert.equal(a.spectrum.size, 64);
  assert.equal(a.spectrum.power.length, 64 * 64);
  assert.deepEqual(a.spectrum.axes, [0, 1]);
  assert.equal(a.spectrum.radial.frequency.length, a.spectrum.radial.power.length);
  assert.deepEqual(a.skipped, {});
  // the file -> request logic of the page, through the core
  const csv = fileRequest('p.csv', 'x,y\n0.1,0.2\n0.3,0.25\n0.5,0.5\n');
  assert.equal(core.analyzePoints({ ...csv.request, spectrum: false }).n, 3);
  const json = fileRequest('p.json', '[[[0.1, 0.2], [0.6, 0.7]], [[0.3, 0.4], [0.8, 0.9]]]');
  const two = core.analyzePoints({ ...json.request, spectrum: false, pairwise: false });
  assert.equal(two.sets, 2);
  assert.match(two.skipped.l2_star_discrepancy, /pairwise: false/);
  const bad = fileRequest('bad.csv', 'x,y\n0.1,0.2\n0.3,1.2\n');
  assertMcplayError(() => core.analyzePoints(bad.request), Status.ARGUMENT, /^request\.csv: row 3, column 2: '1\.2' is outside \[0, 1\)$/);
});

test('discrepancyCurve: a curve per sampler over the powers of two, RMS error with a problem; reps 0 refused', async () => {
  const core = await getCore();
  const c = core.discrepancyCurve({ samplers: ['uniform', 'sobol'], dim: 2, n_min: 16, n_max: 256, reps: 4, seed: 1, scene: SIN2D });
  assert.deepEqual(c.curves.map((x) => x.sampler), ['independent', 'sobol']);
  for (const x of c.curves) {
    assert.deepEqual(x.n, [16, 32, 64, 128, 256]);
    assert.equal(x.rms_error.length, 5);
  }
  assert.equal(c.problem, 'sin_product_2d');
  const [u, s] = c.curves;
  assert.ok(s.l2_star_discrepancy[4] < u.l2_star_discrepancy[4]);
  assertMcplayError(() => core.discrepancyCurve({ reps: 0 }), Status.ARGUMENT, /^request\.reps: expected 1 to 64/);
});

test('integratePoints: one set is a deterministic rule, K sets a t interval; points of the wrong dimension refused', async () => {
  const core = await getCore();
  const one = core.integratePoints(SIN2D, { sampler: { sampler: 'sobol', n: 256, dim: 2, seed: 1, randomization: 'none' } });
  assert.equal(one.sets, 1);
  assert.equal(one.error_bar, null);
  assert.match(one.note, /deterministic rule/);
  assert.ok(Math.abs(one.error) < 1e-3);
  const k = core.integratePoints(SIN2D, { sampler: { sampler: 'sobol', n: 256, dim: 2, seed: 1, sets: 8 } });
  assert.equal(k.sets, 8);
  assert.equal(k.error_bar.degrees_of_freedom, 7);
  assert.ok(k.error_bar.half_width_95 > 0);
  assertMcplayError(() => core.integratePoints(SIN2D, { sampler: { sampler: 'sobol', n: 16, dim: 3, seed: 1 } }), Status.ARGUMENT,
    /^request: the points have 3 coordinates/);
});

const DISK = (g) => ({ warp: { domain: { type: 'disk', radius: 1 }, g, p: '1/pi' } });

test('warpTest: the wrong polar disk fails, the right one passes; a warp leaving its domain is a scene error', async () => {
  const core = await getCore();
  const wrong = core.warpTest(DISK(['u1*cos(2*pi*u2)', 'u1*sin(2*pi*u2)']), { samples: 100000, seed: 1 });
  assert.equal(wrong.passed, false);
  assert.equal(typeof wrong.verdict, 'string');
  assert.equal(wrong.observed.length, wrong.bins.reduce((a, b) => a * b, 1));
  assert.equal(wrong.expected.length, wrong.observed.length);
  assert.equal(wrong.coordinates.length, wrong.bins.length);
  assert.ok(wrong.worst_bins.length > 0);
  // seed 2: seed 1 is one of the 1% of seeds a level-0.01 test rejects with 12 x 12 bins
  const right = core.warpTest(DISK(['sqrt(u1)*cos(2*pi*u2)', 'sqrt(u1)*sin(2*pi*u2)']), { samples: 100000, seed: 2 });
  assert.equal(right.passed, true, right.verdict);
  assert.ok(Math.abs(right.pdf_integral - 1) < 1e-3);
  assert.ok(right.p_value > right.level);
  assertMcplayError(() => core.warpTest(DISK(['2*u1', 'u2']), { samples: 1000 }), Status.SCENE, /./);
});
