// Tests of web/render_core.js, the only code that talks to the render wasm module, under Node's
// test runner: MCPLAY_WASM_DIR=build-wasm node --test web/test/
// MCPLAY_WASM_DIR holds mcplay_render_web.mjs + .wasm (default build-wasm), MCPLAY_NATIVE is the
// native CLI (default build/mcplay); relative paths are taken from the repository root. The scene is built here: a grey floor quad under a quad light and a
// camera looking down, as glTF JSON with its buffer embedded as base64, inline in the scene
// (as the playground passes it). A missing module fails the tests that need it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

import { loadRenderCore, McplayError, Status, RENDER_WASM_FUNCTIONS, RENDER_WASM_RUNTIME_METHODS } from '../render_core.js';
import { McplayError as CoreMcplayError } from '../core.js';
import { isRenderScene } from '../src/protocol.js';
import { manifestEntry, siteScene, inlineGltf } from '../tools/build-site.mjs';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WASM_DIR = path.resolve(ROOT, process.env.MCPLAY_WASM_DIR || 'build-wasm');
const MJS = path.join(WASM_DIR, 'mcplay_render_web.mjs');
const WASM = path.join(WASM_DIR, 'mcplay_render_web.wasm');
const NATIVE = path.resolve(ROOT, process.env.MCPLAY_NATIVE || 'build/mcplay');

/** A 4 x 4 m floor (albedo 0.5) at y = 0 under a 1 x 1 m light of radiance Le at height h facing
 *  down; the camera at half the height looks straight down. One buffer: positions then indices. */
function quadLightGltf({ h = 1, Le = 5 } = {}) {
  const pos = new Float32Array([
    -2, 0, -2, -2, 0, 2, 2, 0, 2, 2, 0, -2, // floor, counter-clockwise seen from +y
    -0.5, h, -0.5, 0.5, h, -0.5, 0.5, h, 0.5, -0.5, h, 0.5, // light, counter-clockwise seen from -y
  ]);
  const idx = new Uint16Array([0, 1, 2, 0, 2, 3]);
  const bytes = Buffer.concat([Buffer.from(pos.buffer), Buffer.from(idx.buffer)]);
  return {
    asset: { version: '2.0' },
    extensionsUsed: ['KHR_materials_emissive_strength'],
    scene: 0,
    scenes: [{ nodes: [0, 1, 2] }],
    nodes: [
      { mesh: 0 }, { mesh: 1 },
      // the camera looks along its -z: rotated by -90 degrees about x, it looks down (-y)
      { camera: 0, translation: [0, 0.5 * h, 0], rotation: [-Math.SQRT1_2, 0, 0, Math.SQRT1_2] },
    ],
    cameras: [{ type: 'perspective', perspective: { yfov: 1.2, znear: 0.01, aspectRatio: 1 } }],
    meshes: [
      { primitives: [{ attributes: { POSITION: 0 }, indices: 2, material: 0 }] },
      { primitives: [{ attributes: { POSITION: 1 }, indices: 2, material: 1 }] },
    ],
    materials: [
      { pbrMetallicRoughness: { baseColorFactor: [0.5, 0.5, 0.5, 1], metallicFactor: 0, roughnessFactor: 1 } },
      {
        pbrMetallicRoughness: { baseColorFactor: [0, 0, 0, 1], metallicFactor: 0, roughnessFactor: 1 },
        emissiveFactor: [1, 1, 1], extensions: { KHR_materials_emissive_strength: { emissiveStrength: Le } },
      },
    ],
    buffers: [{ byteLength: bytes.length, uri: `data:application/octet-stream;base64,${bytes.toString('base64')}` }],
    bufferViews: [
      { buffer: 0, byteOffset: 0, byteLength: pos.byteLength, target: 34962 },
      { buffer: 0, byteOffset: pos.byteLength, byteLength: idx.byteLength, target: 34963 },
    ],
    accessors: [
      { bufferView: 0, byteOffset: 0, componentType: 5126, count: 4, type: 'VEC3', min: [-2, 0, -2], max: [2, 0, 2] },
      { bufferView: 0, byteOffset: 48, componentType: 5126, count: 4, type: 'VEC3', min: [-0.5, h, -0.5], max: [0.5, h, 0.5] },
      { bufferView: 1, byteOffset: 0, componentType: 5123, count: 6, type: 'SCALAR' },
    ],
  };
}

