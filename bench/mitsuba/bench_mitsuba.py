#!/usr/bin/env python3
"""mcplay's renderer beside Mitsuba 3 on the same glTF scenes: time per image, relative MSE
and efficiency at 16, 64 and 256 spp, each renderer scored against its own converged reference.

  build/mitsuba-venv/bin/python bench/mitsuba/bench_mitsuba.py [--mcplay build/mcplay]
      [--spp 16,64,256] [--ref-spp 4096] [--threads 2] [--quick] [--sobol] [--scalar] [--best]
      [--widths]

`make bench-mitsuba` installs what it needs (Debian's libllvm19 for drjit 1.5, Mitsuba 3.9.1 in a
virtual environment under build/) and runs this. Not part of `make test`.

The Mitsuba scene is built here from the glTF file alone (our own reader: node transforms,
triangles with flat face normals, the camera; Lambertian materials as `twosided(diffuse)`,
metals as `roughconductor` GGX with alpha = roughness^2 and F = 1, emissive materials as one-sided
`area` emitters). Strategies: light sampling (Mitsuba `direct` with emitter samples only; mcplay
`light_solid_angle`), BSDF sampling (`direct` with BSDF samples only; mcplay `bsdf`), MIS (`direct`,
one of each, power heuristic; mcplay `mis_power`) and path tracing (Mitsuba `path` with
max_depth = mcplay's bounces + 1, the same Russian-roulette depth; mcplay `path`).

Relative MSE of an image I against a reference R (two halves R1, R2 of different seeds, R their
mean): mean over pixels and channels of ((I - R)^2 - v) / (R^2 + eps), v = (R1 - R2)^2 / 4 the
unbiased variance of R's pixel (the reference's own noise is not counted as error), eps = 1e-2
(mean luminance of R)^2 [RousselleKnausZwicker11]. Efficiency = 1 / (relative MSE x seconds).
With --images K the relative MSE is the mean over K images of different seeds. Seconds are
render time only, the smallest of those runs (at least two) (Mitsuba's after a first render of the same
size compiled its kernels; mcplay's from its result JSON). The two renderers' references are
also compared with each other (the same relative MSE), which says whether they render the same
image. With --sobol, mcplay also renders every cell with its Owen-scrambled Sobol' pixel sampler
(`--pixel-sampler sobol`; the default is stratified), scored against the same mcplay reference:
one more column, and its own efficiency ratio against Mitsuba. With --best, mcplay also renders
each class with its best estimator (MCPLAY_BEST: padded Sobol' pixels with the samples spread
over the pixels by their neighbours' error, the emission seen directly split at emitter edges,
the candidates and light samples per camera sample chosen by timed pilots, their time counted),
one more column the same way. With --scalar, Mitsuba's
`scalar_rgb` variant renders every cell too: the same integrators one sample at a time per
thread, as mcplay runs, against `llvm_ad_rgb`'s kernels that run a SIMD register's width of
samples at once. It is scored against the `llvm_ad_rgb` reference (the same estimator), and
mcplay's time and efficiency are given over its own. --widths times only, at the largest --spp:
mcplay, `scalar_rgb`, and `llvm_ad_rgb` with its kernels compiled for 4, 8 and the machine's own
number of lanes (see width_child).

A relative MSE marked `!` (with the number) rests on fewer than 10 effective pixel terms, Kish's
(sum t)^2 / sum t^2 over the pixel terms t of the cell's images: a few rare large pixel errors
(a camera ray that hits a small bright emitter from a pixel that barely sees it, a heavy-tailed
BSDF-sampled weight) rule it, so one run of the cell says little and its efficiency ratio is
noise; rerun with more --images. mcplay's studies flag such levels `rare_large_errors` by the
same rule. The summary gives the medians with and without the marked cells. A relative MSE in
parentheses is below the reference's own noise (the mean of v / (R^2 + eps), what is
subtracted): it cannot be told from 0 with this reference, and its efficiency ratio says only
"far ahead".
"""
import argparse
import base64
import ctypes
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', '..'))

