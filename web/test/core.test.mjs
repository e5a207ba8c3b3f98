// Tests of web/core.js, the only code that talks to the wasm core, under Node's test runner:
//   MCPLAY_WASM_DIR=build-wasm MCPLAY_NATIVE=build/mcplay node --test web/test/
// MCPLAY_WASM_DIR holds mcplay_web.mjs + mcplay_web.wasm (default build-wasm), MCPLAY_NATIVE is
// the native CLI (default build/mcplay); relative paths are taken from the repository root.
// A missing module or CLI fails the tests that need it; nothing is skipped.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

import {
  loadCore, McplayError, Status, WASM_FUNCTIONS, WASM_RUNTIME_METHODS, MAX_JSON_BYTES,
} from '../core.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WASM_DIR = path.resolve(ROOT, process.env.MCPLAY_WASM_DIR || 'build-wasm');
const NATIVE = path.resolve(ROOT, process.env.MCPLAY_NATIVE || 'build/mcplay');
const MJS = path.join(WASM_DIR, 'mcplay_web.mjs');
const WASM = path.join(WASM_DIR, 'mcplay_web.wasm');

const EXP_1D = fs.readFileSync(path.join(ROOT, 'scenes', 'exp_1d.json'), 'utf8');
const EXPECTATION_4XY = fs.readFileSync(path.join(ROOT, 'scenes', 'expectation_4xy.json'), 'utf8');
const SMALL = { n_min: 16, n_max: 256, reps: 4, estimators: ['uniform', 'stratified'] };
const TINY_SCENE = { f: 'x^2', n_min: 16, n_max: 32, reps: 2, estimators: ['uniform'] };

// One core for the whole file, loaded on first use. A missing build rejects with a message
// saying what to build, so every test that needs the core fails with it.
let corePromise = null;
function getCore() {
  corePromise ??= (async () => {
    for (const f of [MJS, WASM]) {
      if (!fs.existsSync(f)) {
        throw new Error(`wasm module not found: ${f}. Build it with \`make build-wasm\` (target ` +
          'mcplay_web) or point MCPLAY_WASM_DIR at the directory holding mcplay_web.mjs/.wasm');
      }
    }
    const { default: createMcplay } = await import(pathToFileURL(MJS).href);
    return loadCore(createMcplay, { wasmBinary: fs.readFileSync(WASM) });
  })();
  return corePromise;
}

function runNative(args) {
  if (!fs.existsSync(NATIVE)) {
    throw new Error(`native CLI not found: ${NATIVE}. Build it with \`make build\` or set MCPLAY_NATIVE`);
  }
  return execFileSync(NATIVE, args, { cwd: ROOT, encoding: 'utf8', maxBuffer: 64 << 20 });
}

// Names listed in one of src/wasm/exported_*.txt ('#' comments, blank lines ignored).
function exportList(file) {
  return fs.readFileSync(path.join(ROOT, 'src', 'wasm', file), 'utf8').split('\n')
    .map((l) => l.trim()).filter((l) => l && !l.startsWith('#'));
}

// Asserts that fn() throws a McplayError with this status whose message matches re.
function assertMcplayError(fn, status, re) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof McplayError, `expected McplayError, got ${e && e.name}: ${e && e.message}`);
    assert.ok(e instanceof Error);
    assert.equal(e.name, 'McplayError');
    assert.equal(e.status, status, `status ${e.status} (${e.message})`);
    assert.match(e.message, re);
    return true;
  });
}

test('the wasm module is built and loads', async () => {
  assert.ok(fs.existsSync(MJS), `missing ${MJS}: run \`make build-wasm\` or set MCPLAY_WASM_DIR`);
  assert.ok(fs.existsSync(WASM), `missing ${WASM}: run \`make build-wasm\` or set MCPLAY_WASM_DIR`);
  await getCore();
});

test('the wrapper and the build agree on the exported names', () => {
  assert.deepEqual([...exportList('exported_functions.txt')].sort(), [...WASM_FUNCTIONS].sort(),
    'src/wasm/exported_functions.txt and WASM_FUNCTIONS in web/core.js differ');
  const runtime = new Set(exportList('exported_runtime_methods.txt'));
  for (const name of WASM_RUNTIME_METHODS) {
    assert.ok(runtime.has(name), `web/core.js uses ${name}, not in src/wasm/exported_runtime_methods.txt`);
  }
});