const ESTIMATORS = ['cosine_hemisphere', 'light_area', 'mis_power'];
const SCENE = {
  name: 'tiny_quad_light',
  description: 'floor under a quad light',
  render: { gltf: quadLightGltf(), width: 16, height: 16, spp_min: 1, spp_max: 8, reps: 3, estimators: ESTIMATORS },
};
const SMALL = { spp_min: 1, spp_max: 4, reps: 2, width: 8, height: 8 };

let corePromise = null;
function getCore() {
  corePromise ??= (async () => {
    for (const f of [MJS, WASM]) {
      if (!fs.existsSync(f)) {
        throw new Error(`render wasm module not found: ${f}. Build it with \`make build-wasm\` (target ` +
          'mcplay_render_web) or point MCPLAY_WASM_DIR at the directory holding mcplay_render_web.mjs/.wasm');
      }
    }
    const { default: create } = await import(pathToFileURL(MJS).href);
    return loadRenderCore(create, { wasmBinary: fs.readFileSync(WASM) });
  })();
  return corePromise;
}

function exportList(file) {
  return fs.readFileSync(path.join(ROOT, 'src', 'wasm', file), 'utf8').split('\n')
    .map((l) => l.trim()).filter((l) => l && !l.startsWith('#'));
}

function assertMcplayError(fn, status, re) {
  assert.throws(fn, (e) => {
    assert.ok(e instanceof McplayError, `expected McplayError, got ${e && e.name}: ${e && e.message}`);
    assert.equal(e.status, status, `status ${e.status} (${e.message})`);
    assert.match(e.message, re);
    return true;
  });
}

// A PNG's width and height from its IHDR chunk.
function pngSize(base64) {
  const b = Buffer.from(base64, 'base64');
  assert.equal(b.subarray(1, 4).toString('latin1'), 'PNG', 'not a PNG');
  return [b.readUInt32BE(16), b.readUInt32BE(20)];
}

const withoutTimes = (levels) => levels.map((l) => {
  const { time_mean_s: _a, time_total_s: _b, efficiency: _c, time_std_s: _d, time_median_s: _e,
    time_median_ci95_s: _f, ...rest } = l;
  return rest;
});

test('the render module is built, loads, and agrees with the wrapper on the exported names', async () => {
  assert.ok(fs.existsSync(MJS), `missing ${MJS}: run \`make build-wasm\` or set MCPLAY_WASM_DIR`);
  const core = await getCore();
  assert.match(core.version(), /^\d+\.\d+\.\d+/);
  assert.deepEqual(exportList('render_exported_functions.txt').sort(), [...RENDER_WASM_FUNCTIONS].sort(),
    'src/wasm/render_exported_functions.txt and RENDER_WASM_FUNCTIONS in web/render_core.js differ');
  const runtime = new Set(exportList('exported_runtime_methods.txt'));
  for (const name of RENDER_WASM_RUNTIME_METHODS) assert.ok(runtime.has(name), name);
  // one error class for both cores: the page tells failures apart by status, not by module
  assert.equal(McplayError, CoreMcplayError);
  await assert.rejects(loadRenderCore(null), /default export of mcplay_render_web\.mjs/);
});

test('sceneInfo describes the inline glTF scene', async () => {
  const core = await getCore();
  const info = core.sceneInfo(SCENE);
  assert.equal(info.kind, 'render');
  assert.equal(info.name, 'tiny_quad_light');
  assert.equal(info.triangles, 4);
  assert.equal(info.lights, 2, 'the light quad is two emitting triangles');
  assert.deepEqual([info.width, info.height], [16, 16]);
  assert.deepEqual(info.estimators.map((e) => e.name), ESTIMATORS);
  for (const e of info.estimators) for (const k of ['strategy', 'light_selection', 'light_sampling', 'pixel_sampler']) assert.equal(typeof e[k], 'string');
  assert.equal(info.settings.n_name, 'spp');
  assert.equal(info.settings.error_name, 'relative_mse');
  assert.deepEqual([info.settings.n_min, info.settings.n_max, info.settings.reps], [1, 8, 3]);
  assert.deepEqual(info.warnings, []);
  // options override the scene's settings; the scene may also come as JSON text
  const small = core.sceneInfo(JSON.stringify(SCENE), { width: 32, spp_max: 64 });
  assert.deepEqual([small.width, small.settings.n_max], [32, 64]);
});

