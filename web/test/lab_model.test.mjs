// Tests of the sampler lab's pure state (web/src/lab/model.js): the reducer, the URL round
// trip, the requests built from the inputs and from a chosen file, and the words shown.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import {
  initialLab, labReducer, labToQuery, queryToLab, typedWarpScene, typedDomain, fileRequest, pointSource, analyzeRequest,
  samplerRequest, curveRequest, verdictText, warpFacts, measureRows, integrateText, skippedLines, displayRows,
  problemChoices, hasIntegrand, labSnapshot, opensOnExample, TYPED, BUILTIN_WARPS,
} from '../src/lab/model.js';

const act = (state, type, payload = {}) => labReducer(state, { type, payload });

test('the URL round trip keeps the lab\'s inputs, and the study\'s URL is untouched while it is shown', () => {
  let s = initialLab();
  assert.equal(labToQuery(s), '', 'the study is shown: no lab keys');
  s = act(s, 'lab/view', { view: 'lab' });
  s = act(s, 'lab/warp/edit', { field: 'example', value: TYPED });
  s = act(s, 'lab/warp/edit', { field: 'g1', value: 'u1*cos(2*pi*u2)' });
  s = act(s, 'lab/warp/edit', { field: 'p', value: '1/pi' });
  s = act(s, 'lab/warp/edit', { field: 'samples', value: '10000' });
  s = act(s, 'lab/warp/edit', { field: 'seed', value: '7' });
  const q = labToQuery(s);
  assert.match(q, /^\?view=lab&lab=warp&warp=typed/);
  const back = queryToLab(q);
  assert.equal(back.view, 'lab');
  assert.equal(back.tab, 'warp');
  assert.equal(back.warp.example, TYPED);
  assert.deepEqual(back.warp.typed, s.warp.typed);
  assert.equal(back.warp.samples, 10000);
  assert.equal(back.warp.seed, '7');
  assert.equal(labToQuery(back), q);

  let p = act(initialLab(), 'lab/view', { view: 'lab' });
  p = act(p, 'lab/tab', { tab: 'points' });
  for (const [field, value] of [['sampler', 'halton'], ['randomization', 'none'], ['n', '512'], ['dim', '3'], ['seed', '4'], ['sets', '8'], ['problem', 'sin_product_2d']]) {
    p = act(p, 'lab/points/edit', { field, value });
  }
  p = act(p, 'lab/points/edit', { field: 'axes', value: [0, 2] });
  p = act(p, 'lab/curve/edit', { field: 'sampler', value: 'lattice', checked: true });
  p = act(p, 'lab/curve/edit', { field: 'sampler', value: 'uniform', checked: false });
  p = act(p, 'lab/curve/edit', { field: 'n_max', value: '1024' });
  const q2 = labToQuery(p);
  const back2 = queryToLab(q2);
  assert.deepEqual({ ...back2.points, integrate: null }, { ...p.points, integrate: null });
  assert.deepEqual(back2.curve, p.curve);
  assert.equal(labToQuery(back2), q2);
});

test('queryToLab: malformed values keep their defaults; a query without view=lab is the study\'s', () => {
  const d = initialLab();
  assert.deepEqual(queryToLab('?scene=exp_1d&n_min=16'), d);
  const s = queryToLab('?view=lab&lab=nope&samples=12&n=0&dim=99&sampler=magic&axes=1,1&cn=64,16&creps=100&domain=cube&warp=a%20b');
  assert.equal(s.view, 'lab');
  assert.equal(s.tab, 'warp');
  assert.equal(s.warp.samples, d.warp.samples);
  assert.equal(s.points.n, d.points.n);
  assert.equal(s.points.dim, d.points.dim);
  assert.equal(s.points.sampler, d.points.sampler);
  assert.deepEqual(s.points.axes, d.points.axes);
  assert.equal(s.curve.n_min, d.curve.n_min);
  assert.equal(s.curve.reps, d.curve.reps);
  assert.equal(s.warp.typed.domain, d.warp.typed.domain);
  assert.equal(s.warp.example, d.warp.example);
});

