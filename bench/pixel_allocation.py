#!/usr/bin/env python3
"""Uniform against adaptive pixel allocation (src/render/adaptive.h), estimator by estimator.

    pixel_allocation.py MCPLAY [--images K] [--spp 16,64] [--threads T]

For each scene (quad_light_floor 320x240, cornell_box 128x128, veach_mis 320x180, and the
Cornell box's path tracer) and estimator (light_solid_angle, mis_power, ris with 8 candidates;
path), mcplay renders K images of different seeds at each spp with `pixel_allocation`
`uniform` and `adaptive`, both with the padded Sobol' sampler and emission_samples 16 (as
bench_mitsuba's best), and scores each against a reference of two 1024-spp halves of different
seeds (mis_power, or path for the path scene; padded Sobol'): relative MSE
mean over pixels and channels of ((I - R)^2 - v) / (R^2 + eps), v = (R1 - R2)^2 / 4 the
reference's own noise, eps = 1e-2 (mean luminance of R)^2 [RousselleKnausZwicker11], averaged
over the K images; seconds the median of the K renders' (the result JSON's, pilots included);
efficiency 1 / (relative MSE x seconds). Prints one line per cell with adaptive's efficiency
over uniform's. Needs numpy (the bench venv of `make bench-mitsuba` has it).
"""
import argparse
import json
import os
import subprocess
import tempfile

import sys

import numpy as np

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), '..'))
sys.path.insert(0, os.path.join(ROOT, 'bench', 'mitsuba'))
from bench_mitsuba import luminance, read_pfm  # noqa: E402 (mitsuba itself is imported lazily)
CASES = [
    ('quad_light_floor', 320, 240, ['light_solid_angle', 'mis_power', 'ris']),
    ('cornell_box', 128, 128, ['light_solid_angle', 'mis_power', 'ris']),
    ('veach_mis', 320, 180, ['light_solid_angle', 'mis_power', 'ris']),
    ('cornell_box_path', 128, 128, ['path']),
]


def estimator(strategy, allocation):
    e = {'name': strategy, 'strategy': strategy, 'pixel_sampler': 'padded_sobol',
         'pixel_allocation': allocation}
    if strategy == 'ris':
        e['candidates'] = 8
    if strategy == 'path':
        e['max_depth'] = 5
    else:
        e['emission_samples'] = 16
    return e


def render(exe, scene, est, spp, seed, w, h, threads, folder):
    out = os.path.join(folder, 'image.pfm')
    cmd = [exe, 'render', scene, '--scenes', os.path.join(ROOT, 'scenes'), '--estimator',
           json.dumps(est), '--spp', str(spp), '--seed', str(seed), '--width', str(w),
           '--height', str(h), '--threads', str(threads), '--out', out, '--format', 'json',
           '--no-cache']
    r = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    e = r['estimator']
    pilots = sum(e[k]['seconds'] for k in ('split_pilot', 'candidate_pilot', 'emission_pilot')
                 if k in e)
    return read_pfm(out), r['seconds'] + pilots


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    ap.add_argument('mcplay')
    ap.add_argument('--images', type=int, default=6)
    ap.add_argument('--spp', default='16,64')
    ap.add_argument('--threads', type=int, default=2)
    a = ap.parse_args()
    spps = [int(s) for s in a.spp.split(',')]
    with tempfile.TemporaryDirectory() as folder:
        for scene, w, h, strategies in CASES:
            ref_est = estimator('path' if scene.endswith('path') else 'mis_power', 'uniform')
            r1, _ = render(a.mcplay, scene, ref_est, 1024, 11, w, h, a.threads, folder)
            r2, _ = render(a.mcplay, scene, ref_est, 1024, 12, w, h, a.threads, folder)
            ref, noise = (r1 + r2) / 2, (r1 - r2) ** 2 / 4
            eps = 1e-2 * luminance(ref).mean() ** 2
            for spp in spps:
                for strategy in strategies:
                    eff = {}
                    for allocation in ('uniform', 'adaptive'):
                        rel, secs = [], []
                        for k in range(a.images):
                            img, s = render(a.mcplay, scene, estimator(strategy, allocation), spp,
                                            200 + k, w, h, a.threads, folder)
                            rel.append((((img - ref) ** 2 - noise) / (ref ** 2 + eps)).mean())
                            secs.append(s)
                        m, t = float(np.mean(rel)), float(np.median(secs))
                        eff[allocation] = (m, t, 1 / (m * t))
                    (mu, tu, eu), (ma, ta, ea) = eff['uniform'], eff['adaptive']
                    print(f'{scene:17s} {strategy:17s} {spp:4d} spp  uniform {mu:.3g} in {tu:.3f} s'
                          f'  adaptive {ma:.3g} in {ta:.3f} s  efficiency x{ea / eu:.2f}',
                          flush=True)


if __name__ == '__main__':
    main()
