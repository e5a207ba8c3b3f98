// The npm package as a user gets it: `make test-npm` packs it, installs the tarball into an
// empty temporary folder and runs this file there (copied beside that folder's node_modules), so
// `mcplay` is imported by its package name from the installed copy, not from the repository:
//   MCPLAY_ROOT=<repository> MCPLAY_NATIVE=<repository>/build/mcplay node --test installed.test.mjs
// The studies are checked against the native CLI's `--format json` output for the same scene
// and options. A missing CLI or repository fails the tests that need them; nothing is skipped.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

import { load, loadCore, McplayError, Status, MAX_JSON_BYTES } from 'mcplay';
import { load as loadRender, McplayError as RenderMcplayError } from 'mcplay/render';

const HERE = path.dirname(fileURLToPath(import.meta.url));
const ROOT = path.resolve(process.env.MCPLAY_ROOT ?? path.join(HERE, '..', '..'));
const NATIVE = path.resolve(ROOT, process.env.MCPLAY_NATIVE ?? 'build/mcplay');

// Fields that differ between two runs of the same study: timings, thread counts, the render
// accelerator, the scene file's path. The rule of tests/compare_results.mjs (the native CLI
// against the wasm CLI, `make test-compare`), whose list this is.
const VARYING = new Set(['time_mean_s', 'time_std_s', 'time_median_s', 'time_median_ci95_s',
  'time_total_s', 'training_time_mean_s', 'efficiency', 'wall_time_s', 'threads',
  'rays_per_second', 'seconds', 'file', 'accel']);

// Polynomial integrands only: between the integer-identical random streams and the sums there
// is no libm call (glibc's and the wasm libm's sin or exp may differ in the last bit), so every
// other number is bit for bit the native one.
const STUDY = { n_min: 16, n_max: 1024, reps: 4, seed: 7,
  estimators: ['uniform', 'stratified', 'latin_hypercube', 'sobol'] };
const INLINE_SCENE = {
  name: 'npm_inline',
  description: 'an expression typed inline: x^2 y + 3 z on the unit cube',
  f: 'x1^2 * x2 + 3 * x3',
  exact: 1 / 6 + 3 / 2,
};

function runNative(args, input) {
  if (!fs.existsSync(NATIVE)) {
    throw new Error(`native CLI not found: ${NATIVE}. Build it with \`make build\` or set MCPLAY_NATIVE`);
  }
  return execFileSync(NATIVE, args, { cwd: ROOT, encoding: 'utf8', maxBuffer: 64 << 20, input });
}

// The native CLI's JSON result for a scene file and the options of STUDY.
function nativeStudy(sceneFile) {
  return JSON.parse(runNative(['run', sceneFile, '--n-min', String(STUDY.n_min), '--n-max',
    String(STUDY.n_max), '--reps', String(STUDY.reps), '--seed', String(STUDY.seed),
    '--estimators', STUDY.estimators.join(','), '--threads', '2', '--format', 'json', '--quiet']));
}

// Asserts that two results agree field for field, numbers with Object.is, except VARYING.
// Returns how many numbers were compared.
function assertSameResult(actual, expected, where = 'result') {
  if (typeof expected === 'number' || typeof actual === 'number') {
    assert.ok(Object.is(actual, expected), `${where}: package ${actual} vs native ${expected}`);
    return 1;
  }
  if (expected === null || actual === null || typeof expected !== 'object' || typeof actual !== 'object') {
    assert.deepEqual(actual, expected, where);
    return 0;
  }
  assert.equal(Array.isArray(actual), Array.isArray(expected), `${where}: array vs object`);
  const keys = [...new Set([...Object.keys(actual), ...Object.keys(expected)])].filter((k) => !VARYING.has(k));
  let count = 0;
  for (const k of keys) {
    assert.ok(k in actual, `${where}.${k}: missing from the package's result`);
    assert.ok(k in expected, `${where}.${k}: missing from the native result`);
    count += assertSameResult(actual[k], expected[k], `${where}.${k}`);
  }
  return count;
}

let corePromise = null;
const getCore = () => (corePromise ??= load());

function readScene(name) {
  return fs.readFileSync(path.join(ROOT, 'scenes', name), 'utf8');
}

test('"mcplay" resolves to the installed package, whose version is the core\'s and the CLI\'s', async () => {
  const resolved = fileURLToPath(import.meta.resolve('mcplay'));
  const installed = path.join(process.cwd(), 'node_modules', 'mcplay');
  assert.ok(resolved.startsWith(installed + path.sep), `mcplay resolved to ${resolved}, not under ${installed}`);
  assert.ok(fileURLToPath(import.meta.resolve('mcplay/render')).startsWith(installed + path.sep));
  const pkg = JSON.parse(fs.readFileSync(path.join(installed, 'package.json'), 'utf8'));
  assert.deepEqual(Object.keys(pkg.dependencies ?? {}), [], 'no runtime dependencies');
  const core = await getCore();
  assert.equal(core.version(), pkg.version);
  assert.equal(runNative(['--version']).trim(), `mcplay ${pkg.version}`);
  assert.equal(typeof loadCore, 'function');
  assert.equal(MAX_JSON_BYTES, 256 * 1024 * 1024);
});