test('the reducer drops answers of requests that were replaced', () => {
  let s = act(initialLab(), 'lab/warp/start', { id: 1 });
  s = act(s, 'lab/warp/start', { id: 2 });
  s = act(s, 'lab/warp/done', { id: 1, result: { passed: false } });
  assert.equal(s.warp.status, 'running');
  s = act(s, 'lab/warp/done', { id: 2, result: { passed: true } });
  assert.equal(s.warp.status, 'done');
  assert.deepEqual(s.warp.result, { passed: true });
  s = act(s, 'lab/points/file', { name: 'bad.csv', error: 'row 12, column 2: \'1.2\' is outside [0, 1)' });
  assert.equal(s.points.status, 'error');
  assert.equal(s.points.source, 'file');
  assert.match(s.points.message, /row 12/);
});

test('the manifest\'s warp scenes replace the built-in examples; the example shown stays valid', () => {
  let s = initialLab();
  assert.deepEqual(s.examples.map((e) => e.name), BUILTIN_WARPS.map((w) => w.name));
  s = act(s, 'lab/examples', { entries: [{ name: 'warp_disk_polar', file: 'warp_disk_polar.json', hasIntegrand: true }] });
  assert.deepEqual(s.examples.map((e) => e.name), ['warp_disk_polar']);
  assert.equal(s.warp.example, 'warp_disk_polar');
  assert.equal(s.examples[0].hasIntegrand, true);
  s = act(initialLab(), 'lab/warp/edit', { field: 'example', value: TYPED });
  s = act(s, 'lab/examples', { entries: [{ name: 'warp_x' }] });
  assert.equal(s.warp.example, TYPED);
  assert.deepEqual(act(initialLab(), 'lab/examples', { entries: [] }).examples, initialLab().examples);
});

test('every example carries its "what to look for": the built-in ones their own, the manifest\'s the tour\'s', () => {
  for (const e of initialLab().examples) assert.ok(e.look && e.look.length > 20, e.name);
  const s = act(initialLab(), 'lab/examples', { entries: [{ name: 'warp_a', look: 'red residuals near the centre' }, { name: 'warp_b' }] });
  assert.equal(s.examples[0].look, 'red residuals near the centre');
  assert.equal(s.examples[1].look, '');
});

test('the lab opens on a running example: once, in the warp test, with the examples and the core in', () => {
  const ready = { examples: true, core: true };
  const lab = act(initialLab(), 'lab/view', { view: 'lab' });
  assert.equal(opensOnExample(lab, ready), true);
  // not before the examples or the core, not in the study or the point sets
  assert.equal(opensOnExample(lab, { examples: false, core: true }), false);
  assert.equal(opensOnExample(lab, { examples: true, core: false }), false);
  assert.equal(opensOnExample(initialLab(), ready), false);
  assert.equal(opensOnExample(act(lab, 'lab/tab', { tab: 'points' }), ready), false);
  // not again once a test has run or is running
  const running = act(lab, 'lab/warp/start', { id: 1 });
  assert.equal(opensOnExample(running, ready), false);
  assert.equal(opensOnExample(act(running, 'lab/warp/done', { id: 1, result: { passed: true } }), ready), false);
});

test('the typed warp: a scene of the documented form, or a reason', () => {
  const typed = { domain: 'disk', params: '"radius": 1', g1: 'u1*cos(2*pi*u2)', g2: 'u1*sin(2*pi*u2)', g3: '', p: '1/pi', named: '' };
  assert.deepEqual(typedWarpScene(typed).scene.warp, { domain: { type: 'disk', radius: 1 }, g: ['u1*cos(2*pi*u2)', 'u1*sin(2*pi*u2)'], p: '1/pi' });
  assert.deepEqual(typedWarpScene({ ...typed, domain: 'interval', params: '{"lower": [0], "upper": [1]}', g1: '-log(1-u)', g2: '', p: 'x' }).scene.warp,
    { domain: { type: 'interval', lower: [0], upper: [1] }, g: '-log(1-u)', p: 'x' });
  assert.deepEqual(typedWarpScene({ ...typed, named: 'concentric_disk' }).scene, { name: 'concentric_disk', warp: 'concentric_disk' });
  assert.match(typedWarpScene({ ...typed, p: ' ' }).error, /type p/);
  assert.match(typedWarpScene({ ...typed, g1: '' }).error, /g1 is empty/);
  assert.match(typedWarpScene({ ...typed, g1: '', g2: '' }).error, /type g/);
  assert.match(typedDomain('disk', 'radius: 1').error, /not JSON members/);
  assert.match(typedDomain('disk', '"type": "box"').error, /chosen in the list/);
  assert.match(typedDomain('cube', '').error, /unknown domain type/);
  assert.deepEqual(typedDomain('sphere', '').domain, { type: 'sphere' });
  assert.equal(hasIntegrand({ warp: 'x', f: 'x' }), true);
  assert.equal(hasIntegrand({ warp: 'x' }), false);
});