test('version is a semver string equal to the native CLI --version', async () => {
  const core = await getCore();
  const v = core.version();
  assert.match(v, /^\d+\.\d+\.\d+([-+].*)?$/);
  assert.equal(runNative(['--version']).trim(), `mcplay ${v}`);
});

test('catalog lists the estimator presets', async () => {
  const core = await getCore();
  const cat = core.catalog();
  assert.equal(cat.version, 1);
  const names = cat.estimators.map((e) => e.name);
  for (const preset of ['uniform', 'stratified', 'latin_hypercube', 'importance', 'stratified_importance']) {
    assert.ok(names.includes(preset), `catalog lacks preset ${preset}: ${names}`);
  }
  for (const e of cat.estimators) {
    assert.equal(typeof e.sampler, 'string');
    assert.equal(typeof e.needs_pdf, 'boolean');
  }
  assert.ok(cat.samplers.includes('stratified'));
  assert.ok(cat.domains.includes('box'));
});

test('sceneInfo summarises a scene given as text or as an object', async () => {
  const core = await getCore();
  const info = core.sceneInfo(EXP_1D);
  assert.equal(info.name, 'exp_1d');
  assert.equal(info.dimension, 1);
  assert.ok(Math.abs(info.exact - (Math.E - 1)) < 1e-15);
  assert.equal(info.estimators.length, 5);
  assert.deepEqual(core.sceneInfo(JSON.parse(EXP_1D)), info);
});

test('runStudy on exp_1d returns the documented result and reports every level', async () => {
  const core = await getCore();
  const seen = [];
  const r = core.runStudy(EXP_1D, SMALL, (level) => { seen.push(level); });
  assert.equal(r.version, 1);
  assert.equal(r.mcplay, core.version());
  assert.equal(r.cancelled, false);
  assert.equal(r.scene.name, 'exp_1d');
  assert.deepEqual(
    { n_min: r.settings.n_min, n_max: r.settings.n_max, reps: r.settings.reps },
    { n_min: 16, n_max: 256, reps: 4 });
  assert.deepEqual(r.estimators.map((e) => e.name), ['uniform', 'stratified']);
  for (const e of r.estimators) {
    assert.deepEqual(e.levels.map((l) => l.n), [16, 32, 64, 128, 256]);
    for (const l of e.levels) {
      assert.equal(l.reps, 4);
      assert.equal(l.replicates.estimate.length, 4);
      assert.equal(l.replicates.std_error.length, 4);
      assert.equal(typeof l.mean, 'number');
    }
    assert.equal(typeof e.fit.order, 'number');
  }
  // Uniform sampling's variance falls as 1/N, jittered sampling's as N^-3 on a smooth 1D
  // integrand: each fitted order within 4 of its standard errors (4 replicates: wide).
  const [uni, strat] = r.estimators.map((e) => e.fit);
  assert.ok(Math.abs(uni.order + 1) < 4 * uni.order_se, `uniform order ${uni.order} +- ${uni.order_se}`);
  assert.ok(Math.abs(strat.order + 3) < 4 * strat.order_se, `stratified order ${strat.order} +- ${strat.order_se}`);

  assert.equal(seen.length, 5, 'onLevel once per N');
  seen.forEach((level, i) => {
    assert.equal(level.level_index, i);
    assert.equal(level.n, 16 << i);
    assert.equal(level.version, 1);
    assert.deepEqual(level.estimators.map((e) => e.name), ['uniform', 'stratified']);
    level.estimators.forEach((e, k) => {
      assert.deepEqual(e.level.replicates, r.estimators[k].levels[i].replicates);
    });
  });
  // The same study without a callback gives the same numbers.
  const again = core.runStudy(JSON.parse(EXP_1D), JSON.stringify(SMALL));
  assert.deepEqual(again.estimators.map((e) => e.levels.map((l) => l.replicates)),
    r.estimators.map((e) => e.levels.map((l) => l.replicates)));
});