test('runStudy gives the documented result shape, streams every level, and previews as PNG', async () => {
  const core = await getCore();
  const seen = [];
  const r = core.runStudy(SCENE, { ...SMALL, previews: true }, (p) => { seen.push(p); });
  assert.equal(r.kind, 'render');
  assert.equal(r.cancelled, false);
  assert.equal(r.mcplay, core.version());
  for (const k of ['name', 'description', 'kind', 'width', 'height', 'triangles', 'lights', 'accel', 'warnings', 'reference', 'exact']) {
    assert.ok(k in r.scene, `scene.${k} missing`);
  }
  assert.deepEqual([r.scene.width, r.scene.height], [8, 8]);
  assert.equal(typeof r.scene.reference.spp, 'number');
  assert.ok(r.scene.reference.mean_luminance > 0);
  assert.equal(r.scene.exact, r.scene.reference.mean_luminance);
  assert.deepEqual(
    { n_min: r.settings.n_min, n_max: r.settings.n_max, reps: r.settings.reps, n_name: r.settings.n_name, error_name: r.settings.error_name },
    { n_min: 1, n_max: 4, reps: 2, n_name: 'spp', error_name: 'relative_mse' });
  assert.deepEqual(pngSize(r.reference_png), [8, 8]);
  assert.deepEqual(r.estimators.map((e) => e.name), ESTIMATORS);
  for (const e of r.estimators) {
    for (const k of ['strategy', 'light_selection', 'light_sampling', 'pixel_sampler']) assert.equal(typeof e[k], 'string', k);
    assert.ok(Array.isArray(e.warnings));
    assert.deepEqual(e.levels.map((l) => l.n), [1, 2, 4]);
    for (const l of e.levels) {
      assert.equal(l.reps, 2);
      assert.ok(l.variance > 0 && Number.isFinite(l.variance), `${e.name} spp ${l.n}: relative MSE ${l.variance}`);
      assert.equal(l.mse, l.variance, 'a render level\'s variance is its relative MSE');
      assert.ok(Math.abs(l.rmse - Math.sqrt(l.mse)) <= 1e-12 * l.rmse);
      assert.ok(l.time_mean_s > 0);
      assert.ok(l.mean > 0, 'mean image luminance');
      assert.ok(Array.isArray(l.warnings));
      assert.ok(l.coverage95 === null || (l.coverage95 >= 0 && l.coverage95 <= 1));
    }
    assert.equal(typeof e.fit.order, 'number');
    assert.ok(e.rays_per_second > 0);
    assert.deepEqual(pngSize(e.preview_png), [8, 8]);
    assert.deepEqual(pngSize(e.error_png), [8, 8]);
  }
  // Light sampling on a diffuse floor under one quad light beats cosine-weighted directions.
  const last = (name) => r.estimators.find((e) => e.name === name).levels.at(-1).variance;
  assert.ok(last('light_area') < last('cosine_hemisphere'), `${last('light_area')} vs ${last('cosine_hemisphere')}`);

  assert.equal(seen.length, 3, 'one progress line per spp');
  seen.forEach((p, i) => {
    assert.equal(p.kind, 'render');
    assert.equal(p.level_index, i);
    assert.equal(p.n, 1 << i);
    assert.deepEqual(p.estimators.map((e) => e.name), ESTIMATORS);
    p.estimators.forEach((e, k) => {
      assert.deepEqual(withoutTimes([e.level]), withoutTimes([r.estimators[k].levels[i]]));
      assert.deepEqual(pngSize(e.preview_png), [8, 8]);
      assert.deepEqual(pngSize(e.error_png), [8, 8]);
    });
  });
  // No previews unless asked for.
  const plain = core.runStudy(SCENE, SMALL);
  assert.equal(plain.reference_png, undefined);
  assert.equal(plain.estimators[0].preview_png, undefined);
});

test('estimators have their own random streams: a study split over workers gives the same numbers', async () => {
  const core = await getCore();
  const all = core.runStudy(SCENE, SMALL);
  const parts = [['cosine_hemisphere', 'mis_power'], ['light_area']].map((estimators) => core.runStudy(SCENE, { ...SMALL, estimators }));
  for (const e of all.estimators) {
    const part = parts.flatMap((p) => p.estimators).find((x) => x.name === e.name);
    assert.deepEqual(withoutTimes(part.levels), withoutTimes(e.levels), e.name);
    assert.deepEqual(part.fit, e.fit, e.name);
  }
  // ... and the same reference in every part
  assert.equal(parts[0].scene.reference.mean_luminance, all.scene.reference.mean_luminance);
  assert.equal(parts[1].scene.exact, all.scene.exact);
});

