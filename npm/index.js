// The package's main entry ("mcplay"): the integration core, web/core.js over the wasm module
// mcplay_web.mjs + .wasm (the C API of src/api/mcplay.h), loaded from this package's folder.
//
//   import { load } from 'mcplay';
//   const core = await load();
//   const result = core.runStudy({ f: 'exp(x)', exact: Math.E - 1 }, { n_max: 4096 });
//   console.log(core.format(result));
import createMcplay from './mcplay_web.mjs';
import { loadCore } from './core.js';
import { wasmOptions } from './wasm_options.js';

export { loadCore, McplayError, Status, MAX_JSON_BYTES } from './core.js';

// Written out literally so that bundlers copy the .wasm with the bundle.
const WASM_URL = new URL('./mcplay_web.wasm', import.meta.url);

/**
 * Instantiates the integration core from this package's mcplay_web.wasm. Each call gives a new,
 * independent core (its own wasm memory); calls on it are synchronous.
 * @param {object} [options] Emscripten module options; `wasmBinary` (the bytes) or `locateFile`
 *        replaces the package's own .wasm
 * @returns {Promise<object>} the core: version, catalog, sceneInfo, plan, runStudy, format,
 *          samples, points, analyzePoints, discrepancyCurve, integratePoints, warpTest,
 *          heapStats, dispose (index.d.ts)
 */
export async function load(options = {}) {
  return loadCore(createMcplay, await wasmOptions(WASM_URL, options, 'load'));
}