test('runStudy gives the native CLI\'s numbers bit for bit', async () => {
  // A polynomial integrand: no libm call between the integer-identical RNG and the sums (two
  // libms may differ in the last bit of exp or sin, so exp_1d is not bit-identical by design).
  const core = await getCore();
  const native = JSON.parse(runNative(['run', 'scenes/expectation_4xy.json', '--n-min', '16', '--n-max', '256',
    '--reps', '4', '--estimators', 'uniform,stratified', '--format', 'json', '--quiet']));
  const wasm = core.runStudy(EXPECTATION_4XY, SMALL);
  assert.equal(wasm.estimators.length, native.estimators.length);
  let compared = 0;
  wasm.estimators.forEach((we, k) => {
    const ne = native.estimators[k];
    assert.equal(we.name, ne.name);
    assert.equal(we.levels.length, ne.levels.length);
    we.levels.forEach((wl, i) => {
      const nl = ne.levels[i];
      assert.equal(wl.n, nl.n);
      for (const key of ['estimate', 'std_error']) {
        wl.replicates[key].forEach((x, r) => {
          // Exact equality: the RNG is integer-identical and the integrand a polynomial.
          assert.ok(Object.is(x, nl.replicates[key][r]),
            `${we.name} N=${wl.n} replicate ${r} ${key}: wasm ${x} vs native ${nl.replicates[key][r]}`);
          compared++;
        });
      }
      for (const key of ['mean', 'variance', 'std_error']) {
        assert.ok(Object.is(wl[key], nl[key]), `${we.name} N=${wl.n} ${key}: wasm ${wl[key]} vs native ${nl[key]}`);
      }
    });
  });
  assert.equal(compared, 2 * 5 * 4 * 2);
});

test('samples returns the points of the study\'s first replicate', async () => {
  const core = await getCore();
  const options = { ...SMALL, n_min: 64, n_max: 64 };
  const result = core.runStudy(EXP_1D, options);
  const dump = core.samples(EXP_1D, { estimators: SMALL.estimators, n: 64, grid: 16 });
  assert.equal(dump.estimators.length, 2);
  for (const [e, d] of dump.estimators.entries()) {
    assert.equal(d.weight.length, 64);
    const mean = d.weight.reduce((a, b) => a + b, 0) / 64;
    const estimate = result.estimators[e].levels[0].replicates.estimate[0];
    assert.ok(Math.abs(mean - estimate) <= 1e-13 * Math.abs(estimate), `${d.name}: ${mean} vs ${estimate}`);
  }
  assert.deepEqual(dump.estimators[1].strata, [64]);
  assert.equal(dump.curve.x.length, 16);
  assertMcplayError(() => core.samples(EXP_1D, { n: 100000 }), Status.ARGUMENT, /options\.n/);
});

test('samples of an MIS estimator: weights that average to its estimate, technique weights that sum to 1', async () => {
  const core = await getCore();
  const scene = {
    name: 'mis', domain: { type: 'interval', lower: 0, upper: 1 }, f: '1 + x + exp(-50 * (x - 0.3)^2)',
    estimators: [{ name: 'mis', proposals: [{ type: 'gaussian', mu: 0.3, sigma: 0.1 }, 'uniform'], heuristic: 'power' }],
  };
  const options = { reps: 2, n_min: 64, n_max: 64, seed: 3 };
  const result = core.runStudy(scene, options);
  const dump = core.samples(scene, { n: 64, grid: 32, seed: 3 });
  const d = dump.estimators[0];
  const mean = d.weight.reduce((a, b) => a + b, 0) / 64;
  const estimate = result.estimators[0].levels[0].replicates.estimate[0];
  assert.ok(Math.abs(mean - estimate) <= 1e-12 * Math.abs(estimate), `${mean} vs ${estimate}`);
  assert.equal(d.heuristic, 'power');
  assert.deepEqual(d.techniques.map((t) => t.share), [0.5, 0.5]);
  const w = dump.curve.mis_weights.mis;
  assert.equal(w.length, 2);
  for (let i = 0; i < 32; i++) assert.ok(Math.abs(w[0][i] + w[1][i] - 1) < 1e-12);
  assert.ok(w[0][Math.round(0.3 * 31)] > 0.5 && w[1][31] > 0.9, 'the peak pdf takes the peak, uniform the far end');
});

test('onLevel returning true cancels the study after that level', async () => {
  const core = await getCore();
  let calls = 0;
  const r = core.runStudy(EXP_1D, SMALL, () => ++calls === 2);
  assert.equal(calls, 2);
  assert.equal(r.cancelled, true);
  for (const e of r.estimators) assert.deepEqual(e.levels.map((l) => l.n), [16, 32]);
  // Only `true` cancels: other truthy values (e.g. the number Array.push returns) do not.
  const seen = [];
  const full = core.runStudy(EXP_1D, SMALL, (l) => seen.push(l));
  assert.equal(full.cancelled, false);
  assert.equal(seen.length, 5);
});

