// Writes the renderer's test scenes as self-contained glTF 2.0 files (buffers embedded as
// base64 data URIs) into scenes/: meters, y up, one perspective camera each. Emitters are
// one-sided quads (or triangles) whose counter-clockwise front faces the scene; their radiance
// is emissiveFactor (max component 1) times KHR_materials_emissive_strength. Non-metals are
// pure Lambertian (KHR_materials_specular specularFactor 0).
//
//   node scenes/tools/make_render_scenes.mjs
//
// Output is deterministic (no clocks, no randomness) and needs no npm packages.
import { writeFileSync } from 'node:fs';
import { dirname, join } from 'node:path';
import { fileURLToPath } from 'node:url';

const outDir = join(dirname(fileURLToPath(import.meta.url)), '..');

// --- Vectors -------------------------------------------------------------------------------

const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const mul = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [
  a[1] * b[2] - a[2] * b[1],
  a[2] * b[0] - a[0] * b[2],
  a[0] * b[1] - a[1] * b[0],
];
const length = (a) => Math.sqrt(dot(a, a));
const normalize = (a) => mul(a, 1 / length(a));
const deg = (d) => (d * Math.PI) / 180;

function check(condition, message) {
  if (!condition) throw new Error(message);
}

// --- Geometry: lists of vertices and counter-clockwise triangles ----------------------------

/// Parallelogram p0, p0 + u, p0 + u + v, p0 + v split into nu x nv cells; its front face
/// (counter-clockwise winding) points along u x v.
function grid(p0, u, v, nu = 1, nv = 1) {
  const positions = [];
  const indices = [];
  for (let j = 0; j <= nv; ++j)
    for (let i = 0; i <= nu; ++i) positions.push(add(p0, add(mul(u, i / nu), mul(v, j / nv))));
  const id = (i, j) => j * (nu + 1) + i;
  for (let j = 0; j < nv; ++j)
    for (let i = 0; i < nu; ++i) {
      indices.push(id(i, j), id(i + 1, j), id(i + 1, j + 1));
      indices.push(id(i, j), id(i + 1, j + 1), id(i, j + 1));
    }
  return { positions, indices };
}

/// Rectangle of size su x sv centred at c whose front faces along the unit normal n; t is a
/// unit tangent perpendicular to n (the su side).
function rect(c, n, t, su, sv, nu = 1, nv = 1) {
  check(Math.abs(dot(n, t)) < 1e-12, 'rect: tangent not perpendicular to the normal');
  const u = mul(t, su);
  const v = mul(cross(n, t), sv); // t x (n x t) = n: front along n
  return grid(sub(c, mul(add(u, v), 0.5)), u, v, nu, nv);
}

function merge(...parts) {
  const positions = [];
  const indices = [];
  for (const p of parts) {
    const base = positions.length;
    positions.push(...p.positions);
    indices.push(...p.indices.map((i) => i + base));
  }
  return { positions, indices };
}

/// Axis-aligned box centred at c with half sizes h, n x n cells per face; faces point outwards
/// (or inwards); `skip` lists faces to leave out, e.g. ['-y'].
function box(c, h, n, { inward = false, skip = [] } = {}) {
  const parts = [];
  const e = [[1, 0, 0], [0, 1, 0], [0, 0, 1]];
  const names = ['x', 'y', 'z'];
  for (let a = 0; a < 3; ++a)
    for (const s of [-1, 1]) {
      if (skip.includes((s < 0 ? '-' : '+') + names[a])) continue;
      const b = (a + 1) % 3;
      const d = (a + 2) % 3; // e_b x e_d = e_a
      let u = mul(e[b], 2 * h[b]);
      let v = mul(e[d], 2 * h[d]);
      if ((s > 0) === inward) [u, v] = [v, u]; // u x v = outward normal unless inward
      const faceCentre = add(c, mul(e[a], s * h[a]));
      parts.push(grid(sub(faceCentre, mul(add(u, v), 0.5)), u, v, n, n));
    }
  return merge(...parts);
}

