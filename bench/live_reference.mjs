// The live view's reference handed to one band session (mcp_render_live_reference), timed in
// the page's render module built in each given directory, in turn: the best of six calls each.
// Usage: node bench/live_reference.mjs SITE SCENE MODULE_DIR [MODULE_DIR...]
//   e.g. node bench/live_reference.mjs build/site cornell_box build/site build-wasm
// (build/site holds the module the site was built with, build-wasm the one built since).
import fs from 'node:fs';
import path from 'node:path';
import { loadRenderCore } from '../web/render_core.js';

const [site, name, ...dirs] = process.argv.slice(2);
if (!site || !name || !dirs.length) {
  console.error('usage: node bench/live_reference.mjs SITE SCENE MODULE_DIR [MODULE_DIR...]');
  process.exit(2);
}
const scene = fs.readFileSync(path.join(site, 'scenes', `${name}.json`), 'utf8');
const reference = fs.readFileSync(path.join(site, 'refs', `${name}.live.mcref`)).toString('base64');
const runs = [];
for (const dir of dirs) {
  const file = path.resolve(dir, 'mcplay_render_web.mjs');
  const create = (await import(file)).default;
  const core = await loadRenderCore(create, { wasmBinary: fs.readFileSync(path.resolve(dir, 'mcplay_render_web.wasm')) });
  const { session } = core.liveOpen(scene, { pixel_sampler: 'padded_sobol', long_side: 256, rows: [0, 128],
    live_reference: 'available', pixels: true, threads: 1 });
  runs.push({ dir, core, session, best: Infinity });
}
for (let r = 0; r < 6; ++r) {
  for (const run of runs) {
    const t0 = performance.now();
    run.core.liveReference(run.session, { reference_data: reference });
    run.best = Math.min(run.best, performance.now() - t0);
  }
}
for (const run of runs) console.log(`${run.dir}: ${name}'s reference to a 128-row session in ${run.best.toFixed(0)} ms (best of 6)`);