test('an exception thrown in onLevel propagates and the core keeps working', async () => {
  const core = await getCore();
  const boom = new Error('boom from onLevel');
  let calls = 0;
  assert.throws(() => core.runStudy(EXP_1D, SMALL, () => { if (++calls === 3) throw boom; }),
    (e) => e === boom);
  assert.equal(calls, 3, 'onLevel is not called again after it threw');
  // Non-Error values are rethrown as they are.
  assert.throws(() => core.runStudy(EXP_1D, SMALL, () => { throw 'a string'; }), (e) => e === 'a string');

  const reference = core.runStudy(EXP_1D, SMALL);
  assert.equal(reference.cancelled, false);
  assert.equal(reference.estimators[0].levels.length, 5);
  const levels = [];
  const after = core.runStudy(EXP_1D, SMALL, (l) => { levels.push(l.n); });
  assert.deepEqual(levels, [16, 32, 64, 128, 256]);
  assert.deepEqual(after.estimators.map((e) => e.levels.map((l) => l.replicates)),
    reference.estimators.map((e) => e.levels.map((l) => l.replicates)));
  assert.match(core.format(after, 'csv'), /uniform/);
});

test('runStudy is not re-entrant; other calls work inside onLevel', async () => {
  const core = await getCore();
  let inner = null;
  let info = null;
  const r = core.runStudy(EXP_1D, SMALL, () => {
    info = core.sceneInfo(EXP_1D);
    try {
      core.runStudy(EXP_1D, SMALL);
    } catch (e) {
      inner = e;
    }
    return true;
  });
  assert.equal(info.name, 'exp_1d');
  assert.ok(inner instanceof McplayError && inner.status === Status.ARGUMENT, String(inner));
  assert.match(inner.message, /already running/);
  assert.equal(r.cancelled, true);
});

test('bad scenes throw McplayError SCENE naming what is wrong', async () => {
  const core = await getCore();
  // Malformed JSON: line, column and byte.
  for (const call of [(s) => core.sceneInfo(s), (s) => core.runStudy(s, null)]) {
    assertMcplayError(() => call('{"f": "x", "n_max": }'), Status.SCENE,
      /^scene: invalid JSON: parse error at line 1, column \d+/);
    // Unknown field: named, with the known ones.
    assertMcplayError(() => call({ f: 'x', n_mx: 64 }), Status.SCENE, /unknown field 'n_mx'/);
    // Bad expression: the field and the 1-based position.
    assertMcplayError(() => call({ f: 'sin(' }), Status.SCENE, /^scene\.f: at position 5: /);
  }
  assertMcplayError(() => core.sceneInfo({ f: 'sinn(x)' }), Status.SCENE,
    /scene\.f: at position \d+: unknown function 'sinn'/);
  // Not JSON at all on the JS side.
  assertMcplayError(() => core.sceneInfo(42), Status.ARGUMENT, /scene: expected an object or JSON text/);
  assertMcplayError(() => core.runStudy(undefined), Status.ARGUMENT, /scene: expected/);
});

test('bad options and formats throw McplayError ARGUMENT', async () => {
  const core = await getCore();
  assertMcplayError(() => core.runStudy(EXP_1D, '{"reps": '), Status.ARGUMENT, /^options: invalid JSON/);
  assertMcplayError(() => core.runStudy(EXP_1D, SMALL, 'not a function'), Status.ARGUMENT, /onLevel/);
  const r = core.runStudy(TINY_SCENE, null);
  assertMcplayError(() => core.format(r, 'xml'), Status.ARGUMENT, /unknown format 'xml' \(known: table, json, csv\)/);
  assertMcplayError(() => core.format({ version: 1 }, 'table'), Status.ARGUMENT, /not an mcplay study result/);
  assertMcplayError(() => core.format('{', 'json'), Status.ARGUMENT, /^result: invalid JSON/);
});