test('one estimator split over workers by replicate: the parts merge to the whole study', async () => {
  const core = await getCore();
  const options = { ...SMALL, reps: 5, estimators: ['light_area'] };
  const whole = core.runStudy(SCENE, options);
  const parts = [0, 1].map((part) => core.runStudy(SCENE, { ...options, part, parts: 2 }));
  assert.deepEqual(parts.map((p) => p.part), [{ index: 0, of: 2 }, { index: 1, of: 2 }]);
  assert.deepEqual(parts[1].estimators[0].levels[0].images.map((i) => i.replicate), [1, 3]);
  const merged = core.mergeParts(parts);
  const e = merged.estimators[0];
  assert.deepEqual(withoutTimes(e.levels), withoutTimes(whole.estimators[0].levels));
  assert.deepEqual(e.fit, whole.estimators[0].fit);
  assert.deepEqual(e.warnings, whole.estimators[0].warnings);
  assert.equal(merged.part, undefined);
  assert.equal(merged.settings.threads, 2);
  assertMcplayError(() => core.mergeParts([parts[0]]), Status.ARGUMENT, /part\.of.*is 2, but 1 parts were given/);
  assertMcplayError(() => core.mergeParts([whole]), Status.ARGUMENT, /not a part of a split study/);
});

// The site's way to skip the reference: the native CLI renders it once (`mcplay reference`) from
// the very scene file the page loads, and the wasm study takes it as options.reference_data. The
// two builds must agree on the key (the glTF as JSON, the name, the size, the reference's
// settings), and the study's numbers must be those of a study that rendered it itself.
test('a reference rendered by the native CLI is taken by the wasm study; its progress otherwise', async () => {
  const core = await getCore();
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'mcplay-ref-'));
  try {
    const sceneFile = path.join(dir, 'scene.json');
    fs.writeFileSync(sceneFile, JSON.stringify({ ...SCENE, render: { ...SCENE.render, width: 8, height: 8 } }));
    execFileSync(NATIVE, ['reference', sceneFile, '--out', path.join(dir, 'r.mcref'), '--no-cache', '--quiet']);
    const referenceData = fs.readFileSync(path.join(dir, 'r.mcref')).toString('base64');
    const rows = [];
    const levels = [];
    const rendered = core.runStudy(SCENE, SMALL, (p) => { levels.push(p.kind); }, (p) => { rows.push(p); });
    assert.equal(rendered.scene.reference.source, 'rendered');
    assert.ok(rows.length >= 2, `reference progress lines: ${rows.length}`);
    for (const p of rows) {
      assert.equal(p.kind, 'render_reference');
      assert.equal(p.rows, 8);
      assert.ok(p.rows_done >= 1 && p.rows_done <= 8);
    }
    assert.deepEqual(levels, ['render', 'render', 'render'], 'levels only through onLevel');
    const rowsAgain = [];
    const supplied = core.runStudy(SCENE, { ...SMALL, reference_data: referenceData }, null, (p) => { rowsAgain.push(p); });
    assert.equal(supplied.scene.reference.source, 'supplied');
    assert.equal(rowsAgain.length, 0, 'no reference to render');
    // Native and wasm builds agree to rounding (libm, contraction), not bit for bit.
    const close = (a, b, what) => assert.ok(Math.abs(a - b) <= 1e-9 * Math.abs(b), `${what}: ${a} vs ${b}`);
    close(supplied.scene.reference.mean_luminance, rendered.scene.reference.mean_luminance, 'reference mean');
    supplied.estimators.forEach((e, k) => e.levels.forEach((l, i) => {
      const r = rendered.estimators[k].levels[i];
      assert.equal(l.mean, r.mean, `${e.name} spp ${l.n}: the same images`);
      close(l.variance, r.variance, `${e.name} spp ${l.n}: relative MSE`);
    }));
    // Another image size: not used, rendered, and said so.
    const other = core.runStudy(SCENE, { ...SMALL, width: 6, reference_data: referenceData });
    assert.equal(other.scene.reference.source, 'rendered');
    assert.match(other.scene.reference.supplied, /^not used/);
    // Returning true from onReference cancels before any level.
    assert.throws(() => core.runStudy(SCENE, SMALL, null, () => true),
      (e) => e instanceof McplayError && e.status === Status.CANCELLED);
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});

