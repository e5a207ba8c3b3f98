// How the entry modules (index.js, render.js) hand Emscripten its .wasm. The glue is the page's
// build (-sENVIRONMENT=web,worker): under Node it would fetch() a file: URL, which Node's fetch
// refuses, so there it is given the bytes, read from this package's folder. Elsewhere (pages,
// workers, bundles) it is given the URL beside the entry module: the entry modules write
// new URL('./x.wasm', import.meta.url) out literally, so bundlers copy the .wasm as an asset.

// Emscripten module options that already say where the wasm comes from: left as given.
const SOURCE_OPTIONS = ['wasmBinary', 'locateFile', 'instantiateWasm'];

// Hidden from bundlers (a variable, and their ignore comments): only Node runs this import.
const NODE_FS = 'node:fs/promises';

/** True under Node (and runtimes that provide its API: Deno, Bun, Electron). */
function isNode() {
  return typeof process === 'object' && process !== null &&
    typeof process.versions === 'object' && typeof process.versions.node === 'string';
}

/**
 * The bytes of the wasm file at `url`, a file: URL beside the entry module (Node only).
 * @param {URL} url
 * @returns {Promise<Uint8Array>}
 */
async function readWasm(url) {
  const { readFile } = await import(/* webpackIgnore: true */ /* @vite-ignore */ NODE_FS);
  try {
    return await readFile(url);
  } catch (e) {
    throw new Error(`mcplay: cannot read ${decodeURIComponent(url.pathname)} (${e.code ?? e.message}); ` +
      'the package is incomplete: reinstall it');
  }
}

/**
 * The Emscripten module options that load `wasmUrl`: the caller's own options, plus the wasm
 * bytes (Node, for a file: URL) or a locateFile returning `wasmUrl` (pages, workers, bundles),
 * unless the caller already said where the wasm comes from.
 * @param {URL} wasmUrl the .wasm file beside the entry module
 * @param {object} options the caller's Emscripten module options
 * @param {string} what the calling function, for the error message
 * @returns {Promise<object>}
 */
export async function wasmOptions(wasmUrl, options, what) {
  if (options === null || typeof options !== 'object' || Array.isArray(options)) {
    throw new TypeError(`${what}: options must be an object of Emscripten module options, got ` +
      (options === null ? 'null' : Array.isArray(options) ? 'an array' : typeof options));
  }
  if (SOURCE_OPTIONS.some((key) => options[key] !== undefined)) return options;
  if (isNode() && wasmUrl.protocol === 'file:') return { ...options, wasmBinary: await readWasm(wasmUrl) };
  return { ...options, locateFile: (file) => (file.endsWith('.wasm') ? wasmUrl.href : file) };
}
