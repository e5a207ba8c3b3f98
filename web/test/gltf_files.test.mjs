// A glTF scene opened in the page (web/src/gltf_files.js): the chosen files become one render
// scene with everything inline, or an error naming the file and what is wrong.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { base64Of, checkGltfBytes, MAX_GLTF_BYTES, sceneFromFiles } from '../src/gltf_files.js';

const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', '..');
const bytesOf = (text) => new TextEncoder().encode(text);

/** A .glb of `json` with `bin` as its BIN chunk (both padded to 4 bytes as the format asks). */
function glb(json, bin) {
  const pad = (b, fill) => { const n = (4 - (b.length % 4)) % 4; return Buffer.concat([b, Buffer.alloc(n, fill)]); };
  const j = pad(Buffer.from(JSON.stringify(json)), 0x20);
  const b = pad(Buffer.from(bin), 0);
  const head = Buffer.alloc(12);
  head.writeUInt32LE(0x46546c67, 0); head.writeUInt32LE(2, 4); head.writeUInt32LE(12 + 8 + j.length + 8 + b.length, 8);
  const chunk = (type, data) => { const h = Buffer.alloc(8); h.writeUInt32LE(data.length, 0); h.writeUInt32LE(type, 4); return Buffer.concat([h, data]); };
  return new Uint8Array(Buffer.concat([head, chunk(0x4e4f534a, j), chunk(0x004e4942, b)]));
}

test('base64Of agrees with Node for lengths around the chunk size', () => {
  for (const n of [0, 1, 2, 3, 0x8000 - 1, 0x8000, 0x8000 + 1, 100000]) {
    const bytes = new Uint8Array(n).map((_, i) => (i * 131 + 7) & 255);
    assert.equal(base64Of(bytes), Buffer.from(bytes).toString('base64'), `${n} bytes`);
  }
});

test('a .gltf with its .bin chosen beside it becomes one inline scene', () => {
  const gltf = { asset: { version: '2.0' }, buffers: [{ uri: 'sub%20dir/mesh.bin', byteLength: 4 }], images: [{ uri: 'tex.png' }] };
  const scene = sceneFromFiles([
    { name: 'my scene.gltf', bytes: bytesOf(JSON.stringify(gltf)) },
    { name: 'mesh.bin', bytes: new Uint8Array([1, 2, 3, 4]) },
    { name: 'tex.png', bytes: new Uint8Array([137, 80]) },
  ]);
  assert.equal(scene.name, 'my_scene');
  assert.equal(scene.render.gltf.buffers[0].uri, 'data:application/octet-stream;base64,AQIDBA==');
  assert.equal(scene.render.gltf.images[0].uri, 'data:image/png;base64,iVA=');
});

test('a .glb becomes its JSON with the BIN chunk as buffer 0', () => {
  const scene = sceneFromFiles([{ name: 'box.glb', bytes: glb({ asset: { version: '2.0' }, buffers: [{ byteLength: 3 }] }, [9, 8, 7]) }]);
  assert.equal(scene.name, 'box');
  assert.equal(scene.render.gltf.buffers[0].uri, `data:application/octet-stream;base64,${Buffer.from([9, 8, 7]).toString('base64')}`);
});

test('the bundled quad_light_floor.gltf opens as the site would build it', () => {
  const file = path.join(ROOT, 'scenes', 'quad_light_floor.gltf');
  const scene = sceneFromFiles([{ name: 'quad_light_floor.gltf', bytes: new Uint8Array(fs.readFileSync(file)) }]);
  assert.equal(scene.render.gltf.asset.version, '2.0');
  for (const b of scene.render.gltf.buffers) assert.match(b.uri, /^data:/);
});

test('what cannot be opened is named', () => {
  const cases = [
    [[], /choose a \.glb file/],
    [[{ name: 'a.bin', bytes: new Uint8Array(1) }], /none of the chosen files is a \.gltf or \.glb/],
    [[{ name: 'a.gltf', bytes: bytesOf('{}') }, { name: 'b.glb', bytes: new Uint8Array(1) }], /choose one \.gltf or \.glb file, not 2/],
    [[{ name: 'a.gltf', bytes: bytesOf('{"asset": ') }], /a\.gltf: not valid JSON/],
    [[{ name: 'a.gltf', bytes: bytesOf('[1]') }], /a\.gltf: not a glTF/],
    [[{ name: 'a.gltf', bytes: bytesOf('{"buffers": [{"uri": "m.bin"}]}') }], /a\.gltf: buffers\[0\] names 'm\.bin', which was not chosen/],
    [[{ name: 'a.gltf', bytes: bytesOf('{"images": {"uri": "t.png"}}') }], /a\.gltf: "images" is not an array/],
    [[{ name: 'a.glb', bytes: bytesOf('not a glb file at all') }], /a\.glb: not a binary glTF/],
  ];
  for (const [files, message] of cases) assert.throws(() => sceneFromFiles(files), message);
  const truncated = glb({ buffers: [{ byteLength: 3 }] }, [1, 2, 3]).subarray(0, 30);
  assert.throws(() => sceneFromFiles([{ name: 't.glb', bytes: truncated }]), /t\.glb: /);
  assert.throws(() => checkGltfBytes(MAX_GLTF_BYTES + 1), /the page opens at most 64 MiB/);
  checkGltfBytes(MAX_GLTF_BYTES);
});