test('a chosen file becomes the core\'s request: JSON rows as points, anything else as CSV text', () => {
  assert.deepEqual(fileRequest('p.csv', 'x,y\n0.1,0.2\n'), { request: { csv: 'x,y\n0.1,0.2\n' } });
  assert.deepEqual(fileRequest('p.txt', '0.1 0.2\n'), { request: { csv: '0.1 0.2\n' } });
  assert.deepEqual(fileRequest('P.JSON', '[[0.1, 0.2]]'), { request: { points: [[0.1, 0.2]] } });
  assert.match(fileRequest('p.json', '[[0.1,').error, /^p\.json: not valid JSON/);
  assert.match(fileRequest('big.csv', 'x', 65 * 1024 * 1024).error, /more than the limit/);
  // the source: the file's request when it is the source, else the sampler's
  let s = act(initialLab(), 'lab/points/file', { name: 'p.csv', request: { csv: '0.1,0.2\n' } });
  assert.deepEqual(pointSource(s.points), { source: { csv: '0.1,0.2\n' } });
  s = act(s, 'lab/points/edit', { field: 'source', value: 'sampler' });
  assert.deepEqual(pointSource(s.points), { source: { sampler: { sampler: 'sobol', n: 1024, dim: 2, seed: 1 } } });
  assert.match(pointSource({ ...s.points, source: 'file', file: null }).error, /choose a file/);
  assert.deepEqual(analyzeRequest(s.points).request.spectrum, { axes: [0, 1], size: 256 });
});

test('sampler and curve requests: the QMC randomization only when chosen, K sets, bounds checked here', () => {
  const base = initialLab().points;
  assert.deepEqual(samplerRequest({ ...base, sampler: 'halton', randomization: 'none', sets: '4' }).sampler,
    { sampler: 'halton', n: 1024, dim: 2, seed: 1, randomization: 'none', sets: 4 });
  assert.equal(samplerRequest({ ...base, sampler: 'uniform', randomization: 'owen' }).sampler.randomization, undefined);
  assert.match(samplerRequest({ ...base, n: '0' }).error, /^n must/);
  assert.match(samplerRequest({ ...base, dim: '65' }).error, /^dim must/);
  const c = initialLab().curve;
  assert.deepEqual(curveRequest(c).request, { samplers: ['uniform', 'stratified', 'sobol', 'halton'], dim: 2, n_min: 16, n_max: 4096, reps: 8, seed: 1 });
  assert.deepEqual(curveRequest(c, { f: 'x' }).request.scene, { f: 'x' });
  assert.match(curveRequest({ ...c, samplers: [] }).error, /at least one/);
  assert.match(curveRequest({ ...c, n_min: '64', n_max: '16' }).error, /n_min <= n_max/);
  assert.deepEqual(problemChoices([{ name: 'a', kind: 'integral', dimension: 2 }, { name: 'r', kind: 'render', dimension: null },
    { name: 'w', kind: 'warp', dimension: null }, { name: 'u', kind: 'integral', dimension: null }]), [{ name: 'a', dimension: 2 }]);
});

