// A glTF scene the reader opens in the page: the files chosen (a .glb, or a .gltf with the .bin
// and image files it names) become one render scene with the glTF inline, every external buffer
// and image turned into a data: URI, as the site's own scenes are built (web/tools/build-site.mjs)
// and as the render core takes them (it reads no files). Pure: no DOM, no fetch; the caller
// reads the files into bytes. Every failure is an Error whose message names the file and what is
// wrong, for the page to show.

/** The most the page reads of the chosen files together (the core has its own, larger bounds). */
export const MAX_GLTF_BYTES = 64 * 1024 * 1024;

const IMAGE_TYPES = { png: 'image/png', jpg: 'image/jpeg', jpeg: 'image/jpeg', webp: 'image/webp' };

/** Base64 of bytes (a Uint8Array), in chunks: no call gets more arguments than it can take. */
export function base64Of(bytes) {
  let text = '';
  for (let i = 0; i < bytes.length; i += 0x8000) text += String.fromCharCode(...bytes.subarray(i, i + 0x8000));
  return btoa(text);
}

const extension = (name) => (name.includes('.') ? name.slice(name.lastIndexOf('.') + 1).toLowerCase() : '');
const baseName = (uri) => uri.slice(uri.lastIndexOf('/') + 1);

/** The glTF JSON of a binary glTF (.glb): its JSON chunk, with the BIN chunk as buffer 0's data URI. */
function glbToJson(bytes, name) {
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  const u32 = (o) => view.getUint32(o, true);
  if (bytes.length < 20 || u32(0) !== 0x46546c67) throw new Error(`${name}: not a binary glTF (no "glTF" magic)`);
  if (u32(8) > bytes.length) throw new Error(`${name}: the header says ${u32(8)} bytes, the file has ${bytes.length}`);
  const jsonLength = u32(12);
  if (u32(16) !== 0x4e4f534a || 20 + jsonLength > bytes.length) throw new Error(`${name}: its first chunk is not JSON`);
  let gltf;
  try {
    gltf = JSON.parse(new TextDecoder().decode(bytes.subarray(20, 20 + jsonLength)));
  } catch (e) {
    throw new Error(`${name}: its JSON chunk is not valid JSON (${e.message})`);
  }
  const binAt = 20 + jsonLength + ((4 - (jsonLength % 4)) % 4);
  if (binAt + 8 <= bytes.length && u32(binAt + 4) === 0x004e4942 && gltf && Array.isArray(gltf.buffers)
      && gltf.buffers[0] && gltf.buffers[0].uri === undefined) {
    const chunk = u32(binAt);
    if (binAt + 8 + chunk > bytes.length) throw new Error(`${name}: its BIN chunk runs past the end of the file`);
    // The chunk is padded to 4 bytes; the buffer is its byteLength (when that fits).
    const declared = gltf.buffers[0].byteLength;
    const length = Number.isSafeInteger(declared) && declared >= 0 && declared <= chunk ? declared : chunk;
    gltf.buffers[0].uri = `data:application/octet-stream;base64,${base64Of(bytes.subarray(binAt + 8, binAt + 8 + length))}`;
  }
  return gltf;
}

/** Throws when the chosen files hold more than the page reads (checked before they are read). */
export function checkGltfBytes(total) {
  if (total > MAX_GLTF_BYTES) {
    throw new Error(`the chosen files hold ${(total / 1048576).toFixed(1)} MiB; the page opens at most ${MAX_GLTF_BYTES / 1048576} MiB (the CLI takes more: mcplay run scene.gltf)`);
  }
}

/**
 * The render scene of the chosen files: [{name, bytes: Uint8Array}]. Exactly one .gltf or .glb;
 * the buffers and images its JSON names by relative URI are looked up among the other files by
 * their file name. Returns {name, description, render: {gltf}}.
 */
export function sceneFromFiles(files) {
  if (!Array.isArray(files) || !files.length) throw new Error('choose a .glb file, or a .gltf file with the .bin and image files it names');
  checkGltfBytes(files.reduce((sum, f) => sum + f.bytes.length, 0));
  const mains = files.filter((f) => ['gltf', 'glb'].includes(extension(f.name)));
  if (mains.length !== 1) {
    throw new Error(mains.length ? `choose one .gltf or .glb file, not ${mains.length} (${mains.map((f) => f.name).join(', ')})`
      : 'none of the chosen files is a .gltf or .glb file');
  }
  const main = mains[0];
  let gltf;
  if (extension(main.name) === 'glb') {
    gltf = glbToJson(main.bytes, main.name);
  } else {
    try {
      gltf = JSON.parse(new TextDecoder().decode(main.bytes));
    } catch (e) {
      throw new Error(`${main.name}: not valid JSON (${e.message})`);
    }
  }
  if (!gltf || typeof gltf !== 'object' || Array.isArray(gltf)) throw new Error(`${main.name}: not a glTF (its JSON is not an object)`);
  const byName = new Map(files.filter((f) => f !== main).map((f) => [f.name, f]));
  const inline = (list, what, typeOf) => {
    if (list === undefined) return;
    if (!Array.isArray(list)) throw new Error(`${main.name}: "${what}" is not an array`);
    list.forEach((item, i) => {
      if (!item || typeof item.uri !== 'string' || item.uri.startsWith('data:')) return;
      let uri = item.uri;
      try {
        uri = decodeURIComponent(uri);
      } catch {
        // kept as written
      }
      const file = byName.get(baseName(uri));
      if (!file) throw new Error(`${main.name}: ${what}[${i}] names '${item.uri}', which was not chosen: choose it with the glTF file`);
      item.uri = `data:${typeOf(file.name)};base64,${base64Of(file.bytes)}`;
    });
  };
  inline(gltf.buffers, 'buffers', () => 'application/octet-stream');
  inline(gltf.images, 'images', (n) => IMAGE_TYPES[extension(n)] || 'application/octet-stream');
  const stem = main.name.replace(/\.(gltf|glb)$/i, '').replace(/[^A-Za-z0-9_.-]/g, '_') || 'scene';
  return { name: stem, description: `${main.name}, opened in the page`, render: { gltf } };
}