test('format gives table, csv and json text', async () => {
  const core = await getCore();
  const r = core.runStudy(EXP_1D, SMALL);
  const table = core.format(r, 'table');
  assert.match(table, /^mcplay \d+\.\d+\.\d+ +scene exp_1d/);
  assert.match(table, /stratified/);
  const csv = core.format(JSON.stringify(r), 'csv');
  assert.ok(csv.split('\n').length > 10);
  assert.deepEqual(JSON.parse(core.format(r, 'json')), r);
  assert.match(core.format(r, 'json'), /\n  "/, 'json is pretty-printed');
  const native = runNative(['run', 'scenes/exp_1d.json', '--n-min', '16', '--n-max', '256', '--reps', '4',
    '--estimators', 'uniform,stratified', '--format', 'csv', '--quiet']);
  // Same columns as the CLI's CSV (timings differ, so only the header is compared).
  assert.equal(csv.split('\n')[0], native.split('\n')[0]);
});

test('200 calls leak nothing and do not grow the wasm heap', async () => {
  const core = await getCore();
  const cycle = (i) => {
    switch (i % 5) {
      case 0: return core.runStudy(TINY_SCENE, null, () => {});
      case 1: return core.runStudy(TINY_SCENE, { reps: 3 }, () => true);             // cancelled
      case 2: try { core.runStudy(TINY_SCENE, null, () => { throw new Error('x'); }); } catch { } return;
      case 3: try { core.sceneInfo({ f: 'sin(' }); } catch { } return;                // error path
      default: return core.format(core.runStudy(TINY_SCENE, null), 'table');
    }
  };
  for (let i = 0; i < 10; i++) cycle(i); // warm up: mcp_last_error's buffer etc. reach their size
  const before = core.heapStats();
  for (let i = 0; i < 200; i++) cycle(i);
  const after = core.heapStats();
  const grew = after.allocatedBytes - before.allocatedBytes;
  assert.ok(grew <= 256, `malloc'd bytes in use grew by ${grew} over 200 calls`);
  assert.ok(after.arenaBytes - before.arenaBytes <= 64 << 10,
    `malloc arena grew from ${before.arenaBytes} to ${after.arenaBytes}`);
  assert.equal(after.memoryBytes, before.memoryBytes, 'wasm memory grew');
});

test('strings cross as UTF-8, and large ones grow the wasm memory', async () => {
  const core = await getCore();
  const label = 'π ≈ 3.14159 — ∫ eˣ dx, ünïcödé 🎲 "quoted" \\ back\nslash';
  assert.equal(core.sceneInfo({ f: 'x', description: label }).description, label);
  assert.equal(core.runStudy({ ...TINY_SCENE, name: 'ñame 🎲' }, null).scene.name, 'ñame 🎲');
  // every ASCII character but NUL (copied by TextEncoder, the rest by stringToUTF8)
  const ascii = Array.from({ length: 127 }, (_, i) => String.fromCharCode(i + 1)).join('');
  assert.equal(core.sceneInfo({ f: 'x', description: ascii }).description, ascii);

  const before = core.heapStats();
  const big = 'x'.repeat(24 << 20); // 24 MB in and out: more than the initial 16 MB memory
  const info = core.sceneInfo({ f: 'x', description: big });
  assert.equal(info.description.length, big.length);
  const after = core.heapStats();
  assert.ok(after.memoryBytes > before.memoryBytes, 'the memory grew');
  assert.ok(after.allocatedBytes - before.allocatedBytes <= 256, 'and the big strings were freed');
  assert.equal(core.runStudy(TINY_SCENE, null).estimators.length, 1);
});

test('a disposed core refuses calls', async () => {
  const { default: createMcplay } = await import(pathToFileURL(MJS).href);
  const core = await loadCore(createMcplay, { wasmBinary: fs.readFileSync(WASM) });
  assert.equal(core.runStudy(TINY_SCENE, null).estimators.length, 1);
  core.dispose();
  core.dispose();
  assertMcplayError(() => core.version(), Status.ARGUMENT, /disposed/);
});

test('non-finite numbers are refused by name, not sent as null', async () => {
  const core = await getCore();
  assertMcplayError(() => core.runStudy({ ...TINY_SCENE, exact: NaN }, null), Status.ARGUMENT,
    /^scene\.exact: expected a finite number, got NaN$/);
  assertMcplayError(() => core.sceneInfo({ f: 'x', estimators: [{ name: 'g', pdf: { type: 'gaussian', mu: 0.5, sigma: Infinity } }] }),
    Status.ARGUMENT, /^scene\.estimators\[0\]\.pdf\.sigma: expected a finite number, got Infinity$/);
  assertMcplayError(() => core.runStudy(TINY_SCENE, { n_max: -Infinity }), Status.ARGUMENT,
    /^options\.n_max: expected a finite number, got -Infinity$/);
  assertMcplayError(() => core.plan(TINY_SCENE, { reps: NaN }), Status.ARGUMENT, /^options\.reps: /);
  // Values JSON cannot hold: a clear error, and the core goes on working.
  const cyclic = { f: 'x' };
  cyclic.self = cyclic;
  assertMcplayError(() => core.sceneInfo(cyclic), Status.ARGUMENT, /^scene: cannot be written as JSON/);
  assertMcplayError(() => core.sceneInfo({ f: 'x', n_max: 10n }), Status.ARGUMENT, /^scene: cannot be written as JSON/);
  assertMcplayError(() => core.sceneInfo(Symbol('s')), Status.ARGUMENT, /^scene: expected an object or JSON text, got symbol/);
  assert.equal(core.runStudy(TINY_SCENE, null).estimators.length, 1);
});

test('format refuses results of the wrong shape with a clear error', async () => {
  const core = await getCore();
  assertMcplayError(() => core.format({ estimators: 5 }), Status.ARGUMENT,
    /^result\.estimators: expected an array, got number$/);
  assertMcplayError(() => core.format({ estimators: [{ levels: 'x' }] }, 'csv'), Status.ARGUMENT,
    /^result\.estimators\[0\]\.levels: expected an array, got string$/);
  assertMcplayError(() => core.format(core.runStudy(TINY_SCENE, null), 'table\0'), Status.ARGUMENT, /^format: expected one of/);
  assert.match(core.format(core.runStudy(TINY_SCENE, null), 'table'), /uniform/);
});

test('a text beyond the size limit is refused before it reaches the wasm memory', async () => {
  const core = await getCore();
  const before = core.heapStats();
  const huge = 'x'.repeat(MAX_JSON_BYTES + 1);
  assertMcplayError(() => core.sceneInfo(huge), Status.ARGUMENT, /^scene: the JSON text has more than the limit/);
  assert.equal(core.heapStats().memoryBytes, before.memoryBytes, 'no memory was grown for it');
  assert.equal(core.sceneInfo({ f: 'x' }).dimension, 1);
});

test('plan validates like runStudy and predicts the cost of a study', async () => {
  const core = await getCore();
  const p = core.plan(EXP_1D, SMALL);
  assert.equal(p.evaluations, (16 + 32 + 64 + 128 + 256) * 4 * 2);
  assert.deepEqual(p.levels, [16, 32, 64, 128, 256]);
  assert.equal(p.threads, 1);
  assert.ok(p.predicted_seconds > 0 && p.pilot_seconds < 0.5);
  assert.deepEqual(p.estimators.map((e) => e.name), ['uniform', 'stratified']);
  // The study that is too big is refused by both, with the same message.
  const big = { f: 'x*x', estimators: ['uniform'], n_max: 2 ** 36, reps: 32 };
  let message = null;
  assert.throws(() => core.runStudy(big), (e) => { message = e.message; return e.status === Status.SCENE; });
  assert.match(message, /^scene: n_max = 68719476736, reps = 32 and 1 estimator\(s\) ask for/);
  assertMcplayError(() => core.plan(big), Status.SCENE, new RegExp(`^${message.replace(/[()^.*+?[\]\\]/g, '\\$&')}$`));
});

test('deeply nested and oversized inputs get errors and leave the module usable', async () => {
  const core = await getCore();
  // 8,000 levels used to overflow the wasm stack ("Maximum call stack size exceeded"), after
  // which every call failed: the nesting is now refused before any recursive walk.
  for (const depth of [8000, 150000]) {
    const text = '['.repeat(depth) + ']'.repeat(depth);
    assertMcplayError(() => core.sceneInfo(text), Status.SCENE, /nested more than 64 levels deep/);
    assertMcplayError(() => core.runStudy(TINY_SCENE, text), Status.ARGUMENT, /^options: invalid JSON: objects and arrays are nested/);
  }
  assertMcplayError(() => core.sceneInfo({ f: '('.repeat(100000) + 'x' + ')'.repeat(100000) }), Status.SCENE, /^scene\.f: /);
  assertMcplayError(() => core.sceneInfo('{"f": "x", "f": "x^2"}'), Status.SCENE, /appears twice/);
  assertMcplayError(() => core.runStudy({ ...TINY_SCENE, n_max: 2 ** 36, reps: 32 }), Status.SCENE, /integrand evaluations/);
  // Still usable, with the same numbers as before.
  const a = core.runStudy(TINY_SCENE, null);
  assert.equal(a.estimators[0].levels.length, 2);
  assert.deepEqual(core.runStudy(TINY_SCENE, null).estimators[0].levels[0].replicates,
    a.estimators[0].levels[0].replicates);
});
