"""mcplay: Monte Carlo estimators with honest error bars, over the same C++ core as the CLI.

>>> import numpy as np, mcplay
>>> r = mcplay.integrate(lambda x: np.exp(x.sum(axis=1)), dim=4)
>>> r.estimate, r.error_bar, r.best.name          # doctest: +SKIP
>>> r.flags, r.to_pandas(), r.plot("variance")     # doctest: +SKIP

The functions:

- :func:`integrate`: a numpy callable or an expression over a box, every estimator that applies.
- :func:`run`, :func:`merge`: a scene's study (a dict, a file or a bundled name), whole or in
  parts over processes or machines, the same dict as ``mcplay run --format json``.
- :func:`points`, :func:`analyze`, :func:`warp_test`: the sampler lab.
- :func:`render`: an image of a render scene as an ``(H, W, 3)`` array, or a progressive series.
- :func:`catalog`, :func:`estimators`, :func:`scenes`: what the core offers.

Every bad argument raises :class:`McplayError` (a ``ValueError``) with a one-line message naming
it. Every number comes from the core: the package computes none of its own.
"""

from __future__ import annotations

# From a source tree the extension lives in the build folder's mcplay/ (CMake puts it in
# build/python/mcplay): with both folders on PYTHONPATH this makes them one package.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)

from . import _core  # noqa: E402
from ._scenes import scene_names as scenes
from ._scenes import scenes_dir
from ._util import McplayError
from .integrate import integrate
from .lab import Analysis, WarpTest, analyze, points, warp_test
from .render import ProgressiveRender, Render, render
from .result import EstimatorResult, Flag, Result, Stopping
from .study import catalog, estimators, merge, plan, run, scene_info

__version__: str = _core.version()

__all__ = [
    "Analysis",
    "EstimatorResult",
    "Flag",
    "McplayError",
    "ProgressiveRender",
    "Render",
    "Result",
    "Stopping",
    "WarpTest",
    "analyze",
    "catalog",
    "estimators",
    "integrate",
    "merge",
    "plan",
    "points",
    "render",
    "run",
    "scene_info",
    "scenes",
    "scenes_dir",
    "warp_test",
]