test('onLevel returning true cancels; an exception in it propagates and the core keeps working', async () => {
  const core = await getCore();
  let calls = 0;
  const r = core.runStudy(SCENE, SMALL, () => ++calls === 2);
  assert.equal(r.cancelled, true);
  for (const e of r.estimators) assert.deepEqual(e.levels.map((l) => l.n), [1, 2]);
  const boom = new Error('boom');
  assert.throws(() => core.runStudy(SCENE, SMALL, () => { throw boom; }), (e) => e === boom);
  let inner = null;
  core.runStudy(SCENE, SMALL, () => {
    try {
      core.runStudy(SCENE, SMALL);
    } catch (e) {
      inner = e;
    }
    return true;
  });
  assert.ok(inner instanceof McplayError && inner.status === Status.ARGUMENT, String(inner));
  assert.match(inner.message, /already running/);
  assert.equal(core.runStudy(SCENE, SMALL).cancelled, false);
});

test('renderImage: the image as PNG with diagnostics; error_png against the reference', async () => {
  const core = await getCore();
  const im = core.renderImage(SCENE, { estimator: 'light_area', spp: 4, outputs: ['png', 'error_png'] });
  assert.equal(im.kind, 'render_image');
  assert.equal(im.estimator.name, 'light_area');
  assert.equal(im.spp, 4);
  assert.deepEqual(pngSize(im.images.png), [16, 16]);
  assert.deepEqual(pngSize(im.images.error_png), [16, 16]);
  assert.ok(im.seconds > 0 && im.rays_per_second > 0);
  assert.equal(im.diagnostics.samples, 16 * 16 * 4);
  assert.ok(im.relative_mse > 0);
  // an estimator object that is not in the scene, and no outputs at all
  const other = core.renderImage(SCENE, { estimator: { name: 'x', strategy: 'bsdf' }, spp: 1, outputs: [] });
  assert.deepEqual(other.images, {});
});

test('errors come back as McplayError with the core\'s message', async () => {
  const core = await getCore();
  assertMcplayError(() => core.sceneInfo({ f: 'x' }), Status.SCENE, /not a render scene/);
  assertMcplayError(() => core.sceneInfo('{"render": '), Status.SCENE, /invalid JSON/);
  assertMcplayError(() => core.sceneInfo({ render: { width: 8 } }), Status.SCENE, /scene\.render\.gltf: missing/);
  assertMcplayError(() => core.runStudy({ render: { gltf: 'nowhere.gltf' } }), Status.SCENE, /scene\.render\.gltf: 'nowhere\.gltf' does not exist/);
  assertMcplayError(() => core.sceneInfo({ render: { gltf: { asset: {} } } }), Status.SCENE, /scene\.render\.gltf: /);
  // A bad value in the options is a bad argument (the scene itself is fine).
  assertMcplayError(() => core.runStudy(SCENE, { spp_max: 0 }), Status.ARGUMENT, /options\.spp_max/);
  assertMcplayError(() => core.runStudy(SCENE, { estimators: ['nope'] }), Status.ARGUMENT, /unknown estimator 'nope'/);
  assertMcplayError(() => core.runStudy(SCENE, { colour: 1 }), Status.ARGUMENT, /unknown field 'colour'|colour/);
  assertMcplayError(() => core.renderImage(SCENE, { spp: 0 }), Status.ARGUMENT, /options\.spp/);
  assertMcplayError(() => core.renderImage(SCENE, { outputs: ['gif'] }), Status.ARGUMENT, /unknown output "gif"/);
  assertMcplayError(() => core.runStudy(SCENE, '{"reps": '), Status.ARGUMENT, /^options: invalid JSON/);
  assertMcplayError(() => core.sceneInfo(7), Status.ARGUMENT, /scene: expected an object or JSON text/);
  assertMcplayError(() => core.runStudy(SCENE, SMALL, 'no'), Status.ARGUMENT, /onLevel/);
  // the core works after all of that
  assert.equal(core.sceneInfo(SCENE).triangles, 4);
});

test('repeated calls leak nothing and do not grow the wasm heap', async () => {
  const core = await getCore();
  const tiny = { ...SMALL, spp_max: 2, width: 4, height: 4, previews: true };
  const cycle = (i) => {
    switch (i % 5) {
      case 0: return core.runStudy(SCENE, tiny, () => {});
      case 1: return core.runStudy(SCENE, tiny, () => true); // cancelled
      case 2: try { core.runStudy(SCENE, tiny, () => { throw new Error('x'); }); } catch { } return null;
      case 3: try { core.sceneInfo({ render: { gltf: { asset: {} } } }); } catch { } return null;
      default: return core.renderImage(SCENE, { spp: 1, width: 4, height: 4, outputs: ['png', 'error_png'] });
    }
  };
  for (let i = 0; i < 10; i++) cycle(i); // warm up: buffers reach their size
  const before = core.heapStats();
  for (let i = 0; i < 60; i++) cycle(i);
  const after = core.heapStats();
  const grew = after.allocatedBytes - before.allocatedBytes;
  assert.ok(grew <= 256, `malloc'd bytes in use grew by ${grew} over 60 calls`);
  assert.equal(after.memoryBytes, before.memoryBytes, 'wasm memory grew');
});

