"""python_smoke (ctest, MCPLAY_PYTHON builds): the extension mcplay._core from the build tree.

Imports the package (python/ and the build folder's python/ on PYTHONPATH), integrates a numpy
callable in d = 2 with mcplay.integrate against its exact value, and runs one bundled scene
through the extension; a second or two.
Usage: smoke.py SCENES_DIR
"""

import json
import math
import pathlib
import sys

import numpy as np

import mcplay
from mcplay import _core

# Fixed seeds; every check is a distance from the exact value in standard errors.
TOLERANCE_SE = 5.0


def check_level(name: str, level: dict, exact: float) -> None:
    """The level's mean is within TOLERANCE_SE standard errors of exact."""
    mean, se = level["mean"], level["std_error"]
    if not (se > 0 and abs(mean - exact) < TOLERANCE_SE * se):
        sys.exit(f"python_smoke: {name}: {mean} +- {se} is not within {TOLERANCE_SE} se of {exact}")


def main() -> None:
    scenes = pathlib.Path(sys.argv[1])
    calls = 0

    def f(x: np.ndarray) -> np.ndarray:
        nonlocal calls
        calls += 1
        return np.exp(x.sum(1))

    exact = (math.e - 1.0) ** 2
    # The public API, as a user calls it.
    result = mcplay.integrate(f, dim=2, estimators=["uniform", "sobol"], n=4096, n_min=4096,
                              reps=8, seed=7, threads=2, exact=exact)
    for name, estimator in result.estimators.items():
        mean, se = estimator.estimate, estimator.stderr
        if not (se > 0 and abs(mean - exact) < TOLERANCE_SE * se):
            sys.exit(f"python_smoke: callable, {name}: {mean} +- {se} is not within "
                     f"{TOLERANCE_SE} se of {exact}")
    if calls == 0:
        sys.exit("python_smoke: the callable was never called")

    text = (scenes / "exp_1d.json").read_text()
    result = json.loads(_core.study_run(text, json.dumps({"n_max": 1024, "reps": 8, "seed": 3})))
    for estimator in result["estimators"]:
        check_level(f"exp_1d, {estimator['name']}", estimator["levels"][-1], math.e - 1.0)
    print(f"python_smoke: mcplay {_core.version()}: callable ({calls} blocks) and exp_1d agree "
          f"with their exact values")


if __name__ == "__main__":
    main()
