// Tests of the sample view's randomized QMC cards (web/src/plot/sample_panels.js): one
// randomization of K is drawn (its points come first), and a Sobol' set's net cells; and,
// through the wasm core, that the first N/K points of a Sobol' run are one randomization:
// a (0, m, 2)-net, one point in each of the cells the card draws.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath, pathToFileURL } from 'node:url';
import { firstRandomizationSize, sobolNetCells } from '../src/plot/sample_panels.js';
import { loadCore } from '../core.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const WASM_DIR = path.resolve(ROOT, process.env.MCPLAY_WASM_DIR || 'build-wasm');

const pts = (n) => [Array.from({ length: n }, (_, i) => i / n), Array.from({ length: n }, () => 0.5)];

test('a set of K randomizations shows its first one; other sets show every point', () => {
  assert.equal(firstRandomizationSize({ u: pts(256), randomizations: 16, sampler: 'sobol' }), 16);
  assert.equal(firstRandomizationSize({ u: pts(1024), randomizations: 16, sampler: 'halton' }), 64);
  assert.equal(firstRandomizationSize({ u: pts(256), randomizations: 1, sampler: 'sobol' }), null, 'one sequence (sobol_walsh)');
  assert.equal(firstRandomizationSize({ u: pts(256), randomizations: 0, sampler: 'independent' }), null);
  assert.equal(firstRandomizationSize({ u: pts(256), sampler: 'stratified' }), null);
});

test('the net cells of a Sobol\' set: 2^m points in 2^⌊m/2⌋ × 2^⌈m/2⌉ cells, on the first two axes', () => {
  assert.deepEqual(sobolNetCells({ sampler: 'sobol' }, 16), [4, 4]);
  assert.deepEqual(sobolNetCells({ sampler: 'sobol' }, 64), [8, 8]);
  assert.deepEqual(sobolNetCells({ sampler: 'sobol' }, 32), [4, 8]);
  assert.equal(sobolNetCells({ sampler: 'sobol' }, 24), null, 'not a power of two');
  assert.equal(sobolNetCells({ sampler: 'halton' }, 16), null);
  assert.equal(sobolNetCells({ sampler: 'sobol' }, 16, [1, 2]), null, 'another pair of axes');
});

test('the core: the first N/K Sobol\' points are one randomization, a net with one point per cell', async () => {
  const { default: createMcplay } = await import(pathToFileURL(path.join(WASM_DIR, 'mcplay_web.mjs')).href);
  const core = await loadCore(createMcplay, { wasmBinary: fs.readFileSync(path.join(WASM_DIR, 'mcplay_web.wasm')) });
  const scene = fs.readFileSync(path.join(ROOT, 'scenes', 'sin_product_2d.json'), 'utf8');
  for (const n of [256, 1024]) {
    const dump = core.samples(scene, { estimators: ['sobol'], n, seed: 7 });
    const e = dump.estimators[0];
    const k = firstRandomizationSize(e);
    assert.equal(k, n / e.randomizations);
    const [cx, cy] = sobolNetCells(e, k);
    const count = new Map();
    for (let i = 0; i < k; ++i) {
      const cell = `${Math.floor(e.u[0][i] * cx)},${Math.floor(e.u[1][i] * cy)}`;
      count.set(cell, (count.get(cell) || 0) + 1);
    }
    assert.equal(count.size, cx * cy, `n = ${n}: ${count.size} of ${cx * cy} cells hold a point`);
  }
  // one sequence (sobol_walsh: linear scrambling and a digital shift): all its points are the net
  const walsh = core.samples(fs.readFileSync(path.join(ROOT, 'scenes', 'walsh_bound_oscillatory_3d.json'), 'utf8'),
    { estimators: ['sobol_walsh'], n: 256, seed: 2 }).estimators[0];
  assert.equal(firstRandomizationSize(walsh), null);
  const [wx, wy] = sobolNetCells(walsh, 256);
  const cells = new Set(walsh.u[0].map((x, i) => `${Math.floor(x * wx)},${Math.floor(walsh.u[1][i] * wy)}`));
  assert.equal(cells.size, wx * wy);
});
