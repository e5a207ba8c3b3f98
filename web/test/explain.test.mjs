// Tests of web/src/explain.js: every method the core names gets a panel (its teaching text, or
// the generic one with its kind's summary), and the orders follow the dimension where they
// depend on it. The core's methods come from the wasm module's catalog and scene info, not from
// a list here: MCPLAY_WASM_DIR holds mcplay_web.mjs + mcplay_web.wasm (default build-wasm).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';

import { explainEstimator, EXPLAINED } from '../src/explain.js';
import { loadCore } from '../core.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WASM_DIR = path.resolve(ROOT, process.env.MCPLAY_WASM_DIR || 'build-wasm');

async function getCore() {
  const mjs = path.join(WASM_DIR, 'mcplay_web.mjs');
  const wasm = path.join(WASM_DIR, 'mcplay_web.wasm');
  for (const f of [mjs, wasm]) {
    if (!fs.existsSync(f)) {
      throw new Error(`wasm module not found: ${f}. Build it with \`make build-wasm\` or point ` +
        'MCPLAY_WASM_DIR at the directory holding mcplay_web.mjs/.wasm');
    }
  }
  const { default: createMcplay } = await import(pathToFileURL(mjs).href);
  return loadCore(createMcplay, { wasmBinary: fs.readFileSync(wasm) });
}

test('every teaching text has a formula, an order and what to look for', () => {
  for (const method of EXPLAINED) {
    const x = explainEstimator({ name: 'e', method, pdf: 'uniform' }, 2);
    assert.ok(x.title && x.formula && x.order && x.look, method);
    assert.match(x.formula, /I_N|map|bisect|VEGAS/, `${method}: ${x.formula}`);
  }
});

test('every preset of the core\'s catalog gets a panel: its teaching text or its kind\'s summary', async () => {
  const core = await getCore();
  const presets = core.catalog().estimators.filter((e) => !e.needs_pdf).map((e) => e.name);
  assert.ok(presets.length >= 10, `catalog presets: ${presets}`);
  const info = core.sceneInfo({ f: 'x', n_min: 1024, n_max: 65536, estimators: presets });
  assert.equal(info.estimator_details.length, presets.length);
  for (const detail of info.estimator_details) {
    const x = explainEstimator(detail, 1);
    assert.ok(x.title && x.formula && x.order && x.look, `${detail.name}: ${JSON.stringify(x)}`);
    if (!EXPLAINED.includes(detail.method)) {
      assert.equal(x.title, detail.method);
      assert.equal(x.look, detail.summary, detail.name);
    }
  }
});

test('stratified orders follow the dimension: N^-(1+2/d) smooth, N^-(1+1/d) across an edge', () => {
  assert.match(explainEstimator({ method: 'stratified' }, 1).order, /N\^−3 for smooth f, N\^−2 across/);
  assert.match(explainEstimator({ method: 'stratified' }, 2).order, /N\^−2 for smooth f, N\^−1\.5 across/);
  assert.match(explainEstimator({ method: 'stratified_importance' }, 4).order, /N\^−1\.5 for smooth f, N\^−1\.25 across/);
  assert.match(explainEstimator({ method: 'stratified' }, null).order, /1\+2\/d/);
});

test('an unknown method gets a generic text, not an exception', () => {
  const x = explainEstimator({ name: 'x', method: 'teleport', pdf: 'p' });
  assert.equal(x.title, 'teleport');
  assert.equal(x.density, 'p');
  assert.equal(explainEstimator(null).title, 'Estimator');
});

test('a method without a text here shows the summary the core gives its kind', () => {
  const x = explainEstimator({ name: 'a', method: 'tempered', summary: 'a new kind, in one line', pdf: 'uniform' }, 1);
  assert.equal(x.title, 'tempered');
  assert.equal(x.look, 'a new kind, in one line');
  assert.equal(x.order, 'depends on the integrand');
});
