#!/usr/bin/env node
// Assembles the playground into a static directory:
//   node web/tools/build-site.mjs [OUT=build/site] [WASM_DIR=build-wasm] [NATIVE=build/mcplay]
// OUT/index.html, style.css, src/** (the page's modules), core.js, render_core.js,
// vendor/uPlot.esm.js + uPlot.min.css (+ its LICENSE) from web/node_modules/uplot/dist,
// mcplay_web.mjs + .wasm and mcplay_render_web.mjs + .wasm from WASM_DIR, scenes/*.json and
// scenes/manifest.json ([{file, name, description, kind, dimension, estimators, n_min, n_max,
// group, look, select?}], warp scenes also {warp: true} (kind 'warp' without an integrand; they need no
// stop of the tour and come last unless it names them), render scenes also {reps, width, height, reference, live_reference}; read from the scene files themselves;
// the page asks the core, sceneInfo, for the rest), in the order of the teaching path
// web/tour.json, which gives each scene its group and what to look for. Its first scene is an
// integral (the page opens it, and only render scenes load the render module).
// Render scenes (a "render" object) are copied with their "gltf" replaced by the glTF itself,
// inline, its external buffers and images turned into data: URIs (a .glb becomes the same
// JSON with its binary chunk as buffer 0), since the wasm module cannot read the site's files,
// and their reference images are rendered here by the native CLI into refs/<name>.mcref (the
// page never renders a bundled scene's reference; see shipReference), and the live view's at its
// default size into refs/<name>.live.mcref (manifest live_reference; shipLiveReference).
// OUT and WASM_DIR default to build/site and build-wasm in the repository. Fails with a message
// naming what is missing.
//   node web/tools/build-site.mjs --references [NATIVE=build/mcplay]
// renders only the references, into the cache build/ref-cache that the site's build reads: the
// native build runs it (CMake target site_references) once the CLI is linked, while the rest of
// the two builds goes on, so that the site waits for no reference.
import fs from 'node:fs';
import path from 'node:path';
import { spawnSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WEB = path.join(ROOT, 'web');
// Arguments are taken from the current directory, the defaults from the repository root.
const REFERENCES_ONLY = process.argv[2] === '--references';
const ARGS = REFERENCES_ONLY ? [undefined, undefined, process.argv[3]] : process.argv.slice(2);
const OUT = ARGS[0] ? path.resolve(ARGS[0]) : path.join(ROOT, 'build', 'site');
const WASM_DIR = ARGS[1] ? path.resolve(ARGS[1]) : path.join(ROOT, 'build-wasm');
const UPLOT = path.join(WEB, 'node_modules', 'uplot');
const NATIVE = ARGS[2] ? path.resolve(ARGS[2]) : path.join(ROOT, 'build', 'mcplay');
const REF_CACHE = path.join(ROOT, 'build', 'ref-cache');

function fail(message) {
  console.error(`build-site: ${message}`);
  process.exit(1);
}

function shown(file) {
  const rel = path.relative(ROOT, file);
  return rel && !rel.startsWith('..') ? rel : file;
}

function need(file, how) {
  if (!fs.existsSync(file)) fail(`missing ${shown(file)}: ${how}`);
  return file;
}


// The dimension a scene's points have, read from its JSON the way docs/scene-format.md
// defines the defaults (null when only the core can tell).
const FIXED_DIMENSION = { interval: 1, disk: 2, triangle: 2, sphere: 3, hemisphere: 3 };
function expressionDimension(text) {
  if (typeof text !== 'string') return null;
  let d = 0;
  for (const m of text.matchAll(/\b(x(\d+)|x|y|z)\b/g)) {
    d = Math.max(d, m[2] ? Number(m[2]) : { x: 1, y: 2, z: 3 }[m[1]]);
  }
  return d || 1;
}
export function sceneDimension(scene) {
  const dom = scene.domain;
  if (dom && typeof dom === 'object') {
    if (FIXED_DIMENSION[dom.type]) return FIXED_DIMENSION[dom.type];
    if (dom.type === 'box') {
      if (Array.isArray(dom.lower)) return dom.lower.length;
      if (Number.isInteger(dom.dim)) return dom.dim;
    }
  }
  const f = scene.f ?? scene.integrand;
  if (typeof f === 'string') return expressionDimension(f);
  if (f && typeof f === 'object') {
    if (f.type === 'expression') return expressionDimension(f.f);
    if (Number.isInteger(f.dim)) return f.dim;
    for (const k of ['powers', 'rates', 'center', 'a', 'u']) if (Array.isArray(f[k])) return f[k].length;
  }
  return null;
}

const DEFAULT_ESTIMATORS = ['uniform', 'stratified', 'latin_hypercube'];
// The render C API's defaults (src/render_api/render_request.cpp, src/render/render_study.h):
// every direct-lighting strategy, 64 x 64 pixels, spp 1..64, 4 replicates.
const DEFAULT_RENDER_ESTIMATORS = ['uniform_hemisphere', 'cosine_hemisphere', 'bsdf', 'light_area',
  'light_solid_angle', 'mis_balance', 'mis_power'];
const RENDER_DEFAULTS = { width: 64, height: 64, spp_min: 1, spp_max: 64, reps: 4 };

/** Does a scene JSON describe a render scene (a "render" object), as the C API decides. */
export function isRenderScene(scene) {
  return Boolean(scene) && typeof scene === 'object' && !Array.isArray(scene) && 'render' in scene;
}

/** Does a scene carry a warp to test (a top-level "warp": a name or an object)? */
export function isWarpScene(scene) {
  return Boolean(scene) && typeof scene === 'object' && !Array.isArray(scene) && 'warp' in scene;
}

// An estimator of a scene's list: a preset name, or an object with a name (render estimators
// default their name to their strategy).
function estimatorName(e) {
  if (typeof e === 'string') return e;
  return e && (e.name ?? e.strategy);
}

/**
 * The manifest in the order of the teaching path (web/tour.json): each entry gets its group's
 * title (`group`), what to look for in it (`look`) and, when the stop names them, the estimators
 * the page starts with selected (`select`). Throws, naming them, when a scene is in
 * no group, in two, or when the tour names a scene that does not exist: the path and the folder
 * must agree.
 */
export function orderByTour(manifest, tour) {
  // Warp scenes (a top-level "warp": the sampler lab's examples) need no stop of the tour:
  // those it does not name come last, in file order.
  const inTour = new Set(((tour && tour.groups) || []).flatMap((g) => (g.scenes || []).map((s) => s.name)));
  const labOnly = manifest.filter((m) => m.warp && !inTour.has(m.name));
  manifest = manifest.filter((m) => !labOnly.includes(m));
  const byName = new Map(manifest.map((m) => [m.name, m]));
  const seen = new Set();
  const out = [];
  const problems = [];
  for (const group of (tour && tour.groups) || []) {
    for (const stop of group.scenes || []) {
      const m = byName.get(stop.name);
      if (!m) problems.push(`the tour names '${stop.name}', which is not a scene`);
      else if (seen.has(stop.name)) problems.push(`the tour names '${stop.name}' twice`);
      else {
        seen.add(stop.name);
        // "select": the estimators the page starts with selected (a QMC stop selects its
        // Sobol', Halton and lattice points, which the scene itself does not list)
        if (stop.select !== undefined && !(Array.isArray(stop.select) && stop.select.length
          && stop.select.every((n) => typeof n === 'string' && n))) {
          problems.push(`the tour's '${stop.name}': select must be a list of estimator names`);
        }
        out.push({ ...m, group: group.title, look: stop.look || '', ...(Array.isArray(stop.select) ? { select: stop.select.slice() } : {}) });
      }
    }
  }
  const missing = manifest.filter((m) => !seen.has(m.name)).map((m) => m.name);
  if (missing.length) problems.push(`scenes in no group of the tour: ${missing.join(', ')}`);
  if (problems.length) throw new Error(problems.join('; '));
  return [...out, ...labOnly];
}

export function manifestEntry(file, scene) {
  const name = scene.name || path.basename(file, '.json');
  const description = scene.description || '';
  if (isRenderScene(scene)) {
    const r = scene.render && typeof scene.render === 'object' ? scene.render : {};
    const v = (k) => (Number.isSafeInteger(r[k]) ? r[k] : RENDER_DEFAULTS[k]);
    return {
      file, name, description, kind: 'render', dimension: null,
      estimators: Array.isArray(r.estimators) ? r.estimators.map(estimatorName) : DEFAULT_RENDER_ESTIMATORS,
      n_min: v('spp_min'), n_max: v('spp_max'), reps: v('reps'), width: v('width'), height: v('height'),
    };
  }
  const estimators = Array.isArray(scene.estimators) ? scene.estimators.map(estimatorName) : DEFAULT_ESTIMATORS;
  if (isWarpScene(scene)) {
    // A warp for the sampler lab; with an integrand also a study (the warp as the estimator "warp").
    const integral = scene.f !== undefined || scene.integrand !== undefined;
    return {
      file, name, description, kind: integral ? 'integral' : 'warp', warp: true,
      dimension: integral ? sceneDimension(scene) : null,
      estimators: integral ? estimators : [],
      n_min: scene.n_min ?? 16,
      n_max: scene.n_max ?? 65536,
    };
  }
  return {
    file,
    name,
    description,
    kind: 'integral',
    dimension: sceneDimension(scene),
    estimators,
    n_min: scene.n_min ?? 16,
    n_max: scene.n_max ?? 65536,
  };
}

const IMAGE_TYPES = { '.png': 'image/png', '.jpg': 'image/jpeg', '.jpeg': 'image/jpeg', '.webp': 'image/webp' };

function dataUri(file, type) {
  return `data:${type};base64,${fs.readFileSync(file).toString('base64')}`;
}

// The glTF JSON of a .glb: its JSON chunk, with the BIN chunk as buffer 0's data URI.
function glbToJson(bytes, where) {
  const u32 = (o) => bytes.readUInt32LE(o);
  if (bytes.length < 20 || u32(0) !== 0x46546c67) throw new Error(`${where}: not a binary glTF (no "glTF" magic)`);
  const jsonLength = u32(12);
  if (u32(16) !== 0x4e4f534a || 20 + jsonLength > bytes.length) throw new Error(`${where}: the first chunk is not JSON`);
  const gltf = JSON.parse(bytes.subarray(20, 20 + jsonLength).toString('utf8'));
  const binAt = 20 + jsonLength;
  if (binAt + 8 <= bytes.length && u32(binAt + 4) === 0x004e4942 && Array.isArray(gltf.buffers) && gltf.buffers[0]
      && gltf.buffers[0].uri === undefined) {
    const bin = bytes.subarray(binAt + 8, binAt + 8 + u32(binAt));
    gltf.buffers[0].uri = `data:application/octet-stream;base64,${bin.toString('base64')}`;
  }
  return gltf;
}

/**
 * The glTF file `gltfPath` as one JSON object with every external buffer and image inlined
 * as a data: URI (files resolved relative to the glTF's folder). Throws naming what is missing.
 */
export function inlineGltf(gltfPath) {
  if (!fs.existsSync(gltfPath)) throw new Error(`missing ${shown(gltfPath)}`);
  const bytes = fs.readFileSync(gltfPath);
  let gltf;
  try {
    gltf = path.extname(gltfPath).toLowerCase() === '.glb' ? glbToJson(bytes, shown(gltfPath)) : JSON.parse(bytes.toString('utf8'));
  } catch (e) {
    throw new Error(`${shown(gltfPath)}: ${e.message}`);
  }
  const dir = path.dirname(gltfPath);
  const inline = (list, typeOf) => {
    for (const item of Array.isArray(list) ? list : []) {
      if (!item || typeof item.uri !== 'string' || item.uri.startsWith('data:')) continue;
      let rel;
      try {
        rel = decodeURIComponent(item.uri);
      } catch {
        rel = item.uri;
      }
      const file = path.resolve(dir, rel);
      if (!fs.existsSync(file)) throw new Error(`${shown(gltfPath)}: missing ${shown(file)} (uri '${item.uri}')`);
      item.uri = dataUri(file, typeOf(file));
    }
  };
  inline(gltf.buffers, () => 'application/octet-stream');
  inline(gltf.images, (f) => IMAGE_TYPES[path.extname(f).toLowerCase()] || 'application/octet-stream');
  return gltf;
}

/**
 * The scene as the site serves it: a render scene's "gltf" file name replaced by the glTF
 * object (inlineGltf), and a reference image file dropped (the wasm module reads no files: the
 * site ships a rendered reference instead, shipReference). Returns {scene, notes}.
 */
export function siteScene(scene, sceneDir) {
  if (!isRenderScene(scene) || !scene.render || typeof scene.render !== 'object') return { scene, notes: [] };
  const notes = [];
  const render = { ...scene.render };
  if (typeof render.gltf === 'string') render.gltf = inlineGltf(path.resolve(sceneDir, render.gltf));
  if (render.reference && typeof render.reference === 'object' && 'file' in render.reference) {
    render.reference = { ...render.reference };
    delete render.reference.file;
    notes.push('reference.file dropped: the site ships a rendered reference instead');
  }
  return { scene: { ...scene, render }, notes };
}

function copy(from, to) {
  fs.mkdirSync(path.dirname(to), { recursive: true });
  fs.copyFileSync(from, to);
}

function copyTree(from, to) {
  for (const ent of fs.readdirSync(from, { withFileTypes: true })) {
    const a = path.join(from, ent.name);
    const b = path.join(to, ent.name);
    if (ent.isDirectory()) copyTree(a, b);
    else if (ent.isFile()) copy(a, b);
  }
}

/**
 * The reference of a site's render scene, rendered once here by the native CLI from the very
 * scene file the page loads (`mcplay reference`; the result is keyed by the glTF, the name,
 * the size and the reference's settings, so the page's study uses it only for exactly these),
 * written to OUT/refs/<name>.mcref. References already rendered are kept in build/ref-cache.
 * Returns the path the manifest gives the page.
 */
function shipReference(sceneFile, name, outRoot = OUT) {
  const rel = `refs/${name.replace(/[^A-Za-z0-9_.-]/g, '_')}.mcref`;
  const out = path.join(outRoot, rel);
  fs.mkdirSync(path.dirname(out), { recursive: true });
  const run = spawnSync(NATIVE, ['reference', sceneFile, '--out', out, '--cache', REF_CACHE, '--quiet'],
    { encoding: 'utf8' });
  if (run.status !== 0) fail(`${shown(sceneFile)}: the reference could not be rendered: ${(run.stderr || run.error || '').toString().trim()}`);
  console.log(`build-site: ${run.stdout.trim()}`);
  return rel;
}

/**
 * The reference of the live view at its default size (`mcplay reference --live`: the long side
 * and spp the live view uses), written to OUT/refs/<name>.live.mcref; the page gives it to every
 * session of a bundled scene at the default size (options.reference_data), so that its curves
 * start with the first pass. Returns the path the manifest gives the page (entry.live_reference).
 */
function shipLiveReference(sceneFile, name, outRoot = OUT) {
  const rel = `refs/${name.replace(/[^A-Za-z0-9_.-]/g, '_')}.live.mcref`;
  const out = path.join(outRoot, rel);
  fs.mkdirSync(path.dirname(out), { recursive: true });
  const run = spawnSync(NATIVE, ['reference', sceneFile, '--live', '--out', out, '--cache', REF_CACHE, '--quiet'],
    { encoding: 'utf8' });
  if (run.status !== 0) fail(`${shown(sceneFile)}: the live view's reference could not be rendered: ${(run.stderr || run.error || '').toString().trim()}`);
  console.log(`build-site: ${run.stdout.trim()} (live view)`);
  return rel;
}

/**
 * Every render scene's two references rendered into REF_CACHE, from the very scene text the
 * site ships (siteScene, written to a scratch folder), so that main() later finds them all
 * there. The scene's name is the one main() gives it (manifestEntry).
 */
function renderReferencesOnly() {
  need(NATIVE, 'build the native CLI first: it renders the render scenes\' references');
  fs.mkdirSync(REF_CACHE, { recursive: true });
  const scratch = fs.mkdtempSync(path.join(REF_CACHE, 'scenes-'));
  try {
    const scenesDir = path.join(ROOT, 'scenes');
    for (const file of fs.readdirSync(scenesDir).filter((f) => f.endsWith('.json') && f !== 'manifest.json').sort()) {
      let scene;
      try {
        scene = JSON.parse(fs.readFileSync(path.join(scenesDir, file), 'utf8'));
      } catch (e) {
        fail(`scenes/${file}: invalid JSON (${e.message})`);
      }
      if (!isRenderScene(scene)) continue;
      let site;
      try {
        site = siteScene(scene, scenesDir);
      } catch (e) {
        fail(`scenes/${file}: render.gltf: ${e.message}`);
      }
      const sceneFile = path.join(scratch, file);
      fs.writeFileSync(sceneFile, `${JSON.stringify(site.scene)}\n`);
      const { name } = manifestEntry(file, scene);
      shipReference(sceneFile, name, scratch);
      shipLiveReference(sceneFile, name, scratch);
    }
  } finally {
    fs.rmSync(scratch, { recursive: true, force: true });
  }
}

function main() {
  if (REFERENCES_ONLY) {
    renderReferencesOnly();
    return;
  }
  need(NATIVE, 'build the native CLI with `make build` (or pass its path as the third argument): it renders the render scenes\' references');
  fs.mkdirSync(REF_CACHE, { recursive: true });
  const wasmFiles = ['mcplay_web.mjs', 'mcplay_web.wasm', 'mcplay_render_web.mjs', 'mcplay_render_web.wasm'].map((f) =>
    need(path.join(WASM_DIR, f), `build the wasm module with \`make build-wasm\` (or pass its directory as the second argument)`));
  const uplotFiles = ['uPlot.esm.js', 'uPlot.min.css'].map((f) =>
    need(path.join(UPLOT, 'dist', f), 'install uPlot with `npm ci --prefix web` (web/package-lock.json)'));
  for (const f of ['index.html', 'style.css', 'core.js', 'render_core.js', 'src']) need(path.join(WEB, f), 'part of the repository');
  // OUT is replaced whole: only when it is empty or a site this script built.
  if (OUT === path.parse(OUT).root || ROOT === OUT || ROOT.startsWith(OUT + path.sep) ||
      [WEB, path.join(ROOT, 'scenes'), WASM_DIR].includes(OUT)) {
    fail(`refusing to write into ${OUT}`);
  }
  if (fs.existsSync(OUT) && fs.readdirSync(OUT).length &&
      !(fs.existsSync(path.join(OUT, 'index.html')) && fs.existsSync(path.join(OUT, 'scenes', 'manifest.json')))) {
    fail(`${OUT} exists and is not a site built by this script: remove it or choose another directory`);
  }
  fs.rmSync(OUT, { recursive: true, force: true });
  fs.mkdirSync(OUT, { recursive: true });

  for (const f of ['index.html', 'style.css', 'core.js', 'render_core.js']) copy(path.join(WEB, f), path.join(OUT, f));
  copyTree(path.join(WEB, 'src'), path.join(OUT, 'src'));
  for (const f of uplotFiles) copy(f, path.join(OUT, 'vendor', path.basename(f)));
  if (fs.existsSync(path.join(UPLOT, 'LICENSE'))) copy(path.join(UPLOT, 'LICENSE'), path.join(OUT, 'vendor', 'uPlot.LICENSE'));
  for (const f of wasmFiles) copy(f, path.join(OUT, path.basename(f)));

  const scenesDir = path.join(ROOT, 'scenes');
  const files = fs.readdirSync(scenesDir).filter((f) => f.endsWith('.json') && f !== 'manifest.json').sort();
  if (!files.length) fail('scenes/ holds no *.json scene');
  const manifest = [];
  for (const file of files) {
    const text = fs.readFileSync(path.join(scenesDir, file), 'utf8');
    let scene;
    try {
      scene = JSON.parse(text);
    } catch (e) {
      fail(`scenes/${file}: invalid JSON (${e.message})`);
    }
    manifest.push(manifestEntry(file, scene));
    if (isRenderScene(scene)) {
      let site;
      try {
        site = siteScene(scene, scenesDir);
      } catch (e) {
        fail(`scenes/${file}: render.gltf: ${e.message}`);
      }
      for (const note of site.notes) console.log(`build-site: scenes/${file}: ${note}`);
      fs.mkdirSync(path.join(OUT, 'scenes'), { recursive: true });
      fs.writeFileSync(path.join(OUT, 'scenes', file), `${JSON.stringify(site.scene)}\n`);
      const entry = manifest[manifest.length - 1];
      entry.reference = shipReference(path.join(OUT, 'scenes', file), entry.name);
      entry.live_reference = shipLiveReference(path.join(OUT, 'scenes', file), entry.name);
    } else {
      copy(path.join(scenesDir, file), path.join(OUT, 'scenes', file));
    }
  }
  // The teaching path's order (web/tour.json); the page opens the first scene, an integral.
  let ordered;
  try {
    ordered = orderByTour(manifest, JSON.parse(fs.readFileSync(need(path.join(WEB, 'tour.json'), 'part of the repository'), 'utf8')));
  } catch (e) {
    fail(`web/tour.json: ${e.message}`);
  }
  manifest.splice(0, manifest.length, ...ordered);
  if (manifest[0].kind === 'render') fail('web/tour.json: the first scene must be an integral (the page opens it)');
  const names = new Set();
  for (const m of manifest) {
    if (names.has(m.name)) fail(`two scenes are named '${m.name}'`);
    names.add(m.name);
  }
  fs.writeFileSync(path.join(OUT, 'scenes', 'manifest.json'), `${JSON.stringify(manifest, null, 2)}\n`);
  const renders = manifest.filter((m) => m.kind === 'render').length;
  console.log(`build-site: ${shown(OUT)} (${manifest.length - renders} integration and ${renders} render scenes, wasm from ${shown(WASM_DIR)})`);
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) main();
