// Writes the bad-input corpus of tests/corpus (issue 10): scene files, glTF/GLB, HDR files and
// cases.tsv, the list tests/corpus/replay.sh runs through the CLI (native and wasm). Each case
// must exit with code 2 (bad arguments) or 3 (bad scene) and print one line naming the problem.
// Deterministic: run `node tests/corpus/make_corpus.mjs` after changing it, commit the output.
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const root = path.resolve(here, '../..');
const cases = [];
const written = new Set();

function write(rel, content) {
  const file = path.join(here, rel);
  fs.mkdirSync(path.dirname(file), { recursive: true });
  fs.writeFileSync(file, content);
  written.add(rel);
}
const json = (v) => { const t = JSON.stringify(v); return (t.length > 4000 ? t : JSON.stringify(v, null, 1)) + '\n'; };
// A case: the exit code, the command line (words; {T} is a fresh temporary folder), and a
// piece of the one-line message that names the problem.
function add(name, exit, args, expect) {
  if (expect.includes('\t') || args.some((a) => /\s/.test(a))) throw new Error(name);
  cases.push([name, exit, args.join(' '), expect]);
}
// An integration scene file that must be refused with exit 3.
function scene(name, content, expect, extra = []) {
  const rel = `scene/${name}.json`;
  write(rel, typeof content === 'string' ? content : json(content));
  add(name, 3, ['run', rel, ...extra], expect);
}
const base = { f: 'x*x', estimators: ['uniform'], n_max: 64, reps: 4 };
const withf = (over) => ({ ...base, ...over });

// --- command-line arguments (exit 2) ----------------------------------------------------------
const ok = 'scene/ok.json';
write(ok, json(base));
const cli = [
  ['reps_huge', ['run', ok, '--reps', '1000000000'], 'got 1000000000'],
  ['reps_one', ['run', ok, '--reps', '1'], 'reps must be in 2..'],
  ['threads_huge', ['run', ok, '--threads', '10000'], 'got 10000'],
  ['n_min_zero', ['run', ok, '--n-min', '0'], 'n_min must be >= 1'],
  ['n_max_below_min', ['run', ok, '--n-min', '64', '--n-max', '16'], 'must be >= n_min'],
  ['n_max_2_40', ['run', ok, '--n-max', '1099511627776'], 'n_max'],
  ['n_max_overflow', ['run', ok, '--n-max', '99999999999999999999999'], "--n-max: expected a whole number"],
  ['n_max_word', ['run', ok, '--n-max', 'lots'], "--n-max: expected a whole number >= 0, got 'lots'"],
  ['seed_negative', ['run', ok, '--seed', '-1'], "--seed: expected a whole number >= 0, got '-1'"],
  ['seed_missing', ['run', ok, '--seed'], '--seed needs a value'],
  ['format_xml', ['run', ok, '--format', 'xml'], "--format: expected table, json or csv, got 'xml'"],
  ['option_unknown', ['run', ok, '--fast'], "unknown option '--fast'"],
  ['command_unknown', ['frobnicate'], "unknown command 'frobnicate'"],
  ['run_no_scene', ['run'], 'run needs a scene'],
  ['run_two_scenes', ['run', ok, ok], 'run takes one scene'],
  ['estimators_empty_name', ['run', ok, '--estimators', 'uniform,,stratified'], 'empty name'],
  ['estimators_comma', ['run', ok, '--estimators', ','], '--estimators'],
  ['estimators_unknown', ['run', ok, '--estimators', 'faure'], "unknown estimator 'faure'"],
  ['estimators_needs_pdf', ['run', ok, '--estimators', 'importance'], 'needs a pdf'],
  ['width_on_integration', ['run', ok, '--width', '8'], 'are for render scenes'],
  ['out_missing_dir', ['run', ok, '--out', '{T}/no/such/dir/result.txt'], "--out: cannot write"],
  ['out_is_dir', ['run', ok, '--out', '{T}'], '--out: '],
  ['list_extra', ['list', 'extra'], "list: unexpected argument 'extra'"],
  ['list_no_dir', ['list', '--scenes', '{T}/none'], "cannot open scenes directory"],
  ['render_no_out', ['render', 'render/ok.json'], 'render needs --out'],
  ['render_out_txt', ['render', 'render/ok.json', '--out', '{T}/x.txt'], 'must end in .png, .hdr or .pfm'],
  ['render_error_jpg', ['render', 'render/ok.json', '--error-out', '{T}/x.jpg'], 'must be a .png file'],
  ['render_spp_zero', ['render', 'render/ok.json', '--spp', '0', '--out', '{T}/x.png'], 'options.spp'],
  ['render_spp_huge', ['render', 'render/ok.json', '--spp', '99999999', '--out', '{T}/x.png'], 'options.spp'],
  ['render_estimator_unknown', ['render', 'render/ok.json', '--estimator', 'nope', '--out', '{T}/x.png'], "unknown estimator 'nope'"],
  ['render_width_huge', ['render', 'render/ok.json', '--width', '100000', '--out', '{T}/x.png'], 'width'],
  ['render_format_bad', ['render', 'render/ok.json', '--format', 'xml', '--out', '{T}/x.png'], '--format'],
  ['render_out_unwritable', ['render', 'render/ok.json', '--out', '{T}/no/dir/x.png'], '--out: cannot write'],
  ['run_render_reps_one', ['run', 'render/ok.json', '--reps', '1'], 'reps'],
  ['run_render_n_max_huge', ['run', 'render/ok.json', '--n-max', '4194304'], 'spp_max'],
];
for (const [name, args, expect] of cli) add(name, 2, args, expect);