/// Icosphere of radius r centred at c: the icosahedron with each triangle split in four
/// `level` times, vertices pushed onto the sphere; faces point outwards (or inwards).
function icosphere(c, r, level, inward = false) {
  const t = (1 + Math.sqrt(5)) / 2;
  let verts = [
    [-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
    [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1],
  ].map(normalize);
  let faces = [
    [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
    [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
    [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
  ];
  for (let l = 0; l < level; ++l) {
    const cache = new Map();
    const mid = (i, j) => {
      const key = i < j ? `${i},${j}` : `${j},${i}`;
      if (!cache.has(key)) {
        cache.set(key, verts.length);
        verts.push(normalize(add(verts[i], verts[j])));
      }
      return cache.get(key);
    };
    const next = [];
    for (const [a, b, d] of faces) {
      const ab = mid(a, b), bd = mid(b, d), da = mid(d, a);
      next.push([a, ab, da], [b, bd, ab], [d, da, bd], [ab, bd, da]);
    }
    faces = next;
  }
  for (const f of faces) {
    const [p, q, s] = f.map((i) => verts[i]);
    const outward = dot(cross(sub(q, p), sub(s, p)), add(add(p, q), s)) > 0;
    if (outward === inward) [f[1], f[2]] = [f[2], f[1]];
  }
  return { positions: verts.map((p) => add(c, mul(p, r))), indices: faces.flat() };
}

// --- glTF assembly -------------------------------------------------------------------------

/// Quaternion (x, y, z, w) of the rotation whose matrix has columns x, y, z.
function quatFromAxes(x, y, z) {
  const m = (r, col) => [x, y, z][col][r];
  const tr = m(0, 0) + m(1, 1) + m(2, 2);
  let q;
  if (tr > 0) {
    const s = Math.sqrt(tr + 1) * 2;
    q = [(m(2, 1) - m(1, 2)) / s, (m(0, 2) - m(2, 0)) / s, (m(1, 0) - m(0, 1)) / s, 0.25 * s];
  } else if (m(0, 0) > m(1, 1) && m(0, 0) > m(2, 2)) {
    const s = Math.sqrt(1 + m(0, 0) - m(1, 1) - m(2, 2)) * 2;
    q = [0.25 * s, (m(0, 1) + m(1, 0)) / s, (m(0, 2) + m(2, 0)) / s, (m(2, 1) - m(1, 2)) / s];
  } else if (m(1, 1) > m(2, 2)) {
    const s = Math.sqrt(1 + m(1, 1) - m(0, 0) - m(2, 2)) * 2;
    q = [(m(0, 1) + m(1, 0)) / s, 0.25 * s, (m(1, 2) + m(2, 1)) / s, (m(0, 2) - m(2, 0)) / s];
  } else {
    const s = Math.sqrt(1 + m(2, 2) - m(0, 0) - m(1, 1)) * 2;
    q = [(m(0, 2) + m(2, 0)) / s, (m(1, 2) + m(2, 1)) / s, 0.25 * s, (m(1, 0) - m(0, 1)) / s];
  }
  return q;
}

const yRotation = (degrees) => [0, Math.sin(deg(degrees) / 2), 0, Math.cos(deg(degrees) / 2)];

class Builder {
  constructor(description) {
    this.description = description;
    this.materials = [];
    this.meshes = [];
    this.nodes = [];
    this.accessors = [];
    this.bufferViews = [];
    this.chunks = [];
    this.byteLength = 0;
    this.cameras = [];
  }

  /// Metallic-roughness material; `radiance` (RGB, or a number for grey) becomes
  /// emissiveFactor = radiance / max component and emissiveStrength = max component.
  /// Dielectrics (metallic 0) get KHR_materials_specular specularFactor 0: no Fresnel layer,
  /// a pure Lambertian surface of albedo `base`, as the scenes' closed forms assume.
  material(name, { base = 0.5, metallic = 0, roughness = 1, radiance = 0, doubleSided } = {}) {
    const rgb = (v) => (Array.isArray(v) ? v : [v, v, v]);
    const m = {
      name,
      pbrMetallicRoughness: {
        baseColorFactor: [...rgb(base), 1],
        metallicFactor: metallic,
        roughnessFactor: roughness,
      },
    };
    const extensions = {};
    const le = rgb(radiance);
    const strength = Math.max(...le);
    if (strength > 0) {
      m.emissiveFactor = le.map((x) => x / strength);
      extensions.KHR_materials_emissive_strength = { emissiveStrength: strength };
    }
    if (metallic === 0) extensions.KHR_materials_specular = { specularFactor: 0 };
    if (Object.keys(extensions).length) m.extensions = extensions;
    if (doubleSided) m.doubleSided = true;
    this.materials.push(m);
    return this.materials.length - 1;
  }

  view(bytes, target) {
    const pad = (4 - (this.byteLength % 4)) % 4;
    if (pad) this.chunks.push(new Uint8Array(pad));
    this.byteLength += pad;
    this.bufferViews.push({
      buffer: 0,
      byteOffset: this.byteLength,
      byteLength: bytes.byteLength,
      target,
    });
    this.chunks.push(new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength));
    this.byteLength += bytes.byteLength;
    return this.bufferViews.length - 1;
  }

  /// A mesh of one triangle primitive on a node with an optional TRS transform.
  object(name, geometry, material, transform = {}) {
    const pos = new Float32Array(geometry.positions.flat());
    const min = [Infinity, Infinity, Infinity];
    const max = [-Infinity, -Infinity, -Infinity];
    for (let i = 0; i < pos.length; ++i) {
      min[i % 3] = Math.min(min[i % 3], pos[i]);
      max[i % 3] = Math.max(max[i % 3], pos[i]);
    }
    const vertexCount = geometry.positions.length;
    this.accessors.push({
      bufferView: this.view(pos, 34962),
      componentType: 5126,
      count: vertexCount,
      type: 'VEC3',
      min,
      max,
    });
    const position = this.accessors.length - 1;
    const small = vertexCount <= 65536;
    const idx = small ? new Uint16Array(geometry.indices) : new Uint32Array(geometry.indices);
    this.accessors.push({
      bufferView: this.view(idx, 34963),
      componentType: small ? 5123 : 5125,
      count: idx.length,
      type: 'SCALAR',
    });
    const indices = this.accessors.length - 1;
    this.meshes.push({
      name,
      primitives: [{ attributes: { POSITION: position }, indices, material, mode: 4 }],
    });
    this.nodes.push({ name, mesh: this.meshes.length - 1, ...transform });
    return this;
  }

  /// Perspective camera at eye looking at target (glTF cameras look along their -z, y up).
  camera(eye, target, yfov, up = [0, 1, 0]) {
    const f = normalize(sub(target, eye));
    const r = normalize(cross(f, up));
    const u = cross(r, f);
    this.cameras.push({ type: 'perspective', perspective: { yfov, znear: 0.001 } });
    this.nodes.push({
      name: 'camera',
      camera: this.cameras.length - 1,
      translation: eye,
      rotation: quatFromAxes(r, u, mul(f, -1)),
    });
    return this;
  }

  gltf() {
    const bin = Buffer.concat(
      this.chunks.map((c) => Buffer.from(c.buffer, c.byteOffset, c.byteLength)));
    const used = new Set();
    for (const m of this.materials) for (const e of Object.keys(m.extensions || {})) used.add(e);
    return {
      asset: { version: '2.0', generator: 'mcplay scenes/tools/make_render_scenes.mjs' },
      ...(used.size ? { extensionsUsed: [...used].sort() } : {}),
      scene: 0,
      scenes: [{
        name: 'scene',
        nodes: this.nodes.map((_, i) => i),
        extras: { description: this.description },
      }],
      nodes: this.nodes,
      cameras: this.cameras,
      meshes: this.meshes,
      materials: this.materials,
      accessors: this.accessors,
      bufferViews: this.bufferViews,
      buffers: [{
        byteLength: bin.length,
        uri: 'data:application/octet-stream;base64,' + bin.toString('base64'),
      }],
    };
  }
}

/// JSON with arrays of numbers or strings on one line.
function format(value, indent = '') {
  if (Array.isArray(value)) {
    if (value.every((x) => typeof x !== 'object'))
      return '[' + value.map((x) => JSON.stringify(x)).join(', ') + ']';
    const inner = indent + '  ';
    return '[\n' + value.map((x) => inner + format(x, inner)).join(',\n') + '\n' + indent + ']';
  }
  if (value && typeof value === 'object') {
    const inner = indent + '  ';
    const keys = Object.keys(value).filter((k) => value[k] !== undefined);
    const members = keys.map((k) => inner + JSON.stringify(k) + ': ' + format(value[k], inner));
    return '{\n' + members.join(',\n') + '\n' + indent + '}';
  }
  return JSON.stringify(value);
}

function write(name, builder) {
  const text = format(builder.gltf()) + '\n';
  writeFileSync(join(outDir, name), text);
  const triangles = builder.accessors
    .filter((a) => a.type === 'SCALAR')
    .reduce((s, a) => s + a.count / 3, 0);
  console.log(`${name}: ${triangles} triangles, ${text.length} bytes`);
}

// --- Ray checks for the Veach scene --------------------------------------------------------

/// Distance along the ray o + t d to the parallelogram p0 + a u + b v (a, b in [0, 1]), or
/// Infinity.
function hitParallelogram(o, d, p0, u, v) {
  const n = cross(u, v);
  const denom = dot(d, n);
  if (Math.abs(denom) < 1e-15) return Infinity;
  const t = dot(sub(p0, o), n) / denom;
  if (!(t > 1e-9)) return Infinity;
  const q = sub(add(o, mul(d, t)), p0);
  const a = dot(cross(q, v), n) / dot(n, n);
  const b = dot(cross(u, q), n) / dot(n, n);
  return a >= 0 && a <= 1 && b >= 0 && b <= 1 ? t : Infinity;
}

// --- The scenes ----------------------------------------------------------------------------

const X = [1, 0, 0];
const UP = [0, 1, 0];
const DOWN = [0, -1, 0];

// 1. A 1 x 1 m light at height 1 facing down over a 4 x 4 m grey floor. The camera, below the
// light's plane, looks down so that every pixel (aspect up to 1.5) sees the floor: a pixel's
// value is base / pi times the irradiance of Lambert's polygon formula.
{
  const b = new Builder(
    '1 x 1 m light (radiance 5) at height 1 facing down over a 4 x 4 m floor (base colour 0.5)');
  const floor = b.material('floor', { base: 0.5 });
  const light = b.material('light', { base: 0, radiance: 5 });
  b.object('floor', rect([0, 0, 0], UP, X, 4, 4), floor);
  b.object('light', rect([0, 1, 0], DOWN, X, 1, 1), light);
  // Centre ray 34 degrees below the horizon; yfov 0.6 rad keeps the top edge (16.8 degrees
  // down) under the floor's far edge (14.8 degrees down) and the light (above the camera).
  const eye = [0, 0.95, 1.6];
  b.camera(eye, [0, 0, eye[2] - eye[1] / Math.tan(deg(34))], 0.6);
  write('quad_light_floor.gltf', b);
}

// 2. The Cornell box [Goral84] (Cornell data: 556 x 548.8 x 559.2 mm) as a 1 m cube with the
// open side at +z: red wall left (x = -0.5), green right, light just under the ceiling.
{
  const b = new Builder('Cornell box, 1 m cube, open at +z, light radiance (17, 12, 4)');
  const white = b.material('white', { base: 0.73 });
  const red = b.material('red', { base: [0.63, 0.065, 0.05] });
  const green = b.material('green', { base: [0.14, 0.45, 0.09] });
  const light = b.material('light', { base: 0.78, radiance: [17, 12, 4] });
  const n = 16;
  const Z = [0, 0, 1];
  b.object('floor', rect([0, 0, 0], UP, X, 1, 1, n, n), white);
  b.object('ceiling', rect([0, 1, 0], DOWN, X, 1, 1, n, n), white);
  b.object('back wall', rect([0, 0.5, -0.5], Z, X, 1, 1, n, n), white);
  b.object('red wall', rect([-0.5, 0.5, 0], X, Z, 1, 1, n, n), red);
  b.object('green wall', rect([0.5, 0.5, 0], [-1, 0, 0], Z, 1, 1, n, n), green);
  // Unit cubes without bottoms, placed by node transforms (165 mm and 165 x 330 mm blocks).
  const block = box([0, 0, 0], [0.5, 0.5, 0.5], 4, { skip: ['-y'] });
  b.object('short block', block, white,
    { translation: [0.18, 0.15, 0.22], rotation: yRotation(-17), scale: [0.3, 0.3, 0.3] });
  b.object('tall block', block, white,
    { translation: [-0.18, 0.3, -0.15], rotation: yRotation(17), scale: [0.3, 0.6, 0.3] });
  b.object('light', rect([0, 0.999, 0], DOWN, X, 0.25, 0.2), light);
  // Cornell camera: 800 mm in front of the opening at mid height, field of view 39.3 degrees.
  b.camera([0, 0.5, 1.94], [0, 0.5, 0], deg(39.3));
  write('cornell_box.gltf', b);
}

// 3. Veach's multiple importance sampling scene [Veach97, fig. 9.2]: four metal plates of GGX
// alpha 0.005, 0.02, 0.05, 0.1 (back to front; roughness = sqrt(alpha)), each tilted so that it
// mirrors the row of lights toward the camera, and four square lights of sides 0.02, 0.06,
// 0.2, 0.6 m with equal power (radiance x area = 1.44).
{
  const b = new Builder('Veach MIS: four plates (alpha 0.005 .. 0.1), four lights of equal power');
  const dark = b.material('dark', { base: 0.1 });
  const eye = [0, 2, 15];
  const lights = [[-3, 0.02], [-1, 0.06], [1, 0.2], [3, 0.6]];
  const lightNormal = normalize([0, -3, 1.7]); // toward the plates (and the camera)
  const plates = [
    { centre: [0, -2.35, -0.2], alpha: 0.005 },
    { centre: [0, -2.8, 1.05], alpha: 0.02 },
    { centre: [0, -3.25, 2.3], alpha: 0.05 },
    { centre: [0, -3.7, 3.55], alpha: 0.1 },
  ];
  const width = 8, depth = 1;
  const quads = plates.map(({ centre, alpha }, i) => {
    // Normal halfway between the directions to the camera and to the middle of the light row.
    const n = normalize(add(normalize(sub(eye, centre)), normalize(sub([0, 0, 0], centre))));
    const mat = b.material(`plate ${i} (alpha ${alpha})`,
      { base: 0.8, metallic: 1, roughness: Math.sqrt(alpha) });
    const g = rect(centre, n, X, width, depth);
    b.object(`plate ${i}`, g, mat);
    const [p0, p1, p2] = g.positions; // grid order: p0, p0 + u, p0 + v, p0 + u + v
    return { p0, u: sub(p1, p0), v: sub(p2, p0), n, centre };
  });
  lights.forEach(([x, side], i) => {
    const mat = b.material(`light ${i} (${side} m)`, { base: 0, radiance: 1.44 / (side * side) });
    b.object(`light ${i}`, rect([x, 0, 0], lightNormal, X, side, side), mat);
  });
  b.object('floor', rect([0, -4, 6], UP, X, 20, 20), dark);
  b.object('back wall', rect([0, 2, -4], [0, 0, 1], X, 20, 12), dark);
  const target = [0, -2.2, 2.5];
  const yfov = 0.46;
  b.camera(eye, target, yfov);
  // Each plate must mirror each light's centre toward the camera at a point inside the plate,
  // seen by the camera (aspect 1) and not hidden by another plate.
  const f = normalize(sub(target, eye));
  const r = normalize(cross(f, UP));
  const u = cross(r, f);
  const tanHalf = Math.tan(yfov / 2);
  quads.forEach((q, i) => {
    for (const [x] of lights) {
      const mirrored = sub(eye, mul(q.n, 2 * dot(sub(eye, q.centre), q.n)));
      const d = sub([x, 0, 0], mirrored);
      const t = hitParallelogram(mirrored, d, q.p0, q.u, q.v);
      check(t < 1, `veach: plate ${i} does not mirror the light at x = ${x}`);
      const point = add(mirrored, mul(d, t));
      const view = sub(point, eye);
      const depthAlong = dot(view, f);
      const half = tanHalf * depthAlong;
      check(Math.abs(dot(view, r)) < half && Math.abs(dot(view, u)) < half,
        `veach: highlight of the light at x = ${x} on plate ${i} is out of view`);
      quads.forEach((o, k) => {
        const hidden = k !== i && hitParallelogram(eye, view, o.p0, o.u, o.v) < 1;
        check(!hidden, `veach: plate ${k} hides plate ${i}`);
      });
    }
  });
  write('veach_mis.gltf', b);
}

// 4. A 1 mm square light of radiance 1e6 (power pi W, like a 1 m^2 light of radiance 1) over a
// floor and a box.
{
  const b = new Builder('1 mm square light, radiance 1e6, over a floor and a box');
  const grey = b.material('grey', { base: 0.5 });
  const light = b.material('light', { base: 0, radiance: 1e6 });
  b.object('floor', rect([0, 0, 0], UP, X, 4, 4), grey);
  b.object('box', box([0, 0.25, 0], [0.25, 0.25, 0.25], 1, { skip: ['-y'] }), grey);
  b.object('light', rect([0.6, 1.5, 0.3], DOWN, X, 0.001, 0.001), light);
  b.camera([0, 1.6, 2.6], [0, 0.2, 0], 0.7);
  write('tiny_bright_light.gltf', b);
}

// 5. A metal plate of roughness 0.035 (GGX alpha 1.225e-3, just above a 1e-3 mirror threshold)
// mirroring a 0.3 m light into the camera, over a diffuse floor.
{
  const b = new Builder(
    'near-mirror plate (roughness 0.035) reflecting a 0.3 m light (radiance 10)');
  const grey = b.material('floor', { base: 0.5 });
  const metal = b.material('near mirror', { base: 0.9, metallic: 1, roughness: 0.035 });
  const light = b.material('light', { base: 0, radiance: 10 });
  const centre = [0, 0.01, 0];
  const lightCentre = [-0.6, 1.2, 0];
  b.object('floor', rect([0, 0, 0], UP, X, 4, 4), grey);
  b.object('plate', rect(centre, UP, X, 1, 1), metal);
  const toPlate = normalize(sub(centre, lightCentre));
  b.object('light', rect(lightCentre, toPlate, [0, 0, 1], 0.3, 0.3), light);
  const reflected = [toPlate[0], -toPlate[1], toPlate[2]]; // mirror about the plate (y up)
  b.camera(add(centre, mul(reflected, 2)), centre, 0.6);
  write('near_mirror.gltf', b);
}

// 6. A 2 x 10 m floor lit by a 1 x 1 m light beyond its end, tilted 2 degrees from the floor's
// plane toward it: the floor sees the light, and the light the floor, at grazing angles.
{
  const b = new Builder('2 x 10 m floor lit by a light quad tilted 2 degrees from its plane');
  const grey = b.material('floor', { base: 0.5 });
  const light = b.material('light', { base: 0, radiance: 500 });
  b.object('floor', rect([0, 0, -5], UP, X, 2, 10, 2, 20), grey);
  const n = [0, -Math.cos(deg(2)), -Math.sin(deg(2))]; // down, tipped toward the floor (-z)
  b.object('light', rect([0, 0.05, 0.7], n, X, 1, 1), light);
  b.camera([0, 1.2, 2], [0, 0, -2.5], 0.7);
  write('grazing_light.gltf', b);
}

// 7. A 0.5 m light facing down 1e-4 m above a diffuse floor.
{
  const b = new Builder('0.5 m light (radiance 1) facing down 1e-4 m above a floor');
  const grey = b.material('floor', { base: 0.5 });
  const light = b.material('light', { base: 0, radiance: 1 });
  b.object('floor', rect([0, 0, 0], UP, X, 2, 2), grey);
  b.object('light', rect([0, 1e-4, 0], DOWN, X, 0.5, 0.5), light);
  b.camera([0, 0.9, 1.3], [0, 0, 0.15], 0.6);
  write('touching_light.gltf', b);
}

// 8. Two perpendicular unit squares sharing the edge y = z = 0: the floor square (z in [0, 1])
// is diffuse, the wall square (y in [0, 1]) emits radiance 1 toward it (form factor 0.2000437).
{
  const b = new Builder('perpendicular unit squares sharing an edge: diffuse floor, emissive wall');
  const grey = b.material('floor', { base: 0.5 });
  const light = b.material('wall light', { base: 0, radiance: 1 });
  b.object('floor', grid([0, 0, 1], [1, 0, 0], [0, 0, -1]), grey); // front +y
  b.object('wall', grid([0, 0, 0], [1, 0, 0], [0, 1, 0]), light); // front +z
  b.camera([0.5, 1.3, 2.3], [0.5, 0.1, 0.45], 0.7);
  write('perpendicular_plates.gltf', b);
}

// 9. Furnace: a closed 2 m cube facing inwards whose faces all have base colour 0.5 and
// radiance 1; every pixel sees radiance 1 / (1 - 0.5) = 2.
{
  const b = new Builder('closed cube, inward faces, base colour 0.5 and radiance 1 everywhere');
  const m = b.material('furnace', { base: 0.5, radiance: 1 });
  b.object('cube', box([0, 0, 0], [1, 1, 1], 4, { inward: true }), m);
  b.camera([0, 0, 0.5], [0, 0, -1], 1.0);
  write('furnace_box.gltf', b);
}

// 10. A black inward-facing icosphere of radiance 1 around a 0.2 m diffuse square of base colour
// 0.8: the square's radiance is 0.8 / pi * (pi * 1) = 0.8.
{
  const b = new Builder('black emitting icosphere (radiance 1) around a diffuse square (base 0.8)');
  const sky = b.material('enclosure', { base: 0, radiance: 1 });
  const grey = b.material('square', { base: 0.8 });
  b.object('enclosure', icosphere([0, 0, 0], 1, 3, true), sky);
  b.object('square', rect([0, 0, 0], [0, 0, 1], X, 0.2, 0.2), grey);
  b.camera([0, 0, 0.6], [0, 0, 0], 0.5);
  write('sphere_interior.gltf', b);
}

// 11. Many lights of different power and distance (resampled importance sampling's case): a
// 1 x 1 m light of radiance 100 high in a corner (98% of the power) and eight dim 0.15 m lights
// of radiance 40 (warm and cool) 0.3 m above a 6 x 6 m floor, where each outshines the far one.
{
  const b = new Builder(
    'a bright light 5 m up (1 m, radiance 100), eight dim ones 0.3 m up (0.15 m, radiance 40)');
  const floor = b.material('floor', { base: 0.6 });
  const wall = b.material('wall', { base: 0.4 });
  b.object('floor', rect([0, 0, 0], UP, X, 6, 6), floor);
  b.object('back wall', rect([0, 1.5, -3], [0, 0, 1], X, 6, 3), wall);
  const far = b.material('far light', { base: 0, radiance: 100 });
  b.object('far light', rect([2, 5, -2], DOWN, X, 1, 1), far);
  const warm = b.material('warm light', { base: 0, radiance: [40, 30, 18] });
  const cool = b.material('cool light', { base: 0, radiance: [18, 30, 40] });
  for (let i = 0; i < 8; ++i) {
    const x = -2.1 + 0.6 * i;
    const z = i % 2 ? -1.2 : 0.4;
    b.object(`near light ${i}`, rect([x, 0.3, z], DOWN, X, 0.15, 0.15), i % 2 ? cool : warm);
  }
  b.camera([0, 2.8, 4.2], [0, 0, -0.6], 0.8);
  write('many_lights.gltf', b);
}

// 12. Where the unshadowed target misleads: a bright 1 m light (radiance 50) above a 3 x 3 m
// slab that hides it from the floor the camera sees, and a dim 0.5 m light (radiance 5) beside
// the slab that lights that floor. Resampling by f Le cos (visibility left out) keeps the
// hidden light's candidates, as light selection by power does.
{
  const b = new Builder(
    'a bright light hidden above a slab (radiance 50), a dim one beside it (radiance 5)');
  const floor = b.material('floor', { base: 0.6 });
  const slab = b.material('slab', { base: 0.3 });
  b.object('floor', rect([0, 0, 0], UP, X, 4, 4), floor);
  b.object('slab', box([0, 1.05, 0], [1.5, 0.05, 1.5], 1), slab);
  const bright = b.material('hidden light', { base: 0, radiance: 50 });
  b.object('hidden light', rect([0, 1.4, 0], DOWN, X, 1, 1), bright);
  const dim = b.material('visible light', { base: 0, radiance: 5 });
  const tilted = normalize([1, -1, 0]);
  b.object('visible light', rect([-1.9, 0.7, 0], tilted, [0, 0, 1], 0.5, 0.5), dim);
  b.camera([0.3, 0.75, 2.6], [0, 0, 0], 0.8);
  write('occluded_light.gltf', b);
}
