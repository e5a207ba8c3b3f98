#!/usr/bin/env node
// Assembles the playground into a static directory:
//   node web/tools/build-site.mjs [OUT=build/site] [WASM_DIR=build-wasm]
// OUT/index.html, style.css, src/** (the page's modules), core.js, vendor/uPlot.esm.js +
// uPlot.min.css (+ its LICENSE) from web/node_modules/uplot/dist, mcplay_web.mjs + .wasm from
// WASM_DIR, scenes/*.json and scenes/manifest.json ([{file, name, description, dimension,
// estimators, n_min, n_max}] read from the scene files themselves; the page asks the core,
// core.sceneInfo, for the rest). OUT and WASM_DIR default to build/site and build-wasm in the
// repository. Fails with a message naming what is missing.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WEB = path.join(ROOT, 'web');
// Arguments are taken from the current directory, the defaults from the repository root.
const OUT = process.argv[2] ? path.resolve(process.argv[2]) : path.join(ROOT, 'build', 'site');
const WASM_DIR = process.argv[3] ? path.resolve(process.argv[3]) : path.join(ROOT, 'build-wasm');
const UPLOT = path.join(WEB, 'node_modules', 'uplot');

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

function manifestEntry(file, scene) {
  const estimators = Array.isArray(scene.estimators)
    ? scene.estimators.map((e) => (typeof e === 'string' ? e : e.name))
    : DEFAULT_ESTIMATORS;
  return {
    file,
    name: scene.name || path.basename(file, '.json'),
    description: scene.description || '',
    dimension: sceneDimension(scene),
    estimators,
    n_min: scene.n_min ?? 16,
    n_max: scene.n_max ?? 65536,
  };
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

function main() {
  const wasmFiles = ['mcplay_web.mjs', 'mcplay_web.wasm'].map((f) =>
    need(path.join(WASM_DIR, f), `build the wasm module with \`make build-wasm\` (or pass its directory as the second argument)`));
  const uplotFiles = ['uPlot.esm.js', 'uPlot.min.css'].map((f) =>
    need(path.join(UPLOT, 'dist', f), 'install uPlot with `npm ci --prefix web` (web/package-lock.json)'));
  for (const f of ['index.html', 'style.css', 'core.js', 'src']) need(path.join(WEB, f), 'part of the repository');
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

  for (const f of ['index.html', 'style.css', 'core.js']) copy(path.join(WEB, f), path.join(OUT, f));
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
    copy(path.join(scenesDir, file), path.join(OUT, 'scenes', file));
  }
  const names = new Set();
  for (const m of manifest) {
    if (names.has(m.name)) fail(`two scenes are named '${m.name}'`);
    names.add(m.name);
  }
  fs.writeFileSync(path.join(OUT, 'scenes', 'manifest.json'), `${JSON.stringify(manifest, null, 2)}\n`);
  console.log(`build-site: ${shown(OUT)} (${manifest.length} scenes, wasm from ${shown(WASM_DIR)})`);
}

if (process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url)) main();
