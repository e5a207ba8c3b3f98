// Tests of web/src/scene_title.js: the readable title the page shows for a scene identifier
// (the identifier stays visible beside it, for the CLI).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { sceneTitle, sceneOptionLabel } from '../src/scene_title.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');

test('identifiers become titles: words, proper names, abbreviations, dimensions, numbers kept', () => {
  assert.equal(sceneTitle('stiff_peak_1e-8'), 'Stiff peak 1e-8');
  assert.equal(sceneTitle('genz_gaussian_32d'), 'Genz Gaussian 32D');
  assert.equal(sceneTitle('mis_ridge_and_spot_2d'), 'MIS ridge and spot 2D');
  assert.equal(sceneTitle('is_near_zero_pdf'), 'IS near zero pdf');
  assert.equal(sceneTitle('vegas_corner_peak'), 'VEGAS corner peak');
  assert.equal(sceneTitle('miser_discontinuous'), 'MISER discontinuous');
  assert.equal(sceneTitle('singular_power_0.3'), 'Singular power 0.3');
  assert.equal(sceneTitle('offset_1e8_sin'), 'Offset 1e8 sin');
  assert.equal(sceneTitle('hemisphere_cos2'), 'Hemisphere cos²');
  assert.equal(sceneTitle('veach_mis'), 'Veach MIS');
  assert.equal(sceneTitle('cornell_box'), 'Cornell box');
  assert.equal(sceneTitle('custom'), 'Custom');
  assert.equal(sceneTitle(''), '');
  assert.equal(sceneTitle(null), '');
});

test('every scene of scenes/ gets a title without an underscore, different from its identifier', () => {
  const names = fs.readdirSync(path.join(ROOT, 'scenes')).filter((f) => f.endsWith('.json'))
    .map((f) => JSON.parse(fs.readFileSync(path.join(ROOT, 'scenes', f), 'utf8')).name);
  assert.ok(names.length > 40);
  for (const name of names) {
    const t = sceneTitle(name);
    assert.doesNotMatch(t, /_/, name);
    assert.notEqual(t, name, name);
    assert.match(t, /^[A-Z0-9]/, name);
  }
});

test('the scene list labels: the title and the dimension or kind, the dimension said once', () => {
  assert.equal(sceneOptionLabel({ name: 'stiff_peak_1e-8', dimension: 1 }), 'Stiff peak 1e-8 (1D)');
  assert.equal(sceneOptionLabel({ name: 'genz_gaussian_32d', dimension: 32 }), 'Genz Gaussian 32D');
  assert.equal(sceneOptionLabel({ name: 'exp_1d', dimension: 1 }), 'Exp 1D');
  assert.equal(sceneOptionLabel({ name: 'cornell_box', kind: 'render' }), 'Cornell box (render)');
  assert.equal(sceneOptionLabel({ name: 'triangle_moment' }), 'Triangle moment (?D)');
});
