"""``integrate``: a Python callable or an expression integrated over a box, a study in one call."""

from __future__ import annotations

import re
import textwrap
from typing import Any, Callable, Mapping

from . import _core
from ._util import (
    argument_error,
    box_domain,
    estimator_list,
    from_json,
    progress_adapter,
    put,
    real_number,
    to_json,
    whole_number,
)
from .result import Result

#: The estimators run when none are named: a plain Monte Carlo baseline, randomized QMC and an
#: adaptive map.
DEFAULT_ESTIMATORS = ("uniform", "sobol", "vegas")

#: The name the scene gives the caller's function.
_FUNCTION_NAME = "f"


def _domain(domain: Any, dim: Any) -> dict | None:
    """The scene's domain from ``domain`` and ``dim`` (None: the core infers it from f)."""
    if dim is not None:
        dim = whole_number(dim, "dim", 1)
    if domain is None:
        return None if dim is None else {"type": "box", "dim": dim}
    if isinstance(domain, Mapping):
        return dict(domain)
    box = box_domain(domain)
    if dim is not None and dim != len(box["lower"]):
        raise argument_error(
            f"dim: {dim} does not match the domain's {len(box['lower'])} (lo, hi) pairs"
        )
    return box


def integrate(
    f: Callable | str | Mapping,
    dim: int | None = None,
    domain: Any = None,
    estimators: Any = None,
    n: int | None = None,
    reps: int | None = None,
    rel_tol: float | None = None,
    abs_tol: float | None = None,
    exact: float | None = None,
    seed: int = 1,
    threads: int | None = None,
    n_min: int | None = None,
    progress: Callable[[dict], Any] | None = None,
    *,
    max_seconds: float | None = None,
    quantity: str = "integral",
    name: str | None = None,
) -> Result:
    """Integrate ``f`` with several estimators and say how far each can be trusted.

        Every estimator runs at every power of two N from ``n_min`` to ``n`` with ``reps``
        independent replicates (or, with ``rel_tol``/``abs_tol``, doubles N until its 95% error bar
        meets the tolerance); the core measures variance, error bars, fitted order, time and the
        diagnostics, exactly as ``mcplay run`` does for a scene.

        Parameters
        ----------
        f
            A callable taking an ``(n, d)`` float64 array (one block of points, never one point at a
            time) and returning ``n`` values; or an expression string in ``x1 .. xd`` (or ``x y
        z``),
            compiled by the core (e.g. ``"exp(-(x-0.5)^2/0.01)"``); or a scene integrand object
            (``{"type": "genz_gaussian", ...}``). A callable may be called from several of the
            core's threads at once; each call holds the GIL, so blocks of a Python callable run one
            at a time while the core's own work (points, warps, sums) runs in parallel. Besides
            the study's points, f is evaluated once a study at 2^15 uniform points, to judge its
            tail (whether the variance may be infinite) where an estimator's variance follows f's.
        dim
            The dimension, for the unit cube [0, 1]^dim (a callable needs ``dim`` or ``domain``).
        domain
            ``None`` (the unit cube of ``dim``), a sequence of ``(lo, hi)`` pairs (a box) or a scene
            domain dict (``{"type": "disk", "radius": 1}``, docs/scene-format.md).
        estimators
            Preset names or scene estimator objects (default ``("uniform", "sobol", "vegas")``).
            An object adds a density or settings, e.g. importance sampling with a given pdf:
            ``{"name": "importance", "pdf": {"type": "exponential", "rate": -1}}``, control variates
            ``{"name": "cv", "control_variates": [{"g": "x", "integral": 0.5}]}``, VEGAS options
            ``{"name": "v", "vegas": {"increments": 50}}``. The presets, from the core's catalog:

    {ESTIMATORS}
        n
            The largest N (default 65536); with a tolerance, the budget of one run (default 2^24).
        reps
            Independent replicates per N (default 32; with a tolerance, runs, default 2: the first
            is the answer reported).
        rel_tol, abs_tol
            Stop at a requested accuracy instead of running the N ladder: N doubles until the 95%
            error bar is within max(abs_tol, rel_tol |estimate|), confirmed by the independent run
            at N/2 and trusted (docs/result-schema.md, Stopping).
        exact
            The exact value, when known: bias, MSE, coverage and the calibration plot use it.
        seed
            The seed of every random stream: the same seed gives the same numbers on any number of
            threads.
        threads
            Worker threads (default: every core; 0 = every core).
        n_min
            The smallest N (default 16; the randomized QMC presets need at least 16).
        progress
            Called with each completed level (a dict) as the study goes.
        max_seconds
            With a tolerance: give up an estimate after about this many seconds.
        quantity
            ``"integral"`` (default) or ``"mean"`` (the integral over the domain's measure).
        name
            The study's name in tables (default the callable's name).

        Returns
        -------
        Result
            ``.estimate``, ``.error_bar`` (95% half-width) and ``.stderr`` of the recommended
            estimator ``.best`` (the smallest error bar at the largest N among the estimators whose
            flags do not say the bar is untrustworthy), each estimator by name
        (``result["sobol"]``),
            ``.flags``, ``.levels``, ``.to_pandas()``, ``.plot()``, ``.stopping``, ``.raw``; its
            ``repr`` is the CLI's table.

        Raises
        ------
        McplayError
            A bad argument (named) before any work; an error of ``f`` (raised, wrong shape, NaN),
            naming the block and the first bad point, with the original error as ``__cause__``.
        KeyboardInterrupt
            Ctrl-C cancels the study within a block.

        Examples
        --------
        >>> import numpy as np, mcplay
        >>> r = mcplay.integrate(lambda x: np.exp(x.sum(axis=1)), dim=4, exact=(np.e - 1) ** 4)
        >>> abs(r.estimate - (np.e - 1) ** 4) < 5 * r.stderr
        True
    """
    functions: dict[str, Callable] = {}
    scene: dict[str, Any] = {}
    if callable(f):
        if dim is None and domain is None:
            raise argument_error(
                "dim: a callable f needs dim (the unit cube [0, 1]^dim) or a domain"
            )
        functions[_FUNCTION_NAME] = f
        scene["integrand"] = {"type": "function", "name": _FUNCTION_NAME}
        default_name = getattr(f, "__name__", "f")
    elif isinstance(f, str):
        scene["f"] = f
        default_name = "expression"
    elif isinstance(f, Mapping):
        scene["integrand"] = dict(f)
        default_name = str(f.get("type", "integrand"))
    else:
        raise argument_error(
            f"f: expected a callable, an expression string or an integrand dict, "
            f"got {type(f).__name__}"
        )
    if name is None:
        name = default_name if default_name.isidentifier() else "f"
    elif not isinstance(name, str):
        raise argument_error(f"name: expected a string, got {type(name).__name__}")
    scene = {"name": name, **scene}
    put(scene, "domain", _domain(domain, dim))
    if not isinstance(quantity, str):
        raise argument_error(f"quantity: expected 'integral' or 'mean', got {quantity!r}")
    scene["quantity"] = quantity
    if exact is not None:
        scene["exact"] = real_number(exact, "exact")
    scene["estimators"] = estimator_list(DEFAULT_ESTIMATORS if estimators is None else estimators)
    stopping = rel_tol is not None or abs_tol is not None
    if rel_tol is not None:
        scene["rel_tol"] = real_number(rel_tol, "rel_tol", positive=True)
    if abs_tol is not None:
        scene["abs_tol"] = real_number(abs_tol, "abs_tol", positive=True)
    if max_seconds is not None:
        if not stopping:
            raise argument_error("max_seconds: a time budget needs rel_tol or abs_tol")
        scene["max_seconds"] = real_number(max_seconds, "max_seconds", positive=True)
    if n_min is not None:
        scene["n_min"] = whole_number(n_min, "n_min", 1)
    if n is not None:
        scene["n_max"] = whole_number(n, "n", 1)
    elif stopping:
        scene["n_max"] = 1 << 24
    if reps is None:
        reps = 2 if stopping else 32
    scene["reps"] = whole_number(reps, "reps", 1)
    scene["seed"] = whole_number(seed, "seed", 0)
    if threads is not None:
        scene["threads"] = whole_number(threads, "threads", 0)
    on_line = progress_adapter(progress)
    text = _core.study_run(to_json(scene, "scene"), None, functions, on_line)
    return Result(from_json(text))


def _estimator_lines() -> str:
    """The presets and their one-line summaries, from the core's catalog."""
    try:
        presets = from_json(_core.call("catalog", ""))["estimators"]
    except Exception as error:  # the docstring must not stop the import
        return f"        (the catalog could not be read: {error})\n"
    lines = []
    for preset in presets:
        needs = " (needs a pdf)" if preset.get("needs_pdf") else ""
        head = f"        - ``{preset['name']}``: "
        body = textwrap.fill(
            preset.get("summary", "") + needs,
            width=96,
            initial_indent=head,
            subsequent_indent=" " * 10,
        )
        lines.append(body)
    return "\n".join(lines) + "\n"


if integrate.__doc__:
    _lines = _estimator_lines()
    integrate.__doc__ = re.sub(
        r"^[ \t]*\{ESTIMATORS\}\n", lambda _: _lines, integrate.__doc__, flags=re.M
    )