// --- scene files that are not scene files (exit 3) -------------------------------------------
add('file_missing', 3, ['run', 'scene/does_not_exist.json'], "no scene file 'scene/does_not_exist.json'");
add('file_directory', 3, ['run', 'scene'], 'is a directory');
add('file_dev_zero', 3, ['run', '/dev/zero'], 'not a regular file');
add('file_dev_urandom', 3, ['run', '/dev/urandom'], 'not a regular file');
add('file_fifo', 3, ['run', '{T}/fifo.json'], 'not a regular file');
add('file_too_large', 3, ['run', '{T}/sparse.json'], 'more than the limit');
add('render_file_dev_zero', 3, ['render', '/dev/zero', '--out', '{T}/x.png'], 'not a regular file');
scene('empty', '', 'invalid JSON');
scene('garbage', '\u0000\u0001binary\u00ff', 'invalid JSON');
scene('truncated', '{"f": "x*x", "estimators": ["unif', 'invalid JSON');
scene('not_object', '[1, 2, 3]', 'expected an object');
scene('string_top', '"x*x"', 'expected an object');
scene('nan_literal', '{"f": "x", "exact": NaN}', 'invalid JSON');
scene('number_1e400', '{"f": "x", "exact": 1e400}', 'exact');
scene('trailing_comma', '{"f": "x",}', 'invalid JSON');
scene('comment', '{"f": "x" /* c */}', 'invalid JSON');
scene('duplicate_key', '{"f": "x", "n_max": 64, "n_max": 1099511627776}', 'appears twice');
scene('duplicate_nested', '{"f": "x", "domain": {"type": "box", "type": "disk"}}', 'appears twice');
scene('deep_150000', '['.repeat(150000) + ']'.repeat(150000), 'nested more than 64 levels');
scene('deep_8000_object', '{"a":'.repeat(8000) + '1' + '}'.repeat(8000), 'nested more than 64 levels');
scene('deep_65', '{"f": "x", "notes": ' + '['.repeat(65) + ']'.repeat(65) + '}', 'nested more than 64 levels');
// A typed warp that leaves its domain fails the study, naming the point (issue 48).
scene('warp_outside_study', { warp: { domain: { type: 'interval', lower: 0, upper: 1 }, g: ['2*u'], p: '1' }, f: 'x', estimators: ['warp'], n_max: 64, reps: 4 }, 'its warp put a point outside its domain');
// Issue 48's silent limits, each refused with the field and the reason: a named warp's
// parameter it does not read (or that another warp reads), a count of 0 that meant the default,
// a time budget of 0 that meant none, --part and --axes named as typed.
scene('warp_param_unknown', withf({ warp: { name: 'concentric_disk', alpha: 0.3 } }), "unknown parameter 'alpha' of the warp 'concentric_disk' (its parameters: center, radius)");
scene('warp_param_none', withf({ warp: { name: 'uniform_sphere', radius: 2 } }), "the warp 'uniform_sphere' (it takes none)");
scene('warp_bins_zero', withf({ warp: { name: 'tabulated_1d', f: 'x', bins: 0 } }), 'warp.bins: must be in 1..4096, got 0');
scene('warp_ny_zero', withf({ warp: { name: 'tabulated_2d', f: 'x*y', nx: 8, ny: 0 } }), 'warp.ny: must be in 1..4096, got 0');
scene('max_seconds_zero', withf({ rel_tol: 0.01, max_seconds: 0 }), 'scene: max_seconds: must be a finite number > 0, got 0');
scene('max_seconds_zero_alone', withf({ max_seconds: 0 }), 'max_seconds: must be a finite number > 0');
scene('heuristic_one_technique', withf({ estimators: [{ name: 'is_power', pdf: { type: 'power', k: 1 }, heuristic: 'power' }] }), "heuristic: estimator 'is_power' samples one technique");
add('part_beyond_reps', 2, ['run', ok, '--part', '0/9', '--format', 'json'], '--part 0/9 (K): must be in 1..reps = 4, got 9');
write('lab/points_2d.csv', '0.1,0.2\n0.3,0.4\n0.5,0.6\n0.7,0.8\n');
add('analyze_axes_beyond', 2, ['analyze', 'lab/points_2d.csv', '--axes', '1,3'], '--axes 1,3: the points have 2 coordinates (x1 to x2)');
add('analyze_axes_zero', 2, ['analyze', 'lab/points_2d.csv', '--axes', '0,1'], '--axes: expected two different columns counted from 1');
// Every reader of JSON is bounded as run's is (issue 48): a point file for analyze, a part for
// merge (analyze on this file crashed with exit 139).
add('analyze_deep_150000', 2, ['analyze', 'scene/deep_150000.json'], 'nested more than 64 levels');
add('merge_deep_150000', 2, ['merge', 'scene/deep_150000.json'], 'nested more than 64 levels');
// A CSV's first row with one unparsable field is an error, not a header (issue 48).
write('lab/first_row_e.csv', '0.5e,0.5\n0.25,0.75\n');
add('analyze_first_row_e', 2, ['analyze', 'lab/first_row_e.csv'], "row 1, column 1: '0.5e' is not a number");
write('lab/first_row_empty.csv', '\ufeff0.5,,0.5\n0.25,0.5,0.75\n');
add('analyze_first_row_empty', 2, ['analyze', 'lab/first_row_empty.csv'], 'row 1, column 2: the field is empty');
// Found by fuzz_scene: user text with control characters quoted in a message must keep it to
// one line (fuzz/findings/scene/).
scene('fuzz_multiline_key', '{"\\n"', 'invalid JSON');
scene('fuzz_multiline_integrand', '{"integrand":{"type":"a\\nb"}}', "unknown integrand 'a\\nb'");
scene('bad_utf8', '{"f": "x\u00ff\u00fe", "name": "\ud800"}', 'scene.f');