# scene, glTF, width, height, strategies (mcplay estimator name for each)
SCENES = [
    ('quad_light_floor', 'quad_light_floor.gltf', 320, 240, ['light', 'bsdf', 'mis']),
    ('cornell_box', 'cornell_box.gltf', 128, 128, ['light', 'bsdf', 'mis', 'path']),
    ('veach_mis', 'veach_mis.gltf', 320, 180, ['light', 'bsdf', 'mis']),
]
MCPLAY_ESTIMATOR = {'light': 'light_solid_angle', 'bsdf': 'bsdf', 'mis': 'mis_power', 'path': 'path'}
# mcplay's best per class (--best), padded Sobol' pixels throughout. Light sampling: resampled light
# samples (ris: candidates drawn as light_solid_angle draws them, the target lum(f Le cos) with
# the BSDF in it; its pilot, measuring with the render's Sobol' pixels, may choose M = 1. Plain
# light_solid_angle won on the Cornell box and lost on Veach's plates at 64 and 256 spp:
# docs/performance-notes.md). Path tracing: each
# vertex's light sample resampled the same way. MIS: light
# samples per camera sample (splitting). Each count chosen by a timed pilot (src/render/
# splitting.h; its time counted in the image's). Every class spends its samples over the pixels
# adaptively (pixel_allocation, src/render/adaptive.h: a first pass of half the spp, the rest by
# the neighbours' error), which needs the padded Sobol' sampler. BSDF sampling alone has no such
# choice: its row is a pure speed contest.
MCPLAY_BEST = {
    'light': {'strategy': 'ris', 'light_selection': 'power', 'light_sampling': 'solid_angle',
              'candidates': 'auto', 'pixel_sampler': 'padded_sobol', 'pixel_allocation': 'adaptive'},
    'mis': {'strategy': 'mis_power', 'light_samples': 'auto', 'pixel_sampler': 'padded_sobol',
            'pixel_allocation': 'adaptive'},
    'path': {'strategy': 'path', 'max_depth': 5, 'candidates': 'auto',
             'pixel_sampler': 'padded_sobol', 'pixel_allocation': 'adaptive'},
}
# Every class: the emission seen directly from BEST_EMISSION_SAMPLES camera rays per sample
# (emission_samples; the edges of a directly seen light, a pixel's coverage, are camera-sample
# noise that neither light nor BSDF samples touch). A fixed count: the timed pilot ("auto")
# sees too few rare edge pixels in its 2-spp bands (docs/performance-notes.md).
BEST_EMISSION_SAMPLES = 16
PATH_BOUNCES, PATH_RR = 5, 3  # mcplay's path defaults (src/render/integrator.h)


# --------------------------------------------------------------------------------------------
# glTF, read for Mitsuba


def quat_matrix(q):
    x, y, z, w = q
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), 0],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), 0],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), 0],
        [0, 0, 0, 1]])


def node_matrix(node):
    if 'matrix' in node:
        return np.array(node['matrix'], dtype=float).reshape(4, 4).T  # column-major
    t = np.eye(4)
    t[:3, 3] = node.get('translation', [0, 0, 0])
    r = quat_matrix(node.get('rotation', [0, 0, 0, 1]))
    s = np.diag(list(node.get('scale', [1, 1, 1])) + [1])
    return t @ r @ s


def buffer_bytes(gltf, i, folder):
    uri = gltf['buffers'][i]['uri']
    if uri.startswith('data:'):
        return base64.b64decode(uri.split(',', 1)[1])
    with open(os.path.join(folder, uri), 'rb') as f:
        return f.read()


def accessor(gltf, i, buffers):
    a = gltf['accessors'][i]
    view = gltf['bufferViews'][a['bufferView']]
    data = buffers[view['buffer']]
    comps = {'SCALAR': 1, 'VEC2': 2, 'VEC3': 3, 'VEC4': 4}[a['type']]
    dtype = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}[a['componentType']]
    size = np.dtype(dtype).itemsize
    stride = view.get('byteStride', comps * size)
    start = view.get('byteOffset', 0) + a.get('byteOffset', 0)
    rows = [np.frombuffer(data, dtype, comps, start + k * stride) for k in range(a['count'])]
    return np.array(rows)