test('the words: verdict, facts, measures with the independent-points expectation, skipped reasons, integration', () => {
  assert.equal(verdictText({ passed: false, verdict: 'the samples do not follow p (p = 1e-300 < 0.01)' }),
    'Failed: the samples do not follow p (p = 1e-300 < 0.01)');
  assert.equal(verdictText({ passed: true }), 'Passed: the samples agree with the density.');
  assert.equal(verdictText(null), '');
  assert.equal(verdictText({ passed: null, outcome: 'unverified', verdict: 'could not verify: 1 bin(s) hold samples' }),
    'Could not verify: 1 bin(s) hold samples');
  assert.equal(verdictText({ passed: false, verdict: 'rejected: the samples do not follow the pdf' }), 'Failed: the samples do not follow the pdf');
  assert.equal(verdictText({ passed: true, verdict: 'passed: chi-square 36.5 on 38 degrees of freedom' }), 'Passed: chi-square 36.5 on 38 degrees of freedom');
  const facts = Object.fromEntries(warpFacts({ pdf_integral: 1.0000001, pdf_integral_error: 2e-4, statistic: 1234.5, dof: 99, pooled_bins: 100, p_value: 1e-30, significance: 0.01 }));
  assert.equal(facts['degrees of freedom'], '99');
  assert.equal(facts['bins pooled (expected < 5)'], '100');
  assert.equal(facts['p-value'], '1.000e-30');
  assert.equal(facts['∫ p over the domain (should be 1)'], '1.0000001 ± 2.0e-4');
  // an integral the quadrature could not settle is not called "not a density"
  const unsettled = Object.fromEntries(warpFacts({ pdf_integral: 0.67, pdf_integral_error: 9.6, pdf_integral_ok: false, outcome: 'unverified' }));
  assert.equal(unsettled['∫ p over the domain (should be 1)'], '0.67 ± 9.6 (the quadrature could not settle it)');
  const wrong = Object.fromEntries(warpFacts({ pdf_integral: 2, pdf_integral_error: 0, pdf_integral_ok: false, outcome: 'failed' }));
  assert.equal(wrong['∫ p over the domain (should be 1)'], '2 ± 0 (not 1: p is not a density)');
  const a = { l2_star_discrepancy: 0.001, centered_l2_discrepancy: null, wraparound_l2_discrepancy: 0.002, min_distance: null,
    min_distance_toroidal: null, expected_iid: { l2_star_discrepancy: 0.01, wraparound_l2_discrepancy: 0.02 },
    skipped: { min_distance: 'the O(N^2 d) sums exceed the limit', spectrum: 'not asked for (spectrum: false)' } };
  const rows = measureRows(a);
  assert.deepEqual(rows.map((r) => [r.key, r.value, r.iid]), [['l2_star_discrepancy', 0.001, 0.01], ['centered_l2_discrepancy', null, null],
    ['wraparound_l2_discrepancy', 0.002, 0.02], ['min_distance', null, null], ['min_distance_toroidal', null, null]]);
  assert.equal(rows[3].skipped, 'the O(N^2 d) sums exceed the limit');
  assert.deepEqual(skippedLines(a), ['min distance: the O(N^2 d) sums exceed the limit', 'spectrum: not asked for (spectrum: false)']);
  const one = integrateText({ problem: 'p', estimate: 0.4052, sets: 1, n: 256, exact: 0.4053, error: -1e-4, error_bar: null });
  assert.match(one, /a deterministic rule: error against the exact value, no error bar/);
  const k = integrateText({ problem: 'p', estimate: 0.405, sets: 8, n: 256, exact: 0.4053, error: -3e-4,
    error_bar: { half_width_95: 3.6e-4, standard_error: 1.5e-4, degrees_of_freedom: 7, method: 't interval over the sets' } });
  assert.match(k, /95% t interval ± 3\.60e-4 .*7 degrees of freedom/);
});