// --- scene fields -------------------------------------------------------------------------------
scene('unknown_field', withf({ n_mx: 5 }), "unknown field 'n_mx'");
scene('no_integrand', { estimators: ['uniform'] }, 'missing "integrand"');
scene('f_and_integrand', withf({ integrand: { type: 'constant' } }), 'not both');
scene('n_max_type', withf({ n_max: '64' }), 'scene.n_max: expected a non-negative whole number');
scene('n_max_negative', withf({ n_max: -64 }), 'scene.n_max');
scene('n_max_fraction', withf({ n_max: 64.5 }), 'scene.n_max');
scene('n_max_2_36_reps_32', withf({ n_max: 68719476736, reps: 32 }), 'integrand evaluations');
scene('reps_huge', withf({ reps: 1000000000 }), 'got 1000000000');
scene('reps_bool', withf({ reps: true }), 'scene.reps');
scene('threads_huge', withf({ threads: 10000 }), 'got 10000');
scene('seed_float', withf({ seed: 1.5 }), 'scene.seed');
scene('quantity_bad', withf({ quantity: 'median' }), 'scene.quantity');
scene('accumulator_bad', withf({ accumulator: 'float16' }), 'scene.accumulator');
scene('exact_string', withf({ exact: 'one third' }), 'scene.exact');
scene('name_number', withf({ name: 7 }), 'scene.name');
scene('estimators_empty', withf({ estimators: [] }), 'scene.estimators');
scene('estimators_object', withf({ estimators: { uniform: 1 } }), 'scene.estimators');
scene('estimator_misspelt', withf({ estimators: ['stratifed'] }), "unknown estimator 'stratifed'");
scene('estimator_faure', withf({ estimators: ['faure'] }), "unknown estimator 'faure'");
scene('estimator_sobol_permutation', withf({ estimators: [{ name: 'q', sampler: 'sobol', randomization: 'permutation' }] }), "does not apply to sobol");
scene('estimator_lattice_too_many', withf({ estimators: ['lattice'], n_max: 2 ** 30 }), 'points are built for');
scene('estimator_sobol_k0', withf({ estimators: [{ name: 'q', sampler: 'sobol', randomizations: 0 }] }), 'must be a power of two from 2 to 1024');
scene('estimator_proposals_empty', withf({ estimators: [{ name: 'm', proposals: [] }] }), 'at least one proposal');
scene('estimator_sobol_k3', withf({ estimators: [{ name: 'q', sampler: 'sobol', randomizations: 3 }] }), 'must be a power of two');
scene('estimator_name_only', withf({ estimators: [{ name: 'mine' }] }), "unknown estimator 'mine'");
scene('estimator_number', withf({ estimators: [5] }), 'scene.estimators[0]');
scene('estimator_duplicate', withf({ estimators: ['uniform', 'uniform'] }), 'duplicate estimator name');
scene('estimator_sampler_bad', withf({ estimators: [{ name: 'a', sampler: 'niederreiter' }] }), "unknown sampler 'niederreiter'");
scene('estimator_per_stratum_3', withf({ estimators: [{ name: 'a', sampler: 'stratified', samples_per_stratum: 3 }] }), 'samples_per_stratum');
scene('estimator_per_stratum_indep', withf({ estimators: [{ name: 'a', sampler: 'independent', samples_per_stratum: 2 }] }), 'stratified sampler only');
scene('estimator_warp_box', withf({ estimators: [{ name: 'a', sampler: 'independent', warp: 'polar' }] }), 'warp');
scene('estimator_warp_bad', { f: '1', domain: { type: 'disk' }, estimators: [{ name: 'a', sampler: 'independent', warp: 'spiral' }] }, "unknown warp 'spiral'");
// A caller's function reaches the core only through the library (Python, mcp_study_run_with).
scene('function_integrand_no_functions', { integrand: { type: 'function', name: 'f' }, domain: { type: 'box', dim: 2 } }, 'given no functions');
scene('function_integrand_no_name', { integrand: { type: 'function' }, domain: { type: 'box', dim: 2 } }, 'expected the name of a function');
scene('function_integrand_dim_0', { integrand: { type: 'function', name: 'f', dim: 0 } }, 'expected 1 to 64');
scene('function_warp_no_functions', { f: 'x', warp: { domain: { type: 'disk' }, g: { function: 'g' }, p: '1/pi' } }, 'given no functions');
scene('importance_no_pdf', withf({ estimators: ['importance'] }), 'needs a pdf');
// domains
scene('domain_unknown', withf({ domain: { type: 'torus' } }), "unknown domain 'torus'");
scene('domain_dim_0', withf({ domain: { type: 'box', dim: 0 } }), 'scene.domain.dim');
scene('domain_dim_65', withf({ domain: { type: 'box', dim: 65 } }), 'scene.domain.dim');
scene('domain_dim_huge', withf({ domain: { type: 'box', dim: 1e15 } }), 'scene.domain.dim');
scene('domain_lower_above_upper', withf({ domain: { type: 'box', lower: [1], upper: [0] } }), 'scene.domain');
scene('domain_lengths', withf({ domain: { type: 'box', lower: [0, 0], upper: [1] } }), 'lower has 2 entries');
scene('domain_box_1e200', withf({ f: '1', domain: { type: 'box', lower: [-1e200, -1e200], upper: [1e200, 1e200] } }), 'scene.domain');
scene('domain_box_tiny', withf({ f: '1', domain: { type: 'box', lower: [0, 0, 0, 0], upper: [1e-100, 1e-100, 1e-100, 1e-100] } }), 'scene.domain');
scene('domain_disk_tiny', { f: '1', domain: { type: 'disk', radius: 1e-200 }, estimators: ['uniform'] }, 'scene.domain');
scene('domain_disk_huge', { f: '1', domain: { type: 'disk', radius: 1e200 }, estimators: ['uniform'] }, 'scene.domain');
scene('domain_disk_negative', { f: '1', domain: { type: 'disk', radius: -1 }, estimators: ['uniform'] }, 'scene.domain');
scene('domain_triangle_flat', { f: '1', domain: { type: 'triangle', vertices: [[0, 0], [1, 1], [2, 2]] }, estimators: ['uniform'] }, 'scene.domain');
scene('domain_triangle_two', { f: '1', domain: { type: 'triangle', vertices: [[0, 0], [1, 1]] }, estimators: ['uniform'] }, 'vertices');
scene('domain_triangle_huge', { f: '1', domain: { type: 'triangle', vertices: [[0, 0], [1e200, 0], [0, 1e200]] }, estimators: ['uniform'] }, 'scene.domain');
scene('domain_interval_2d', withf({ domain: { type: 'interval', lower: [0, 0], upper: [1, 1] } }), 'interval has one dimension');
// integrands
scene('integrand_unknown', withf({ f: undefined, integrand: { type: 'bessel' } }), "unknown integrand 'bessel'");
scene('integrand_no_type', withf({ f: undefined, integrand: { scale: 2 } }), 'missing "type"');
scene('integrand_number', withf({ f: 5 }), 'scene.f');
scene('powers_1000', withf({ f: undefined, integrand: { type: 'monomial', powers: Array(1000).fill(1) } }), 'has 1000 entries');
scene('rates_65', withf({ f: undefined, integrand: { type: 'exponential', rates: Array(65).fill(1) } }), 'has 65 entries');
scene('gaussian_sigma_zero', withf({ f: undefined, integrand: { type: 'gaussian', center: [0.5], sigma: 0 } }), 'sigma');
scene('genz_dim_10000', withf({ f: undefined, integrand: { type: 'genz_gaussian', dim: 10000 } }), 'scene.integrand.dim');
scene('genz_dim_65', withf({ f: undefined, integrand: { type: 'genz_gaussian', dim: 65 } }), 'scene.integrand.dim');
scene('genz_dim_conflict', withf({ f: undefined, domain: { type: 'box', dim: 2 }, integrand: { type: 'genz_oscillatory', dim: 12 } }), 'scene.integrand.dim');
scene('genz_difficulty_zero', withf({ f: undefined, integrand: { type: 'genz_corner_peak', difficulty: 0 } }), 'difficulty');
scene('genz_u_without_a', withf({ f: undefined, integrand: { type: 'genz_corner_peak', u: [0.5] } }), 'give "a" with "u"');
// expressions
const expr = (name, f, expect, dim) => scene(name, withf(dim ? { f, domain: { type: 'box', dim } } : { f }), expect);
expr('expr_empty', '', 'scene.f');
expr('expr_unbalanced', '(x+1', 'scene.f');
expr('expr_unknown_function', 'bessel(x)', 'bessel');
expr('expr_unknown_variable', 'x + q', 'scene.f');
expr('expr_x5_in_2d', 'x1 + x5', 'scene.f', 2);
expr('expr_pow_overflow', '10^400', '10^400');
expr('expr_literal_overflow', '1e400*x', 'scene.f');
expr('expr_const_inf', 'x + exp(1000)', 'scene.f');
expr('expr_deep_parens', '('.repeat(100000) + 'x' + ')'.repeat(100000), 'scene.f');
expr('expr_deep_unary', '-'.repeat(100000) + 'x', 'scene.f');
expr('expr_deep_pow', 'x^'.repeat(50000) + 'x', 'scene.f');
expr('expr_long', 'x+'.repeat(600000) + 'x', 'scene.f');
expr('expr_trailing', 'x*', 'scene.f');
expr('expr_double_op', 'x**2', 'scene.f');
expr('expr_bad_char', 'x $ 2', 'scene.f');
expr('expr_nul', 'x\u0000+1', 'scene.f');
expr('expr_number_garbage', '1.2.3*x', 'scene.f');
expr('expr_args', 'sin(x, x)', 'scene.f');
// pdfs
const pdf = (name, p, expect, over = {}) =>
  scene(name, withf({ estimators: [{ name: 'is', pdf: p }], ...over }), expect);