def gltf_scene(path):
    """Triangles in world space per primitive with its material, and the camera's matrix and yfov."""
    with open(path) as f:
        gltf = json.load(f)
    folder = os.path.dirname(path)
    buffers = [buffer_bytes(gltf, i, folder) for i in range(len(gltf.get('buffers', [])))]
    prims, camera = [], None

    def visit(n, parent):
        node = gltf['nodes'][n]
        m = parent @ node_matrix(node)
        nonlocal camera
        if 'camera' in node:
            camera = (m, gltf['cameras'][node['camera']]['perspective']['yfov'])
        if 'mesh' in node:
            for p in gltf['meshes'][node['mesh']]['primitives']:
                pos = accessor(gltf, p['attributes']['POSITION'], buffers).astype(float)
                world = (m @ np.c_[pos, np.ones(len(pos))].T).T[:, :3]
                idx = (accessor(gltf, p['indices'], buffers).reshape(-1, 3) if 'indices' in p
                       else np.arange(len(pos)).reshape(-1, 3))
                prims.append((world, idx.astype(np.int32), gltf['materials'][p.get('material', 0)]))
        for c in node.get('children', []):
            visit(c, m)

    for n in gltf['scenes'][gltf.get('scene', 0)]['nodes']:
        visit(n, np.eye(4))
    return prims, camera


def write_ply(path, vertices, faces):
    with open(path, 'wb') as f:
        f.write((f'ply\nformat binary_little_endian 1.0\nelement vertex {len(vertices)}\n'
                 'property float x\nproperty float y\nproperty float z\n'
                 f'element face {len(faces)}\nproperty list uchar int vertex_indices\nend_header\n').encode())
        f.write(np.asarray(vertices, '<f4').tobytes())
        for tri in faces:
            f.write(struct.pack('<Biii', 3, *[int(v) for v in tri]))


def mitsuba_scene(mi, gltf_path, width, height, folder):
    prims, (cam, yfov) = gltf_scene(gltf_path)
    scene = {'type': 'scene'}
    for k, (v, f, mat) in enumerate(prims):
        pbr = mat.get('pbrMetallicRoughness', {})
        base = pbr.get('baseColorFactor', [1, 1, 1, 1])[:3]
        if pbr.get('metallicFactor', 1) >= 0.5:
            r = pbr.get('roughnessFactor', 1)
            bsdf = {'type': 'roughconductor', 'distribution': 'ggx', 'alpha': r * r, 'material': 'none',
                    'specular_reflectance': {'type': 'rgb', 'value': base}}
        else:
            bsdf = {'type': 'twosided', 'bsdf': {'type': 'diffuse', 'reflectance': {'type': 'rgb', 'value': base}}}
        ply = os.path.join(folder, f'mesh{k}.ply')
        write_ply(ply, v, f)
        shape = {'type': 'ply', 'filename': ply, 'face_normals': True, 'bsdf': bsdf}
        emissive = mat.get('emissiveFactor')
        if emissive and max(emissive) > 0:
            strength = mat.get('extensions', {}).get('KHR_materials_emissive_strength', {}).get('emissiveStrength', 1)
            shape['emitter'] = {'type': 'area', 'radiance': {'type': 'rgb', 'value': [c * strength for c in emissive]}}
        scene[f'shape{k}'] = shape
    # glTF cameras look down -z with +x right; Mitsuba's look down +z with +x left
    to_world = cam @ np.diag([-1, 1, -1, 1])
    scene['sensor'] = {
        'type': 'perspective', 'fov': math.degrees(yfov), 'fov_axis': 'y', 'near_clip': 1e-3,
        'to_world': mi.ScalarTransform4f(to_world.tolist()),
        'film': {'type': 'hdrfilm', 'width': width, 'height': height, 'rfilter': {'type': 'box'},
                 'pixel_format': 'rgb'},
        'sampler': {'type': 'independent'},
    }
    return scene


MITSUBA_INTEGRATOR = {
    'light': {'type': 'direct', 'emitter_samples': 1, 'bsdf_samples': 0},
    'bsdf': {'type': 'direct', 'emitter_samples': 0, 'bsdf_samples': 1},
    'mis': {'type': 'direct', 'emitter_samples': 1, 'bsdf_samples': 1},
    'path': {'type': 'path', 'max_depth': PATH_BOUNCES + 1, 'rr_depth': PATH_RR + 1},
}


class Mitsuba:
    """One Mitsuba variant's scenes; the variant is made active before each use, so that two
    variants can be timed in one process."""

    def __init__(self, mi, variant, gltf, width, height, folder):
        self.mi, self.variant = mi, variant
        mi.set_variant(variant)
        self.base = mitsuba_scene(mi, gltf, width, height, folder)
        self.scenes = {}

    def scene(self, strategy):
        self.mi.set_variant(self.variant)
        if strategy not in self.scenes:
            self.scenes[strategy] = self.mi.load_dict({**self.base, 'integrator': MITSUBA_INTEGRATOR[strategy]})
        return self.scenes[strategy]

    def render(self, strategy, spp, seed):
        s = self.scene(strategy)
        t0 = time.perf_counter()
        img = self.mi.render(s, spp=spp, seed=seed)
        img = np.array(img, dtype=np.float64)  # waits for the kernel
        return img[:, :, :3], time.perf_counter() - t0