test('a disposed render core refuses calls', async () => {
  const { default: create } = await import(pathToFileURL(MJS).href);
  const core = await loadRenderCore(create, { wasmBinary: fs.readFileSync(WASM) });
  assert.equal(core.sceneInfo(SCENE).kind, 'render');
  core.dispose();
  assertMcplayError(() => core.sceneInfo(SCENE), Status.ARGUMENT, /disposed/);
});

test('the site: render scenes get manifest entries and their glTF inline', () => {
  assert.equal(isRenderScene(SCENE), true);
  assert.equal(isRenderScene(JSON.stringify(SCENE)), true);
  for (const other of [{ f: 'x' }, '{"f": "x"}', '{"description": "\\"render\\""}', null, 'not json "render"', []]) {
    assert.equal(isRenderScene(other), false, JSON.stringify(other));
  }
  const file = path.join(ROOT, 'scenes', 'quad_light_floor.json');
  const scene = JSON.parse(fs.readFileSync(file, 'utf8'));
  const entry = manifestEntry('quad_light_floor.json', scene);
  assert.equal(entry.kind, 'render');
  assert.deepEqual(entry.estimators, scene.render.estimators.map((e) => (typeof e === 'string' ? e : e.name)));
  assert.deepEqual([entry.n_min, entry.n_max, entry.width, entry.height], [scene.render.spp_min, scene.render.spp_max, scene.render.width, scene.render.height]);
  assert.equal(manifestEntry('exp_1d.json', { f: 'exp(x)' }).kind, 'integral');
  const { scene: site } = siteScene(scene, path.dirname(file));
  assert.equal(typeof site.render.gltf, 'object');
  assert.equal(site.render.gltf.asset.version, '2.0');
  for (const b of site.render.gltf.buffers) assert.match(b.uri, /^data:/);
  assert.equal(scene.render.gltf, 'quad_light_floor.gltf', 'the input is not changed');
  assert.throws(() => inlineGltf(path.join(ROOT, 'scenes', 'no_such.gltf')), /missing scenes\/no_such\.gltf/);
});

test('a scene as the site serves it (glTF inline) gives the native CLI\'s numbers for the scene file', async () => {
  const core = await getCore();
  const file = path.join(ROOT, 'scenes', 'quad_light_floor.json');
  const { scene: site } = siteScene(JSON.parse(fs.readFileSync(file, 'utf8')), path.dirname(file));
  const wasm = core.runStudy(site, { spp_min: 1, spp_max: 4, reps: 2, width: 8, height: 8, estimators: ['light_area', 'bsdf'] });
  if (!fs.existsSync(NATIVE)) throw new Error(`native CLI not found: ${NATIVE}. Build it with \`make build\` or set MCPLAY_NATIVE`);
  const native = JSON.parse(execFileSync(NATIVE, ['run', 'scenes/quad_light_floor.json', '--estimators', 'light_area,bsdf',
    '--n-min', '1', '--n-max', '4', '--reps', '2', '--width', '8', '--height', '8', '--no-cache', '--format', 'json', '--quiet'],
  { cwd: ROOT, encoding: 'utf8', maxBuffer: 64 << 20 }));
  assert.equal(wasm.scene.triangles, native.scene.triangles);
  assert.equal(wasm.scene.lights, native.scene.lights);
  const close = (a, b) => Math.abs(a - b) <= 1e-9 * Math.max(Math.abs(a), Math.abs(b));
  assert.ok(close(wasm.scene.exact, native.scene.exact), `reference luminance ${wasm.scene.exact} vs ${native.scene.exact}`);
  wasm.estimators.forEach((we, k) => {
    const ne = native.estimators[k];
    assert.equal(we.name, ne.name);
    we.levels.forEach((wl, i) => {
      const nl = ne.levels[i];
      assert.equal(wl.n, nl.n);
      // the same code on both sides; only libm's last bits (sin, cos) may differ
      assert.ok(close(wl.variance, nl.variance), `${we.name} spp ${wl.n}: relative MSE ${wl.variance} vs native ${nl.variance}`);
      assert.ok(close(wl.mean, nl.mean), `${we.name} spp ${wl.n}: mean ${wl.mean} vs native ${nl.mean}`);
    });
  });
});