pdf('pdf_unknown', { type: 'cauchy' }, "unknown");
pdf('pdf_missing_type', { mu: 0.5 }, 'scene.estimators[0].pdf');
pdf('pdf_gaussian_sigma_zero', { type: 'gaussian', mu: 0.5, sigma: 0 }, 'sigma');
pdf('pdf_gaussian_sigma_neg', { type: 'gaussian', mu: 0.5, sigma: -1 }, 'sigma');
pdf('pdf_gaussian_far', { type: 'gaussian', mu: 1e6, sigma: 1e-3 }, 'scene.estimators[0].pdf');
pdf('pdf_power_neg', { type: 'power', k: -2 }, 'scene.estimators[0].pdf');
pdf('pdf_power_nan_shape', { type: 'tabulated', bins: 8, shape: '0/0*x' }, 'scene.estimators[0].pdf');
pdf('pdf_tab_bins_zero', { type: 'tabulated', bins: 0, shape: 'integrand' }, 'bins');
pdf('pdf_tab_bins_huge', { type: 'tabulated', bins: 1e9, shape: 'integrand' }, 'bins');
pdf('pdf_tab_values_count', { type: 'tabulated', bins: 4, values: [1, 2, 3] }, 'values');
pdf('pdf_tab_values_neg', { type: 'tabulated', values: [1, -1] }, 'scene.estimators[0].pdf');
pdf('pdf_tab_values_zero', { type: 'tabulated', values: [0, 0] }, 'scene.estimators[0].pdf');
pdf('pdf_tab_values_string', { type: 'tabulated', values: [1, 'a'] }, 'values[1]');
pdf('pdf_tab_values_2e6', { type: 'tabulated', values: Array(1100000).fill(1) }, 'values');
pdf('pdf_tab_shape_nan', { type: 'tabulated', bins: 64, shape: 'log(-1-x)' }, 'NaN');
pdf('pdf_tab_shape_bad', { type: 'tabulated', bins: 64, shape: 'sin(' }, 'shape');
pdf('pdf_tab2d_4096', { type: 'tabulated_2d', bins: [4096, 4096], shape: 'integrand' }, 'bins', { f: 'x1*x2', domain: { type: 'box', dim: 2 } });
pdf('pdf_tab2d_on_1d', { type: 'tabulated_2d', bins: [8, 8], shape: 'integrand' }, 'scene.estimators[0].pdf');
pdf('pdf_tab2d_values_2e6', { type: 'tabulated_2d', values: Array(1100000).fill(1) }, 'values', { f: 'x1*x2', domain: { type: 'box', dim: 2 } });
pdf('pdf_product_count', { type: 'product', factors: [{ type: 'uniform' }] }, 'factors', { f: 'x1*x2', domain: { type: 'box', dim: 2 } });
pdf('pdf_expression_bad', { type: 'expression', p: 'x +' }, 'scene.estimators[0].pdf');
pdf('pdf_expression_nan', { type: 'expression', p: 'log(-1-x)' }, 'NaN');
pdf('pdf_cosine_hemisphere_box', { type: 'cosine_hemisphere' }, 'scene.estimators[0].pdf');
pdf('pdf_unknown_key', { type: 'uniform', shape: 1, sigmaa: 2 }, "unknown field 'sigmaa'");