test('displayRows: the first set of a file, for the scatter', () => {
  assert.deepEqual(displayRows({ points: [[0.1, 0.2], [0.3, 0.4]] }), [[0.1, 0.2], [0.3, 0.4]]);
  assert.deepEqual(displayRows({ points: [[[0.1, 0.2]], [[0.5, 0.6]]] }), [[0.1, 0.2]]);
  assert.deepEqual(displayRows({ csv: '# c\nx,y\n0.1,0.2\n\n0.3;0.4\n' }), [[0.1, 0.2], [0.3, 0.4]]);
  assert.deepEqual(displayRows({ csv: 'set,x,y\na,0.1,0.2\na,0.3,0.4\nb,0.5,0.6\n' }), [[0.1, 0.2], [0.3, 0.4]]);
  assert.equal(displayRows({ csv: '0.1\n0.2\n0.3\n' }, 2).length, 2);
  assert.deepEqual(displayRows(null), []);
});

test('labSnapshot is structured-cloneable and leaves out the spectrum grid', () => {
  let s = act(initialLab(), 'lab/points/start', { id: 1 });
  s = act(s, 'lab/points/done', { id: 1, analysis: { n: 4, spectrum: { size: 2, axes: [0, 1], power: [1, 2, 3, 4], radial: { frequency: [1], power: [1], count: [4] } } }, rows: [[0, 0]] });
  const snap = labSnapshot(s);
  assert.deepEqual(structuredClone(snap), snap);
  assert.equal(snap.points.analysis.spectrum.power, undefined);
  assert.equal(snap.points.rows, 1);
});