test('a bundled scene\'s JSON gives the native CLI\'s result, bit for bit but the timings', async () => {
  const core = await getCore();
  const levels = [];
  const result = core.runStudy(readScene('expectation_4xy.json'), STUDY, (p) => { levels.push(p.n); });
  assert.deepEqual(levels, [16, 32, 64, 128, 256, 512, 1024]);
  assert.equal(result.cancelled, false);
  assert.deepEqual(result.estimators.map((e) => e.name), STUDY.estimators);
  const compared = assertSameResult(result, nativeStudy('scenes/expectation_4xy.json'));
  // every replicate's estimate and error bar, at least, were compared
  assert.ok(compared > STUDY.estimators.length * levels.length * STUDY.reps * 2, `${compared} numbers`);
});

test('an inline expression scene gives the native CLI\'s result for the same scene file', async () => {
  const core = await getCore();
  const result = core.runStudy(INLINE_SCENE, STUDY);
  assert.equal(result.scene.dimension, 3);
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'mcplay-npm-'));
  try {
    const file = path.join(dir, 'npm_inline.json');
    fs.writeFileSync(file, JSON.stringify(INLINE_SCENE));
    assertSameResult(result, nativeStudy(file));
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
  // and the estimates are near the exact value, within 5 standard errors at the largest N
  for (const e of result.estimators) {
    const top = e.levels.at(-1);
    assert.ok(Math.abs(top.mean - INLINE_SCENE.exact) <= 5 * top.std_error + 1e-12,
      `${e.name}: ${top.mean} +- ${top.std_error} vs ${INLINE_SCENE.exact}`);
  }
});

// A study table's text without what a second run changes: the header's thread count and wall
// time, the levels' time/est and efficiency columns, the comparison's time, efficiency and ratio.
function tableWithoutTimings(table) {
  let comparison = false;
  return table.split('\n').map((line) => {
    if (line.startsWith('comparison at the largest N')) comparison = true;
    const fields = line.trim().split(/\s+/);
    if (/ thread\(s\), /.test(line)) return line.replace(/ \d+ thread\(s\), .*$/, '');
    if (comparison && fields.length === 6 && /^\d+$/.test(fields[1])) return fields.slice(0, 3).join(' ');
    if (fields.length === 9 && /^\d+$/.test(fields[0])) return fields.slice(0, 7).join(' ');
    return line;
  });
}

test('format gives the CLI\'s table, and csv and json, for a result', async () => {
  const core = await getCore();
  const options = { ...STUDY, n_max: 64 };
  const result = core.runStudy(INLINE_SCENE, options);
  const table = core.format(result);
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'mcplay-npm-'));
  let native;
  try {
    const file = path.join(dir, 'npm_inline.json');
    fs.writeFileSync(file, JSON.stringify(INLINE_SCENE));
    native = runNative(['run', file, '--n-min', '16', '--n-max', '64', '--reps', String(STUDY.reps),
      '--seed', String(STUDY.seed), '--estimators', STUDY.estimators.join(','), '--threads', '2',
      '--format', 'table', '--quiet']);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
  const lines = tableWithoutTimings(table);
  assert.deepEqual(lines, tableWithoutTimings(native));
  assert.equal(lines.filter((l) => /^16 \S+ \S+/.test(l)).length, STUDY.estimators.length, 'a row at N = 16 per estimator');
  const csv = core.format(result, 'csv').trim().split('\n');
  assert.equal(csv.length - 1, STUDY.estimators.length * 3, 'one CSV row per estimator and N');
  assert.deepEqual(JSON.parse(core.format(result, 'json')), result);
  assert.throws(() => core.format(result, 'xml'), (e) => e instanceof McplayError && e.status === Status.ARGUMENT);
});

test('catalog lists the presets the CLI lists', async () => {
  const core = await getCore();
  const catalog = core.catalog();
  const names = catalog.estimators.map((e) => e.name);
  for (const must of ['uniform', 'stratified', 'latin_hypercube', 'sobol', 'vegas', 'miser']) {
    assert.ok(names.includes(must), `catalog has no ${must}`);
  }
  const listed = runNative(['list']);
  for (const e of catalog.estimators) {
    assert.match(listed, new RegExp(`^  ${e.name} +${e.summary.replace(/[.*+?^${}()|[\]\\]/g, '\\$&')}`, 'm'),
      `the CLI's list has no line for ${e.name}`);
  }
});

