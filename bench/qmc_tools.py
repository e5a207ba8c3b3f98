#!/usr/bin/env python3
"""Randomized QMC of other tools on Genz's families, for `make bench-qmc` (docs/benchmarks.md).

    qmc_tools.py PARAMS_DIR --n N --reps R [--randomizations K] [--methods ...]

Reads the params files `genz_compare --write-params` writes (family, a, u, exact per case) and
prints one JSON line per estimate in the format `genz_compare --external` reads:
{"tool", "method", "case", "estimate", "reported_sigma", "calls", "seconds"}.

Methods, each estimate from K independent randomizations of N/K points (N/K rounded to a power
of two), the mean as estimate and the standard deviation of the K means / sqrt(K) as its error
bar, as mcplay's RQMC estimators report theirs (K = 1: one randomized net of N points and no
error bar, "reported_sigma": null); a K other than 16 is part of the method's name
("qmcpy_lms:4"), so runs at several K can share one file:
  qmcpy_lms     QMCPy DigitalNetB2: Joe-Kuo Sobol', linear matrix scramble + digital shift
  qmcpy_lattice QMCPy Lattice: rank-1 lattice, random shifts
  scipy_sobol   scipy.stats.qmc.Sobol(scramble=True): LMS + digital shift, K generators
Seconds are wall time per estimate: points, randomization and integrand (numpy, vectorized).
"""
import argparse
import glob
import json
import math
import os
import sys
import time

import numpy as np


def genz(family, a, u, x):
    """Genz's six test families [Genz84] at the rows of x (n x d), as mcplay defines them
    (src/integrands/genz.h): the same a and u, no rescaling."""
    a = np.asarray(a)
    u = np.asarray(u)
    if family == 1:  # oscillatory
        return np.cos(2.0 * math.pi * u[0] + x @ a)
    if family == 2:  # product peak
        return np.prod(1.0 / (a ** -2.0 + (x - u) ** 2), axis=1)
    if family == 3:  # corner peak
        return (1.0 + x @ a) ** (-(len(a) + 1.0))
    if family == 4:  # Gaussian
        return np.exp(-np.sum((a * (x - u)) ** 2, axis=1))
    if family == 5:  # continuous
        return np.exp(-np.abs(x - u) @ a)
    if family == 6:  # discontinuous: zero beyond u in the first two coordinates
        inside = x[:, 0] <= u[0]
        if len(a) > 1:
            inside &= x[:, 1] <= u[1]
        return np.where(inside, np.exp(x @ a), 0.0)
    raise ValueError("family %r is not one of Genz's six" % family)


def point_sets(method, d, k, m, seed):
    """K randomized point sets of 2^m points in [0, 1)^d, as an array (K, 2^m, d)."""
    if method == "qmcpy_lms":
        import qmcpy as qp
        return qp.DigitalNetB2(d, replications=k, seed=seed).gen_samples(2 ** m)
    if method == "qmcpy_lattice":
        import qmcpy as qp
        return qp.Lattice(d, replications=k, seed=seed).gen_samples(2 ** m)
    if method == "scipy_sobol":
        from scipy.stats import qmc
        rng = np.random.default_rng(seed)
        return np.stack([qmc.Sobol(d, scramble=True, seed=rng).random_base2(m) for _ in range(k)])
    raise ValueError("unknown method %r" % method)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("params_dir")
    ap.add_argument("--n", type=int, default=2 ** 20)
    ap.add_argument("--reps", type=int, default=10)
    ap.add_argument("--randomizations", type=int, default=16)
    ap.add_argument("--methods", default="qmcpy_lms,qmcpy_lattice,scipy_sobol")
    ap.add_argument("--seed", type=int, default=1)
    o = ap.parse_args()
    if o.randomizations < 1 or o.n < 4 * o.randomizations or o.reps < 1:
        sys.exit("qmc_tools: need --randomizations >= 1, --n >= 4 K and --reps >= 1")
    m = int(round(math.log2(o.n / o.randomizations)))
    files = sorted(glob.glob(os.path.join(o.params_dir, "*.json")))
    if not files:
        sys.exit("qmc_tools: no params files in %s" % o.params_dir)
    tools = {"qmcpy_lms": "qmcpy", "qmcpy_lattice": "qmcpy", "scipy_sobol": "scipy"}
    for path in files:
        with open(path) as fh:
            p = json.load(fh)
        d, name = p["d"], p["name"]
        print("[qmc_tools] %s" % name, file=sys.stderr, flush=True)
        for method in o.methods.split(","):
            for rep in range(o.reps):
                seed = o.seed * 1000003 + rep
                t0 = time.perf_counter()
                x = point_sets(method, d, o.randomizations, m, seed)
                x = x.reshape(o.randomizations, 2 ** m, d)  # K = 1: QMCPy drops the axis
                means = np.array([genz(p["family"], p["a"], p["u"], x[j]).mean()
                                  for j in range(o.randomizations)])
                seconds = time.perf_counter() - t0
                sigma = (float(means.std(ddof=1) / math.sqrt(len(means)))
                         if len(means) > 1 else None)
                label = method if o.randomizations == 16 else "%s:%d" % (method, o.randomizations)
                print(json.dumps({
                    "tool": tools[method], "method": label, "case": name,
                    "estimate": float(means.mean()), "reported_sigma": sigma,
                    "calls": o.randomizations * 2 ** m, "seconds": seconds}), flush=True)


if __name__ == "__main__":
    main()