# --------------------------------------------------------------------------------------------
# mcplay, through its CLI


def read_pfm(path):
    with open(path, 'rb') as f:
        assert f.readline().strip() == b'PF'
        w, h = map(int, f.readline().split())
        scale = float(f.readline())
        data = np.frombuffer(f.read(), '<f4' if scale < 0 else '>f4').astype(np.float64)
    return data.reshape(h, w, 3)[::-1]


class Mcplay:
    def __init__(self, exe, scene, width, height, threads, folder, pixel_sampler=None, best=False):
        self.exe, self.scene, self.width, self.height = exe, scene, width, height
        self.threads, self.folder, self.pixel_sampler = threads, folder, pixel_sampler
        self.best, self.light_samples, self.candidates = best, [], []

    def render(self, strategy, spp, seed):
        out = os.path.join(self.folder, 'mcplay.pfm')
        estimator = MCPLAY_ESTIMATOR[strategy]
        if self.best and strategy in MCPLAY_BEST:
            estimator = json.dumps(MCPLAY_BEST[strategy])
        cmd = [self.exe, 'render', self.scene, '--scenes', os.path.join(ROOT, 'scenes'),
               '--estimator', estimator, '--spp', str(spp), '--seed', str(seed),
               '--width', str(self.width), '--height', str(self.height), '--threads', str(self.threads),
               '--out', out, '--format', 'json', '--no-cache']
        if self.pixel_sampler:
            cmd += ['--pixel-sampler', self.pixel_sampler]
        if strategy == 'path':  # the path scene: the Cornell box's path estimators
            cmd[2] = 'cornell_box_path'
            if estimator == MCPLAY_ESTIMATOR[strategy]:
                cmd[6] = 'path_mis'
        r = subprocess.run(cmd, check=True, capture_output=True, text=True)
        result = json.loads(r.stdout)
        est = result['estimator']
        self.light_samples.append(est.get('light_samples', 1))
        self.candidates.append(est.get('candidates', 1))
        # The pilots that chose the counts are part of the image's cost.
        pilots = sum(est[k]['seconds'] for k in ('split_pilot', 'candidate_pilot', 'emission_pilot') if k in est)
        return read_pfm(out), result['seconds'] + pilots


# --------------------------------------------------------------------------------------------
# Scoring


def luminance(img):
    return 0.2126 * img[..., 0] + 0.7152 * img[..., 1] + 0.0722 * img[..., 2]


