// The package's "mcplay/render" entry: the render core, web/render_core.js over the wasm module
// mcplay_render_web.mjs + .wasm (the C API of src/render_api/mcplay_render.h), loaded from this
// package's folder. A separate entry (and module) so that integration users never load the
// renderer.
//
//   import { load } from 'mcplay/render';
//   const render = await load();
//   const image = render.renderImage(scene, { spp: 16, outputs: ['png'] });  // glTF inline
import createMcplayRender from './mcplay_render_web.mjs';
import { loadRenderCore } from './render_core.js';
import { wasmOptions } from './wasm_options.js';

export { loadRenderCore, McplayError, Status } from './render_core.js';

// Written out literally so that bundlers copy the .wasm with the bundle.
const WASM_URL = new URL('./mcplay_render_web.wasm', import.meta.url);

/**
 * Instantiates the render core from this package's mcplay_render_web.wasm. Each call gives a
 * new, independent core; calls on it are synchronous.
 * @param {object} [options] Emscripten module options; `wasmBinary` (the bytes) or `locateFile`
 *        replaces the package's own .wasm
 * @returns {Promise<object>} the render core: version, sceneInfo, plan, runStudy, renderImage,
 *          mergeParts, pixelPoints, reference, liveOpen, livePass, liveReference, liveClose,
 *          heapStats, dispose (render.d.ts)
 */
export async function load(options = {}) {
  return loadRenderCore(createMcplayRender, await wasmOptions(WASM_URL, options, 'load'));
}