test('deep nesting, foreign paths and huge emission get errors and leave the module usable', async () => {
  const core = await getCore();
  const deep = JSON.parse(JSON.stringify(SCENE));
  deep.render.gltf.extras = JSON.parse('['.repeat(100) + ']'.repeat(100));
  assertMcplayError(() => core.sceneInfo(deep), Status.SCENE, /nested more than 64 levels deep/);
  const escape = JSON.parse(JSON.stringify(SCENE));
  escape.render.gltf.buffers[0].uri = '../../../../etc/passwd';
  assertMcplayError(() => core.sceneInfo(escape), Status.SCENE, /^scene\.render\.gltf: buffers\[0\]/);
  const bright = JSON.parse(JSON.stringify(SCENE));
  const light = bright.render.gltf.materials.find((m) => m.emissiveFactor && m.emissiveFactor.some((v) => v > 0));
  light.extensions = { KHR_materials_emissive_strength: { emissiveStrength: 1e308 } };
  light.emissiveFactor = [5, 5, 5];
  assertMcplayError(() => core.sceneInfo(bright), Status.SCENE, /overflows/);
  assert.equal(core.sceneInfo(SCENE).triangles, 4);
});

test('plan predicts a study from a pilot and validates like runStudy', async () => {
  const core = await getCore();
  const p = core.plan(SCENE, { ...SMALL, reference: { spp: 64 } });
  // spp 1, 2, 4 with 2 replicates for each of 3 estimators on 8 x 8 pixels, plus the reference.
  assert.equal(p.samples, 64 * (7 * 2 * 3 + 64));
  assert.deepEqual(p.estimators.map((e) => e.name), ESTIMATORS);
  assert.ok(p.predicted_seconds > 0);
  assert.equal(p.reference.source, 'rendered');
  assertMcplayError(() => core.plan(SCENE, { ...SMALL, reference: { spp: 8 } }), Status.SCENE, /reference\.spp: expected at least 4 x spp_max = 16/);
});

test('pixelPoints: one pixel\'s samples (a Sobol\' pixel stratified as a (0, 6, 2)-net), the CLI\'s points, the core\'s errors', async () => {
  const core = await getCore();
  const p = core.pixelPoints({ pixel_sampler: 'sobol', spp: 64, dim: 2, seed: 1 });
  assert.equal(p.pixel_sampler, 'sobol');
  assert.equal(p.n, 64);
  assert.equal(p.dim, 2);
  assert.equal(p.points.length, 64);
  // every elementary box of area 1/64 holds one point, e.g. the 8 x 8 grid and the 64 x 1 strips
  for (const [bx, by] of [[8, 8], [64, 1], [1, 64], [2, 32]]) {
    const cells = new Set(p.points.map(([x, y]) => `${Math.floor(x * bx)},${Math.floor(y * by)}`));
    assert.equal(cells.size, 64, `${bx} x ${by} boxes`);
  }
  assert.deepEqual(core.pixelPoints({ pixel_sampler: 'sobol', spp: 64, dim: 2, seed: 1 }).points, p.points, 'same request, same points');
  // the native CLI's points, bit for bit (its CSV prints 17 significant digits)
  if (fs.existsSync(NATIVE)) {
    const csv = execFileSync(NATIVE, ['points', 'pixel_sobol', '--n', '64', '--dim', '2', '--seed', '1'], { encoding: 'utf8' });
    const rows = csv.trim().split('\n').slice(1).map((l) => l.split(',').map(Number));
    assert.deepEqual(rows, p.points);
  }
  const s = core.pixelPoints({ pixel_sampler: 'stratified', spp: 48, dim: 4, seed: 2 });
  assert.equal(s.points.length, 48);
  for (const row of s.points) {
    assert.equal(row.length, 4);
    for (const v of row) assert.ok(v >= 0 && v < 1, String(v));
  }
  assertMcplayError(() => core.pixelPoints({ pixel_sampler: 'sobol', spp: 48 }), Status.ARGUMENT,
    /^request\.spp: the 'sobol' pixel sampler needs a power-of-two spp, got 48 \(the nearest are 32 and 64\)$/);
  assertMcplayError(() => core.pixelPoints({ pixel_sampler: 'independent', spp: 4, dim: 3 }), Status.ARGUMENT, /^request\.dim: expected 2, 4, 6 or 8/);
  assertMcplayError(() => core.pixelPoints({ pixel_sampler: 'blue' }), Status.ARGUMENT, /^request\.pixel_sampler: unknown pixel sampler 'blue'/);
});