test('the renderer\'s pixel samplers: a pixelPoints request (n = spp), analysed as the rows it gives; in the URL, not in the curve', async () => {
  const { pixelRequest, isPixelSampler, PIXEL_SAMPLERS, SAMPLERS } = await import('../src/lab/model.js');
  let s = act(act(initialLab(), 'lab/view', { view: 'lab' }), 'lab/tab', { tab: 'points' });
  for (const [field, value] of [['sampler', 'pixel_sobol'], ['n', '64'], ['dim', '4'], ['seed', '3'], ['sets', '5']]) {
    s = act(s, 'lab/points/edit', { field, value });
  }
  assert.ok(isPixelSampler('pixel_sobol') && !isPixelSampler('sobol'));
  assert.deepEqual(pixelRequest(s.points), { pixel: { pixel_sampler: 'sobol', spp: 64, dim: 4, seed: 3 } });
  // the source is the pixel's request; the analysis needs its rows first, then sends them as points
  assert.deepEqual(pointSource(s.points), { pixel: { pixel_sampler: 'sobol', spp: 64, dim: 4, seed: 3 } });
  assert.match(analyzeRequest(s.points).error, /pixel's points are needed first/);
  const rows = [[0.1, 0.2, 0.3, 0.4], [0.6, 0.7, 0.8, 0.9]];
  assert.deepEqual(analyzeRequest(s.points, rows).request, { points: rows, spectrum: { axes: [0, 1], size: 256 } });
  // a spp that is not a power of two is the core's to refuse (its error names the nearest)
  assert.equal(pixelRequest({ ...s.points, n: '48' }).pixel.spp, 48);
  assert.match(pixelRequest({ ...s.points, n: 'x' }).error, /spp/);
  assert.match(pixelRequest({ ...s.points, sampler: 'sobol' }).error, /not one of the renderer's pixel samplers/);
  for (const name of PIXEL_SAMPLERS) assert.equal(pixelRequest({ ...s.points, sampler: name }).pixel.pixel_sampler, name.replace('pixel_', ''));
  // the URL keeps the sampler (sets have no meaning for one pixel: left out)
  const q = labToQuery(s);
  assert.match(q, /sampler=pixel_sobol/);
  assert.doesNotMatch(q, /sets=/);
  assert.equal(queryToLab(q).points.sampler, 'pixel_sobol');
  // the discrepancy curve keeps the integration samplers only
  assert.equal(act(s, 'lab/curve/edit', { field: 'sampler', value: 'pixel_sobol', checked: true }).curve.samplers.includes('pixel_sobol'), false);
  assert.ok(!SAMPLERS.some(isPixelSampler));
  // an unknown sampler is not taken
  assert.equal(act(s, 'lab/points/edit', { field: 'sampler', value: 'magic' }).points.sampler, 'pixel_sobol');
});

test('named warps with parameters: only the chosen name\'s fields that are filled in are sent, parsed as the docs give them', async () => {
  const { namedWarp, warpParam, NAMED_WARP_PARAMS, NAMED_WARPS } = await import('../src/lab/model.js');
  // every named warp has its parameter list (docs/scene-format.md, "Warps")
  assert.deepEqual(Object.keys(NAMED_WARP_PARAMS).sort(), [...NAMED_WARPS].sort());
  assert.deepEqual(NAMED_WARP_PARAMS.ggx_visible_normals.map(([k]) => k), ['alpha', 'wo']);
  assert.deepEqual(NAMED_WARP_PARAMS.spherical_triangle.map(([k]) => k), ['a', 'b', 'c', 'viewpoint']);
  // none filled in: the bare name
  assert.deepEqual(namedWarp('ggx_visible_normals', {}), { warp: 'ggx_visible_normals' });
  assert.deepEqual(namedWarp('ggx_visible_normals', { alpha: ' 0.3 ' }), { warp: { name: 'ggx_visible_normals', alpha: 0.3 } });
  // brackets optional for a vector; a matrix as JSON; an expression as text; other names' fields left out
  assert.deepEqual(namedWarp('ggx_visible_normals', { alpha: '0.3', wo: '0, 0.6, 0.8', radius: '2' }),
    { warp: { name: 'ggx_visible_normals', alpha: 0.3, wo: [0, 0.6, 0.8] } });
  assert.deepEqual(namedWarp('triangle', { vertices: '[[0,0],[2,0],[0,1]]' }), { warp: { name: 'triangle', vertices: [[0, 0], [2, 0], [0, 1]] } });
  assert.deepEqual(namedWarp('tabulated_1d', { f: 'exp(-x)', bins: '32', values: '' }), { warp: { name: 'tabulated_1d', f: 'exp(-x)', bins: 32 } });
  assert.deepEqual(namedWarp('cosine_hemisphere', { alpha: '0.3' }), { warp: 'cosine_hemisphere' });
  // what does not parse is said, naming the field; ranges are the core's to check
  assert.match(namedWarp('ggx_visible_normals', { alpha: 'rough' }).error, /^alpha: 'rough' is not a number/);
  assert.match(namedWarp('polar_disk', { center: '[0, ' }).error, /^center: '\[0,' is not a list of numbers such as \[0, 0\]$/);
  assert.deepEqual(warpParam('alpha', 'number', '30'), { value: 30 });

  // the reducer keeps one text per key; the typed warp's scene; the URL keeps the chosen name's
  let s = act(initialLab(), 'lab/view', { view: 'lab' });
  s = act(s, 'lab/warp/edit', { field: 'example', value: TYPED });
  s = act(s, 'lab/warp/edit', { field: 'named', value: 'ggx_visible_normals' });
  s = act(s, 'lab/warp/edit', { field: 'wp', key: 'alpha', value: '0.3' });
  s = act(s, 'lab/warp/edit', { field: 'wp', key: 'wo', value: '[0, 0, 1]' });
  assert.equal(act(s, 'lab/warp/edit', { field: 'wp', key: 'nope', value: '1' }), s);
  assert.deepEqual(s.warp.typed.wp, { alpha: '0.3', wo: '[0, 0, 1]' });
  assert.deepEqual(typedWarpScene(s.warp.typed).scene, { name: 'ggx_visible_normals', warp: { name: 'ggx_visible_normals', alpha: 0.3, wo: [0, 0, 1] } });
  const q = labToQuery(s);
  assert.match(q, /named=ggx_visible_normals&wp\.alpha=0\.3&wp\.wo=/);
  assert.deepEqual(queryToLab(q).warp.typed, s.warp.typed);
  // emptied: no longer sent
  s = act(s, 'lab/warp/edit', { field: 'wp', key: 'wo', value: '' });
  assert.deepEqual(s.warp.typed.wp, { alpha: '0.3' });
  assert.match(typedWarpScene({ ...s.warp.typed, wp: { alpha: 'x' } }).error, /^alpha:/);
});
