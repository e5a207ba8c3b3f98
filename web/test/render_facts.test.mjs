// renderFacts: the few words the page shows for a render estimator (its tooltip), from the
// fields of the study's result (docs/result-schema.md).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { renderFacts } from '../src/report.js';

test('a ris estimator says how many candidates it resamples; the others say nothing of them', () => {
  const ris = renderFacts({ strategy: 'ris', light_selection: 'uniform', light_sampling: 'area',
    pixel_sampler: 'stratified', candidates: 8 });
  assert.equal(ris, 'strategy ris, lights chosen by uniform, sampled by area, stratified pixel samples, ' +
    '8 candidates resampled');
  const light = renderFacts({ strategy: 'light_solid_angle', light_selection: 'power', light_sampling: 'solid_angle',
    pixel_sampler: 'stratified' });
  assert.doesNotMatch(light, /candidates/);
  assert.match(light, /sampled by solid angle/);
});

test('an adaptive estimator says its samples are spread over the pixels; a uniform one does not', () => {
  const adaptive = renderFacts({ strategy: 'mis_power', pixel_sampler: 'padded_sobol', pixel_allocation: 'adaptive' });
  assert.equal(adaptive, 'strategy mis_power, padded_sobol pixel samples, spread over the pixels by their neighbours\' error');
  assert.doesNotMatch(renderFacts({ strategy: 'mis_power', pixel_sampler: 'padded_sobol' }), /spread/);
});