// The live view (web/src/live/): an image split in row bands over sessions (the page's workers)
// merges into the image one session gives, float for float; the relative MSE of the merged bands
// (sum of their sums over the sum of their terms) is the one session's; a reference rendered by
// reference() with options.live and given to sessions (liveReference) is the one they measure with.
const { float32OfBase64 } = await import('../src/protocol.js');
const { splitRows, createCollector, relativeMse } = await import('../src/live/model.js');

test('live sessions: two bands merge into the one-session image exactly, pass after pass', async () => {
  const core = await getCore();
  const scene = siteScene(JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', 'quad_light_floor.json'), 'utf8')),
    path.join(ROOT, 'scenes')).scene;
  const info = core.sceneInfo(scene);
  const base = { estimators: ['bsdf', 'mis_power'], pixel_sampler: 'padded_sobol', long_side: 16, pixels: true, threads: 1,
    live_reference: 'available', seed: 7 };
  const whole = core.liveOpen(scene, base);
  assert.equal(whole.kind, 'render_live');
  assert.equal(Math.max(whole.width, whole.height), 16);
  assert.ok(info.live_size && info.live_size.width > 0, 'scene info gives the live size');
  const { width, height } = whole;
  const bands = splitRows(height, 2);
  assert.deepEqual(bands, [[0, height / 2], [height / 2, height]]);
  const parts = bands.map((rows) => core.liveOpen(scene, { ...base, rows }));
  parts.forEach((p, i) => assert.deepEqual(p.rows, bands[i]));
  // a reference at the live size, given to every session
  const ref = core.reference(scene, { live: true, long_side: 16 });
  assert.equal(ref.width, width);
  assert.equal(ref.height, height);
  const given = [whole, ...parts].map((s) => core.liveReference(s.session, { reference_data: ref.reference_data }));
  const refWhole = float32OfBase64(given[0].rgb_f32);
  assert.equal(refWhole.length, width * height * 3);
  const refMerged = new Float32Array(width * height * 3);
  given.slice(1).forEach((g, i) => refMerged.set(float32OfBase64(g.rgb_f32), bands[i][0] * width * 3));
  assert.deepEqual(refMerged, refWhole, 'the bands\' reference pixels are the whole reference\'s');
  const collector = createCollector({ width, height, bands, workers: 2 });
  for (const spp of [1, 2, 4, 8]) {
    for (let e = 0; e < 2; ++e) {
      const one = core.livePass(whole.session, { estimator: e, spp, pixels: true });
      assert.equal(one.spp, spp);
      const rgb = float32OfBase64(one.rgb_f32);
      assert.equal(rgb.length, width * height * 3);
      let level = null;
      parts.forEach((p, b) => {
        const pass = core.livePass(p.session, { estimator: e, spp, pixels: true });
        assert.ok(pass.error && pass.error.terms > 0, 'a band with a reference has error sums');
        level = collector.add(e, b, { ...pass, rgb: float32OfBase64(pass.rgb_f32) }) || level;
      });
      assert.ok(level, `estimator ${e} at ${spp} spp: every band in`);
      assert.deepEqual(level.rgb, rgb, `estimator ${e} at ${spp} spp: merged bands = one session, float for float`);
      const whole1 = relativeMse([one.error]);
      assert.ok(Math.abs(level.relmse - whole1) <= 1e-12 * whole1, `relMSE ${level.relmse} vs ${whole1}`);
    }
  }
  // the sampler that cannot extend is refused, saying why; an extreme size is one clear error
  assertMcplayError(() => core.liveOpen(scene, { ...base, pixel_sampler: 'stratified' }), Status.ARGUMENT, /stratified/);
  assertMcplayError(() => core.liveOpen(scene, { ...base, long_side: 100000 }), Status.ARGUMENT, /long_side/);
  // a camera 10:1 wide: beyond the live view's 8:1, said in one line (the scene info says why too)
  const wide = quadLightGltf();
  wide.cameras[0].perspective.aspectRatio = 10;
  const wideScene = { ...SCENE, render: { ...SCENE.render, gltf: wide } };
  assert.ok(core.sceneInfo(wideScene).live_size.error, 'the scene info says why there is no live size');
  assertMcplayError(() => core.liveOpen(wideScene, { ...base, long_side: 256 }), Status.SCENE, /^[^\n]*aspectRatio is 10, beyond the live view's 8:1[^\n]*$/);
  for (const s of [whole, ...parts]) core.liveClose(s.session);
  assert.throws(() => core.liveClose(whole.session), McplayError);
});
