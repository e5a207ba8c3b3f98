"""The callable path against the expression path (issue 47): f(x) = exp(x1 + ... + xd) as the
numpy callable `lambda x: np.exp(x.sum(1))` and as the core's expression, same estimator, seed,
N and threads; wall time of the whole study call (mcplay._core.study_run), median of repeats.

Run from the source tree after a native build with the extension (make deps-python build):
  PYTHONPATH=python:build/python build/py-venv/bin/python bench/python_callable.py
or with the package installed: python bench/python_callable.py.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time

import numpy as np

from mcplay import _core


def study_seconds(scene: dict, options: dict, functions: dict | None, repeat: int) -> tuple:
    """Median wall seconds of `repeat` studies, and the last result's estimate."""
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = json.loads(_core.study_run(json.dumps(scene), json.dumps(options), functions))
        times.append(time.perf_counter() - start)
    return statistics.median(times), result["estimators"][0]["levels"][-1]["mean"]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dim", type=int, default=4)
    parser.add_argument("--n", type=int, default=1 << 20, help="points per estimate")
    parser.add_argument("--reps", type=int, default=8, help="replicates per study")
    parser.add_argument("--repeat", type=int, default=5, help="studies timed per cell")
    parser.add_argument("--estimators", default="uniform,sobol")
    parser.add_argument("--threads", default="1,2")
    args = parser.parse_args()

    box = {"type": "box", "lower": [0.0] * args.dim, "upper": [1.0] * args.dim}
    expression = " + ".join(f"x{i + 1}" for i in range(args.dim))
    scenes = {
        "expression": ({"name": "bench", "domain": box, "f": f"exp({expression})"}, None),
        "callable": ({"name": "bench", "domain": box,
                      "integrand": {"type": "function", "name": "f"}},
                     {"f": lambda x: np.exp(x.sum(1))}),
    }
    print(f"f = exp(x1 + ... + x{args.dim}), N = {args.n}, {args.reps} replicates per study, "
          f"median of {args.repeat} studies; numpy {np.__version__}, mcplay {_core.version()}")
    print(f"{'estimator':<10} {'threads':>7} {'expression s':>13} {'callable s':>11} "
          f"{'ratio':>6} {'ms/estimate (callable)':>23}")
    for estimator in args.estimators.split(","):
        for threads in (int(t) for t in args.threads.split(",")):
            options = {"estimators": [estimator], "n_min": args.n, "n_max": args.n,
                       "reps": args.reps, "seed": 1, "threads": threads}
            seconds, means = {}, {}
            for path, (scene, functions) in scenes.items():
                seconds[path], means[path] = study_seconds(scene, options, functions, args.repeat)
            ratio = seconds["callable"] / seconds["expression"]
            print(f"{estimator:<10} {threads:>7} {seconds['expression']:>13.3f} "
                  f"{seconds['callable']:>11.3f} {ratio:>6.2f} "
                  f"{1e3 * seconds['callable'] / args.reps:>23.1f}")
            if abs(means["callable"] - means["expression"]) > 1e-9 * abs(means["expression"]):
                print(f"  note: estimates differ: {means['callable']!r} vs {means['expression']!r}"
                      " (numpy's exp and the core's round differently in the last bit)")


if __name__ == "__main__":
    main()