test('a bad scene throws McplayError with the C message, the one the CLI prints', async () => {
  const core = await getCore();
  const bad = { name: 'bad', f: 'x1 +* 2' };
  let caught = null;
  try {
    core.runStudy(bad, STUDY);
  } catch (e) {
    caught = e;
  }
  assert.ok(caught instanceof McplayError, `expected McplayError, got ${caught}`);
  assert.ok(caught instanceof Error);
  assert.equal(caught.status, Status.SCENE);
  assert.equal(caught.statusName, 'SCENE');
  assert.doesNotMatch(caught.message, /\n/, 'one line');
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'mcplay-npm-'));
  try {
    const file = path.join(dir, 'bad.json');
    fs.writeFileSync(file, JSON.stringify(bad));
    const cli = spawnSync(NATIVE, ['run', file, '--quiet'], { encoding: 'utf8' });
    assert.equal(cli.status, 3, `CLI exit status ${cli.status}: ${cli.stderr}`);
    assert.equal(cli.stderr.trim(), `mcplay: ${file}: ${caught.message}`);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
  // the core is still usable, and bad options for load are refused by name
  assert.equal(core.sceneInfo(INLINE_SCENE).dimension, 3);
  await assert.rejects(load(null), /load: options must be an object/);
});

test('"mcplay/render" renders a tiny image of a bundled render scene', async () => {
  const render = await loadRender();
  assert.equal(render.version(), (await getCore()).version());
  assert.equal(RenderMcplayError, McplayError, 'one error class for both entries');
  // The wasm module reads no files: the scene's glTF goes inline (its buffers are data: URIs).
  const scene = JSON.parse(readScene('quad_light_floor.json'));
  scene.render.gltf = JSON.parse(readScene(scene.render.gltf));
  const image = render.renderImage(scene, { estimator: 'light_area', spp: 1, width: 16, height: 12,
    outputs: ['pfm'], seed: 3 });
  assert.equal(image.kind, 'render_image');
  // A PFM: "PF\n<width> <height>\n<-1: little-endian>\n" then width x height RGB float32.
  const pfm = Buffer.from(image.images.pfm, 'base64');
  const header = /^PF\n(\d+) (\d+)\n(-?[0-9.]+)\n/.exec(pfm.subarray(0, 64).toString('latin1'));
  assert.ok(header, 'a colour PFM header');
  assert.deepEqual([Number(header[1]), Number(header[2])], [16, 12]);
  assert.ok(Number(header[3]) < 0, 'little-endian');
  const data = pfm.subarray(header[0].length);
  assert.equal(data.length, 16 * 12 * 3 * 4);
  const pixels = new Float32Array(data.buffer.slice(data.byteOffset, data.byteOffset + data.length));
  assert.ok(pixels.every((v) => Number.isFinite(v) && v >= 0), 'finite, non-negative radiance');
  assert.ok(pixels.some((v) => v > 0), 'the light reaches the floor');
  // and a bad render scene is refused with the C message
  assert.throws(() => render.renderImage({ render: { gltf: {} } }, { spp: 1 }),
    (e) => e instanceof McplayError && e.status === Status.SCENE && /gltf/.test(e.message));
  render.dispose();
});

// The ```js blocks of the installed package's README, in order.
function readmeExamples() {
  const readme = fs.readFileSync(path.join(process.cwd(), 'node_modules', 'mcplay', 'README.md'), 'utf8');
  return [...readme.matchAll(/^```js\n([\s\S]*?)^```$/gm)].map((m) => m[1]);
}

test('the README\'s examples run as written', () => {
  const [quickStart, renderExample] = readmeExamples();
  assert.ok(quickStart && renderExample, 'two js examples in README.md');
  assert.ok(quickStart.trim().split('\n').length <= 5, 'the quick start is five lines');
  const dir = fs.mkdtempSync(path.join(process.cwd(), 'readme-'));
  try {
    // Beside node_modules, so that the examples import the installed package; the render
    // example reads the repository's scenes/ through a link.
    fs.writeFileSync(path.join(dir, 'study.mjs'), quickStart);
    fs.writeFileSync(path.join(dir, 'render.mjs'), renderExample);
    fs.symlinkSync(path.join(ROOT, 'scenes'), path.join(dir, 'scenes'));
    const out = execFileSync(process.execPath, ['study.mjs'], { cwd: dir, encoding: 'utf8' });
    assert.match(out, /^mcplay \d+\.\d+\.\d+ {2}scene /);
    for (const name of ['uniform', 'stratified', 'sobol']) assert.match(out, new RegExp(`^${name} {2}\\[`, 'm'));
    assert.match(out, /fitted order: variance ~ N\^\(-/);
    execFileSync(process.execPath, ['render.mjs'], { cwd: dir, encoding: 'utf8' });
    const png = fs.readFileSync(path.join(dir, 'floor.png'));
    assert.equal(png.subarray(1, 4).toString('latin1'), 'PNG');
    const scene = JSON.parse(readScene('quad_light_floor.json'));
    // IHDR: width and height, big-endian, at bytes 16 and 20
    assert.deepEqual([png.readUInt32BE(16), png.readUInt32BE(20)], [scene.render.width, scene.render.height]);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});