// --- render scenes --------------------------------------------------------------------------------
const gltf = JSON.parse(fs.readFileSync(path.join(root, 'scenes/quad_light_floor.gltf'), 'utf8'));
const clone = (v) => JSON.parse(JSON.stringify(v));
const small = { width: 8, height: 8, spp_min: 1, spp_max: 2, reps: 2, estimators: ['light_area'] };
function render(name, renderObj, expect, args = null, exit = 3) {
  const rel = `render/${name}.json`;
  write(rel, json({ name, render: { ...small, ...renderObj } }));
  add(name, exit, args ? args.map((a) => (a === '@' ? rel : a)) : ['run', rel, '--no-cache'], expect);
}
write('render/ok.json', json({ name: 'ok', render: { ...small, gltf: 'ok.gltf' } }));
write('render/ok.gltf', json(gltf));
const buffer = Buffer.from(gltf.buffers[0].uri.split(',')[1], 'base64');
write('outside.bin', buffer);
write('outside.gltf', json(gltf));
write('render/inside.bin', buffer);
const withBuffer = (uri) => { const g = clone(gltf); g.buffers[0].uri = uri; return g; };
// Paths that leave the scene's folder.
render('gltf_absolute', { gltf: '/etc/passwd' }, 'scene.render.gltf');
render('gltf_dotdot', { gltf: '../outside.gltf' }, 'outside the scene');
render('gltf_dev_zero', { gltf: '/dev/zero' }, 'scene.render.gltf');
render('gltf_dev_urandom', { gltf: '/dev/urandom' }, 'scene.render.gltf');
render('gltf_etc', { gltf: '/etc' }, 'scene.render.gltf');
render('gltf_dot', { gltf: '.' }, 'not a file');
render('gltf_missing', { gltf: 'missing.gltf' }, 'does not exist');
render('gltf_empty_name', { gltf: '' }, 'scene.render.gltf');
render('gltf_number', { gltf: 5 }, 'scene.render.gltf');
render('buffer_dotdot', { gltf: withBuffer('../outside.bin') }, 'outside the scene');
render('buffer_passwd', { gltf: withBuffer('../../../../../../../../etc/passwd') }, 'outside the scene');
render('buffer_absolute', { gltf: withBuffer('/etc/passwd') }, 'buffers[0]');
render('buffer_encoded_dotdot', { gltf: withBuffer('%2e%2e/outside.bin') }, 'outside the scene');
render('buffer_dev_zero', { gltf: withBuffer('../../../../../../../../dev/zero') }, 'buffers[0]');
render('buffer_directory', { gltf: withBuffer('.') }, 'buffers[0]');
render('buffer_symlink', { gltf: withBuffer('link.bin') }, 'outside the scene', ['run', '{T}/scene/buffer_symlink.json', '--no-cache']);
write('runtime/buffer_symlink.json', json({ name: 'buffer_symlink', render: { ...small, gltf: withBuffer('link.bin') } }));
{
  const g = clone(gltf);
  g.images = [{ uri: '../outside.bin' }];
  g.textures = [{ source: 0 }];
  g.materials[0].pbrMetallicRoughness.baseColorTexture = { index: 0 };
  render('image_dotdot', { gltf: g }, 'outside the scene');
}
write('render/sub/nested.gltf', json(withBuffer('../../outside.bin')));
render('nested_gltf_escape', { gltf: 'sub/nested.gltf' }, 'outside the scene');
render('reference_absolute', { gltf: 'ok.gltf', reference: { file: '/etc/passwd' } }, 'reference.file');
render('reference_dotdot', { gltf: 'ok.gltf', reference: { file: '../outside.hdr' } }, 'reference.file');
render('reference_dev_zero', { gltf: 'ok.gltf', reference: { file: '../../../../../../../dev/zero' } }, 'reference.file');
render('reference_missing', { gltf: 'ok.gltf', reference: { file: 'none.hdr' } }, 'reference.file');
write('outside.hdr', '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 8\n' + '\u0080\u0080\u0080\u0080'.repeat(64));
// Bad references inside the folder.
write('render/truncated.hdr', '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 8 +X 8\n' + 'AAAA'.repeat(20));
write('render/negative.hdr', '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y -5 +X 8\n' + 'AAAA'.repeat(64));
write('render/notjson.hdr', '{"looks": "like json"}\n');
write('render/huge.hdr', '#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 100000000 +X 100000000\n');
render('reference_truncated', { gltf: 'ok.gltf', reference: { file: 'truncated.hdr' } }, 'reference.file');
render('reference_negative_size', { gltf: 'ok.gltf', reference: { file: 'negative.hdr' } }, 'reference.file');
render('reference_not_hdr', { gltf: 'ok.gltf', reference: { file: 'notjson.hdr' } }, 'reference.file');
render('reference_huge_size', { gltf: 'ok.gltf', reference: { file: 'huge.hdr' } }, 'reference.file');
render('reference_wrong_size', { gltf: 'ok.gltf', width: 4, reference: { file: 'truncated.hdr' } }, 'reference.file');
// glTF content.
{
  const g = clone(gltf);
  g.materials[1].extensions = { KHR_materials_emissive_strength: { emissiveStrength: 1e308 } };
  g.materials[1].emissiveFactor = [5, 5, 5];
  render('emissive_overflow', { gltf: g }, 'materials[1]');
}
{
  const g = clone(gltf);
  g.materials[1].extensions = { KHR_materials_emissive_strength: { emissiveStrength: 1e300 } };
  g.materials[1].emissiveFactor = [1, 1, 1];
  render('emissive_beyond_float32', { gltf: g }, 'beyond the float32 range');
}
{
  const g = clone(gltf);
  g.nodes[0].scale = [1e30, 1, 1e30];
  render('node_scale_1e30', { gltf: g }, 'beyond 1e9');
}
{
  const g = clone(gltf);
  g.scenes[0].extras = { deep: JSON.parse('['.repeat(60) + ']'.repeat(60)) };
  const text = JSON.stringify({ name: 'extras_deep', render: { ...small, gltf: 'extras_deep.gltf' } });
  write('render/extras_deep.json', text + '\n');
  write('render/extras_deep.gltf', JSON.stringify(g).replace('"deep":[', '"deep":' + '['.repeat(200000)).replace(/\]\]\}/, ']'.repeat(200000) + ']]}'));
  add('extras_deep', 3, ['run', 'render/extras_deep.json', '--no-cache'], 'nested more than 64 levels');
}
{ const g = clone(gltf); delete g.cameras; g.nodes = g.nodes.slice(0, 2); g.scenes[0].nodes = [0, 1];
  render('no_camera', { gltf: g }, 'no perspective camera'); }
{ const g = clone(gltf); g.accessors[0].count = 400000; render('accessor_overrun', { gltf: g }, 'accessors'); }
{ const g = clone(gltf); g.bufferViews[0].byteOffset = 1e12; render('view_offset_huge', { gltf: g }, 'bufferViews'); }
{ const g = clone(gltf); g.meshes[0].primitives[0].mode = 1; render('lines_mode', { gltf: g }, 'mode 1'); }
{ const g = clone(gltf); g.nodes[0].children = [0]; render('node_cycle', { gltf: g }, 'nodes'); }
{ const g = clone(gltf); g.materials[0].pbrMetallicRoughness.roughnessFactor = 'rough'; render('material_type', { gltf: g }, 'materials[0]'); }
{ const g = clone(gltf); g.buffers[0].byteLength = 1e15; render('buffer_length_huge', { gltf: g }, 'buffers[0]'); }
{ const g = clone(gltf); g.asset.version = '1.0'; render('asset_version', { gltf: g }, 'version'); }
// glTF 2.0 asks aspectRatio > 0; tinygltf reads 0 as "none", which silently used the scene's
// ratio (issue 48).
{ const g = clone(gltf); g.cameras[0].perspective.aspectRatio = 0; render('camera_aspect_zero', { gltf: g }, 'cameras[0].perspective.aspectRatio: expected a number > 0, got 0'); }
write('render/bad_json.gltf', '{"asset": {"version": "2.0"}, "nodes": [}\n');
render('gltf_invalid_json', { gltf: 'bad_json.gltf' }, 'invalid JSON');
write('render/dup.gltf', '{"asset": {"version": "2.0"}, "scene": 0, "scene": 1}\n');
render('gltf_duplicate_key', { gltf: 'dup.gltf' }, 'appears twice');
write('render/truncated.glb', Buffer.concat([Buffer.from('glTF'), Buffer.from([2, 0, 0, 0, 0, 1, 0, 0])]));
render('glb_truncated', { gltf: 'truncated.glb' }, 'GLB');
write('render/text.gltf', 'this is not a glTF file at all\n');
render('gltf_text', { gltf: 'text.gltf' }, 'invalid JSON');
// Render settings.
render('width_zero', { gltf: 'ok.gltf', width: 0 }, 'scene.render.width');
render('width_huge', { gltf: 'ok.gltf', width: 5000 }, 'scene.render.width');
render('pixels_huge', { gltf: 'ok.gltf', width: 4096, height: 4096 }, 'pixels');
render('spp_max_huge', { gltf: 'ok.gltf', spp_max: 4194304 }, 'spp_max');
render('reps_one_render', { gltf: 'ok.gltf', reps: 1 }, 'scene.render.reps');
render('estimator_unknown_render', { gltf: 'ok.gltf', estimators: ['mis_cubic'] }, "unknown estimator 'mis_cubic'");
render('estimator_depth_zero', { gltf: 'ok.gltf', estimators: [{ strategy: 'path', max_depth: 0 }] }, 'max_depth');
render('estimator_ris_candidates_huge', { gltf: 'ok.gltf', estimators: [{ strategy: 'ris', candidates: 1000 }] }, 'candidates: must be a whole number in 1..64');
render('estimator_candidates_not_ris', { gltf: 'ok.gltf', estimators: [{ strategy: 'light_area', candidates: 4 }] }, "only ris, mis_balance, mis_power and path resample candidates");
render('render_unknown_field', { gltf: 'ok.gltf', colour: 'red' }, "unknown field 'colour'");
render('render_exposure_string', { gltf: 'ok.gltf', exposure: 'bright' }, 'exposure');
render('render_accel_bad', { gltf: 'ok.gltf', accel: 'kd_tree' }, 'accel');
render('render_mixed_quantities', { gltf: 'ok.gltf', estimators: ['light_area', { strategy: 'path' }] }, 'one study compares');
render('render_image_bad_scene', { gltf: '../outside.gltf' }, 'outside the scene', ['render', '@', '--out', '{T}/x.png', '--no-cache']);

// --- cases.tsv ------------------------------------------------------------------------------------
const header = '# exit\targuments (run from tests/corpus; {T} is a fresh temporary folder)\texpected part of the message\n';
const lines = cases.map(([n, e, a, x]) => `${e}\t${a}\t${x}\t# ${n}`);
fs.writeFileSync(path.join(here, 'cases.tsv'), header + lines.join('\n') + '\n');
console.log(`${cases.length} cases, ${written.size} files`);