def reference(renderer, strategy, spp):
    """The converged reference as two halves of different seeds: (mean, per-pixel variance)."""
    a, _ = renderer.render(strategy, spp // 2, 1_000_001)
    b, _ = renderer.render(strategy, spp // 2, 2_000_003)
    return (a + b) / 2, (a - b) ** 2 / 4


def relative(x, ref, *others):
    """x / (R^2 + eps) per pixel and channel, 0 where x, R or any of `others` is not finite."""
    eps = 1e-2 * np.mean(luminance(ref)) ** 2
    ok = np.isfinite(x) & np.isfinite(ref)
    for o in others:
        ok &= np.isfinite(o)
    return np.where(ok, x / (ref ** 2 + eps), 0.0)


def relative_mse(img, ref, ref_var):
    return float(np.mean(relative((img - ref) ** 2 - ref_var, ref, img)))


def reference_noise(ref, ref_var):
    """The reference's own noise in relative MSE (what relative_mse subtracts): a relative MSE
    below it cannot be told from 0 with this reference."""
    return float(np.mean(relative(ref_var, ref)))


def pixel_terms(img, ref):
    """Each pixel's share of the relative MSE (before the reference's noise is subtracted)."""
    return relative((img - ref) ** 2, ref, img).sum(axis=-1).ravel()


# Below this many effective pixel terms a cell's relative MSE is ruled by a few rare large
# pixel errors (mcplay's studies flag such levels rare_large_errors with the same rule).
MIN_EFFECTIVE_TERMS = 10


def effective_terms(terms):
    """Kish's effective number of terms, (sum t)^2 / sum t^2 (Kish 1965)."""
    t = np.concatenate(terms)
    total, squares = float(t.sum()), float((t ** 2).sum())
    return total / math.sqrt(squares) * (total / math.sqrt(squares)) if squares > 0 else math.inf


def scored(renderer, strategy, spp, ref, images):
    """The mean relative MSE of `images` images of different seeds (one image's is noisy where
    the weights are heavy-tailed), the effective number of pixel terms behind it, and the
    smallest time among them (at least two runs)."""
    rels, terms, best = [], [], math.inf
    for k in range(max(images, 2)):
        im, s = renderer.render(strategy, spp, 7 + k)
        if k < images:
            rels.append(relative_mse(im, *ref))
            terms.append(pixel_terms(im, ref[0]))
        best = min(best, s)
    return float(np.mean(rels)), effective_terms(terms), best


def ratio_text(r):
    return f'{r:.2f}' if r is not None else 'n/a'


def rel_text(run):
    """The relative MSE, marked '!' (with the effective number of pixel terms) where a few
    rare large pixel errors rule it: such a cell needs more images (--images)."""
    text = f"{run['rel_mse']:.3e}"
    if run['below_reference_noise']:
        text = f'({text})'
    return text + (f" !{run['effective_terms']:.1f}" if run['rare_large_errors'] else '')


def chosen_scenes(args):
    """The scenes of --scenes as (name, glTF path, width, height, strategies), a quarter of the
    size with --quick."""
    for name, gltf, w, h, strategies in SCENES:
        if name in args.scenes.split(','):
            scale = 4 if args.quick else 1
            if args.strategies:
                strategies = [s for s in strategies if s in args.strategies.split(',')]
            yield name, os.path.join(ROOT, 'scenes', gltf), w // scale, h // scale, strategies


# --------------------------------------------------------------------------------------------
# What SIMD width buys Mitsuba (--widths): time only


# Dr.Jit's LLVM backend compiles its kernels for the machine's widest vectors (16 floats with
# AVX-512). WebAssembly's SIMD is 128 bits wide, so a renderer that runs the same code in the
# browser has 4 float lanes at most. --widths times Mitsuba with its kernels compiled for 4 and
# 8 lanes too, through drjit-core's jit_llvm_set_target(cpu, features, width), a C++ function
# the Python API does not expose (hence the mangled name). The narrow kernels get Haswell's
# AVX2 instructions (gathers, FMA): a 4-lane bound more generous than WebAssembly's.
NARROW_CPU, NARROW_FEATURES = b'haswell', b'+avx,+avx2,+fma,+f16c,+sse4.2,+popcnt,+bmi,+bmi2,+lzcnt,+movbe'


def llvm_width(dr, width):
    """Sets the LLVM kernels' number of lanes (0: the machine's own) and returns it."""
    core = ctypes.CDLL(os.path.join(os.path.dirname(dr.__file__), 'libdrjit-core.so'))
    if width:
        set_target = core._Z19jit_llvm_set_targetPKcS0_j
        set_target.argtypes = [ctypes.c_char_p, ctypes.c_char_p, ctypes.c_uint]
        set_target(NARROW_CPU, NARROW_FEATURES, width)
    vector_width = core._Z21jit_llvm_vector_widthv
    vector_width.restype = ctypes.c_uint
    return vector_width()


def width_child(args):
    """Times Mitsuba in one variant (and LLVM vector width) on every scene and strategy at
    args.spp: the smaller of two runs after a first one, as JSON on standard output."""
    import mitsuba as mi
    mi.set_variant(args.child_variant)
    import drjit as dr
    dr.set_thread_count(args.threads)
    width = llvm_width(dr, args.child_width) if args.child_variant.startswith('llvm') else None
    times = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, gltf, w, h, strategies in chosen_scenes(args):
            mit = Mitsuba(mi, args.child_variant, gltf, w, h, folder)
            for strategy in strategies:
                mit.render(strategy, 16, 3)
                times[f'{name} {strategy}'] = min(mit.render(strategy, int(args.spp), 7 + k)[1] for k in range(2))
    print(json.dumps({'width': width, 'times': times}))


def widths(args):
    """mcplay beside Mitsuba's scalar variant and its LLVM kernels at 4, 8 and the machine's
    own number of lanes: seconds per image at args.spp, and the ratios."""
    configs = [('scalar_rgb', 0, 'scalar'), ('llvm_ad_rgb', 4, 'llvm 4 lanes'),
               ('llvm_ad_rgb', 8, 'llvm 8 lanes'), ('llvm_ad_rgb', 0, 'llvm own width')]
    columns = {}
    for variant, width, label in configs:
        cmd = [sys.executable, os.path.abspath(__file__), '--child-variant', variant, '--child-width', str(width),
               '--spp', args.spp, '--threads', str(args.threads), '--scenes', args.scenes] + (['--quick'] if args.quick else [])
        out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
        result = json.loads(out.strip().splitlines()[-1])
        if variant != 'scalar_rgb' and not width:
            label = f"llvm {result['width']} lanes (own)"
        columns[label] = result['times']
        print(f'  {label}: done', file=sys.stderr, flush=True)
    mcplay = {}
    with tempfile.TemporaryDirectory() as folder:
        for name, gltf, w, h, strategies in chosen_scenes(args):
            mcp = Mcplay(args.mcplay, name, w, h, args.threads, folder)
            for strategy in strategies:
                mcplay[f'{name} {strategy}'] = min(mcp.render(strategy, int(args.spp), 7 + k)[1] for k in range(2))
    labels = list(columns)
    own = labels[-1]
    print(f'seconds per image at {args.spp} spp, {args.threads} threads (smaller of two runs); '
          f'last columns: mcplay over each, and the 4-lane time over the {own} one')
    print('| scene | strategy | mcplay | ' + ' | '.join(labels) + ' | '
          + ' | '.join(f'mcplay / {l}' for l in labels) + ' | 4 lanes / own |')
    print('|---' * (4 + 2 * len(labels)) + '|')
    for key, m in mcplay.items():
        t = [columns[l][key] for l in labels]
        print(f"| {' | '.join(key.split())} | {m:.3f} | " + ' | '.join(f'{x:.3f}' for x in t) + ' | '
              + ' | '.join(f'{m / x:.2f}' for x in t) + f' | {t[1] / t[-1]:.2f} |')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('--mcplay', default=os.path.join(ROOT, 'build', 'mcplay'))
    ap.add_argument('--spp', default='16,64,256')
    ap.add_argument('--ref-spp', type=int, default=4096)
    ap.add_argument('--threads', type=int, default=2)
    ap.add_argument('--images', type=int, default=1,
                    help='images per cell whose relative MSE is averaged (heavy-tailed cells need several)')
    ap.add_argument('--quick', action='store_true', help='small images and references: a smoke test')
    ap.add_argument('--scenes', default=','.join(s[0] for s in SCENES))
    ap.add_argument('--strategies', default='', help='only these classes (light,bsdf,mis,path)')
    ap.add_argument('--best-emission', default=str(BEST_EMISSION_SAMPLES),
                    help="camera rays per sample for the emission seen directly in MCPLAY_BEST "
                         "(emission_samples: a count or auto; 1 leaves the key out, for binaries "
                         "without it)")
    ap.add_argument('--scalar', action='store_true',
                    help="also Mitsuba's scalar_rgb variant (one sample at a time per thread, as "
                         "mcplay runs): one more column, scored against the same Mitsuba reference")
    ap.add_argument('--best', action='store_true',
                    help="also mcplay's best per class (MCPLAY_BEST: splitting chosen by a timed "
                         "pilot): one more column, scored against the same mcplay reference")
    ap.add_argument('--sobol', action='store_true',
                    help="also mcplay with Sobol' pixels (--pixel-sampler sobol): one more column")
    ap.add_argument('--widths', action='store_true',
                    help="time only, at the largest --spp: mcplay beside Mitsuba's scalar variant and "
                         "its LLVM kernels compiled for 4, 8 and the machine's own number of lanes")
    ap.add_argument('--child-variant', help=argparse.SUPPRESS)
    ap.add_argument('--child-width', type=int, default=0, help=argparse.SUPPRESS)
    args = ap.parse_args()
    spps = [int(s) for s in args.spp.split(',')]
    for best in MCPLAY_BEST.values():
        best.pop('emission_samples', None)
        if args.best_emission != '1':
            best['emission_samples'] = 'auto' if args.best_emission == 'auto' else int(args.best_emission)
    os.environ.setdefault('DRJIT_NUM_THREADS', str(args.threads))
    if args.child_variant:
        return width_child(args)
    if args.widths:
        args.spp = str(max(spps))
        return widths(args)
    import mitsuba as mi
    variant = os.environ.get('MI_VARIANT', 'llvm_ad_rgb')
    try:
        mi.set_variant(variant)
    except Exception as e:  # drjit without a usable LLVM
        sys.exit(f'bench-mitsuba: Mitsuba variant {variant} is not usable ({e}); '
                 'llvm variants need DRJIT_LIBLLVM_PATH pointing at LLVM >= 16 (Debian libllvm19)')
    import drjit as dr
    dr.set_thread_count(args.threads)
    print(f'mcplay {subprocess.run([args.mcplay, "--version"], capture_output=True, text=True).stdout.strip()}'
          f' beside Mitsuba {mi.__version__} ({variant}), {args.threads} threads; '
          f'spp {spps}, references {args.ref_spp} spp (two halves), {args.images} image(s) per cell')
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, gltf, w, h, strategies in chosen_scenes(args):
            mit = Mitsuba(mi, variant, gltf, w, h, folder)
            mit_scalar = (Mitsuba(mi, 'scalar_rgb', gltf, w, h, folder)
                          if args.scalar else None)
            mcp = Mcplay(args.mcplay, name, w, h, args.threads, folder)
            mcp_sobol = Mcplay(args.mcplay, name, w, h, args.threads, folder, 'sobol')
            mcp_best = Mcplay(args.mcplay, name, w, h, args.threads, folder, best=True)
            cache = {}  # the references of this scene, per reference strategy
            for strategy in strategies:
                ref_strategy = 'path' if strategy == 'path' else 'mis'
                if ref_strategy not in cache:
                    refs = {}
                    for label, r in (('mcplay', mcp), ('mitsuba', mit)):
                        t0 = time.perf_counter()
                        refs[label] = reference(r, ref_strategy, args.ref_spp)
                        print(f'  {name} {label} reference ({ref_strategy}, {args.ref_spp} spp): '
                              f'{time.perf_counter() - t0:.1f} s', file=sys.stderr)
                    cache[ref_strategy] = refs
                refs = cache[ref_strategy]
                noise = {label: reference_noise(*ref) for label, ref in refs.items()}
                between = relative_mse(refs['mcplay'][0], refs['mitsuba'][0], refs['mitsuba'][1])
                mit.render(strategy, spps[0], 3)  # compiles Mitsuba's kernels for this size
                for spp in spps:
                    row = {'scene': name, 'strategy': strategy, 'spp': spp, 'refs_rel_mse': between}
                    runs = [('mcplay', mcp, 'mcplay'), ('mitsuba', mit, 'mitsuba')]
                    if args.sobol:
                        runs.append(('mcplay_sobol', mcp_sobol, 'mcplay'))
                    if args.best:
                        runs.append(('mcplay_best', mcp_best, 'mcplay'))
                        mcp_best.light_samples, mcp_best.candidates = [], []
                    if mit_scalar:
                        runs.append(('mitsuba_scalar', mit_scalar, 'mitsuba'))
                    for label, r, ref_label in runs:
                        rel, n_eff, s = scored(r, strategy, spp, refs[ref_label], args.images)
                        row[label] = {'seconds': s, 'rel_mse': rel, 'effective_terms': n_eff,
                                      'rare_large_errors': n_eff < MIN_EFFECTIVE_TERMS,
                                      'below_reference_noise': rel < noise[ref_label],
                                      'efficiency': 1 / (rel * s) if rel > 0 and s > 0 else None}
                    eff = [row[k]['efficiency'] for k in ('mcplay', 'mitsuba')]
                    row['time_ratio'] = row['mcplay']['seconds'] / row['mitsuba']['seconds']
                    row['efficiency_ratio'] = eff[0] / eff[1] if None not in eff else None
                    row['rare_large_errors'] = any(row[k]['rare_large_errors'] for k in ('mcplay', 'mitsuba'))
                    line = (f"{name:16} {strategy:5} {spp:4} spp  mcplay {row['mcplay']['seconds']:7.3f} s "
                            f"relMSE {rel_text(row['mcplay'])}  |  Mitsuba {row['mitsuba']['seconds']:7.3f} s "
                            f"relMSE {rel_text(row['mitsuba'])}  |  time x{row['time_ratio']:.2f}  "
                            f"efficiency x{ratio_text(row['efficiency_ratio'])}")
                    if args.sobol:
                        sob = row['mcplay_sobol']
                        row['efficiency_ratio_sobol'] = (sob['efficiency'] / eff[1]
                                                         if sob['efficiency'] and eff[1] else None)
                        row['rare_large_errors_sobol'] = sob['rare_large_errors'] or row['mitsuba']['rare_large_errors']
                        line += (f"  |  sobol {sob['seconds']:7.3f} s relMSE {rel_text(sob)} "
                                 f"efficiency x{ratio_text(row['efficiency_ratio_sobol'])}")
                    if args.best:
                        best = row['mcplay_best']
                        best['light_samples'] = sorted(set(mcp_best.light_samples))
                        best['candidates'] = sorted(set(mcp_best.candidates))
                        row['efficiency_ratio_best'] = (best['efficiency'] / eff[1]
                                                        if best['efficiency'] and eff[1] else None)
                        row['rare_large_errors_best'] = best['rare_large_errors'] or row['mitsuba']['rare_large_errors']
                        kind = ('speed contest' if strategy not in MCPLAY_BEST
                                else f"candidates {best['candidates']} light samples {best['light_samples']}")
                        line += (f"  |  best ({kind}) {best['seconds']:7.3f} s relMSE {rel_text(best)} "
                                 f"efficiency x{ratio_text(row['efficiency_ratio_best'])}")
                    if mit_scalar:
                        sca = row['mitsuba_scalar']
                        row['time_ratio_scalar'] = row['mcplay']['seconds'] / sca['seconds']
                        row['efficiency_ratio_scalar'] = (eff[0] / sca['efficiency']
                                                          if eff[0] and sca['efficiency'] else None)
                        line += (f"  |  Mitsuba scalar {sca['seconds']:7.3f} s relMSE {rel_text(sca)} "
                                 f"mcplay time x{row['time_ratio_scalar']:.2f} "
                                 f"efficiency x{ratio_text(row['efficiency_ratio_scalar'])}")
                    rows.append(row)
                    print(line, flush=True)
    out = os.path.join(ROOT, 'build', 'bench-mitsuba.json')
    with open(out, 'w') as f:
        json.dump(rows, f, indent=1)
    times = sorted(r['time_ratio'] for r in rows)
    for key, flag, label in (('efficiency_ratio', 'rare_large_errors', 'mcplay'),
                             ('efficiency_ratio_sobol', 'rare_large_errors_sobol', 'mcplay sobol'),
                             ('efficiency_ratio_best', 'rare_large_errors_best', 'mcplay best')):
        ratios = sorted(r[key] for r in rows if r.get(key))
        if ratios:
            print(f'efficiency {label} / Mitsuba over {len(ratios)} cells: median {ratios[len(ratios) // 2]:.2f}, '
                  f'range {ratios[0]:.2f} .. {ratios[-1]:.2f}; ahead in {sum(r >= 1 for r in ratios)}')
        steady = sorted(r[key] for r in rows if r.get(key) and not r.get(flag))
        if ratios and len(steady) < len(ratios):
            median = f'median {steady[len(steady) // 2]:.2f}, ' if steady else ''
            print(f'  {len(ratios) - len(steady)} cell(s) marked ! rest on fewer than {MIN_EFFECTIVE_TERMS} '
                  f'effective pixel terms (rare large errors: more --images); the other {len(steady)}: '
                  f'{median}ahead in {sum(r >= 1 for r in steady)}')
    if times:
        print(f'time per image mcplay / Mitsuba: median {times[len(times) // 2]:.2f}, '
              f'range {times[0]:.2f} .. {times[-1]:.2f}')
    scalar = sorted(r['time_ratio_scalar'] for r in rows if 'time_ratio_scalar' in r)
    if scalar:
        effs = sorted(r['efficiency_ratio_scalar'] for r in rows if r.get('efficiency_ratio_scalar'))
        print(f'time per image mcplay / Mitsuba scalar_rgb: median {scalar[len(scalar) // 2]:.2f}, '
              f'range {scalar[0]:.2f} .. {scalar[-1]:.2f}; efficiency median {effs[len(effs) // 2]:.2f}, '
              f'range {effs[0]:.2f} .. {effs[-1]:.2f}, ahead in {sum(r >= 1 for r in effs)} of {len(effs)}')
    for name in sorted({r['scene'] for r in rows}):
        print(f'references, mcplay against Mitsuba, {name}: relative MSE '
              + ', '.join(f"{r['strategy']} {r['refs_rel_mse']:.2e}" for r in rows if r['scene'] == name and r['spp'] == spps[0]))
    print(f'figures: {out}')


if __name__ == '__main__':
    main()
