"""The sampler lab: a sampler's points, their analysis, and warp tests (docs/sampler-lab.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _core
from ._util import argument_error, box_domain, from_json, put, to_json, whole_number

#: The renderer's per-pixel samplers, named as the CLI names them (``mcplay points pixel_sobol``).
_PIXEL_PREFIX = "pixel_"


def points(
    sampler: str,
    n: int,
    dim: int = 2,
    seed: int = 1,
    randomization: str | None = None,
) -> np.ndarray:
    """The points a sampler draws in [0, 1)^dim, as an ``(n, dim)`` float64 array.

    ``sampler``: ``"uniform"``, ``"stratified"``, ``"latin_hypercube"``, ``"sobol"``,
    ``"halton"`` or ``"lattice"`` (``randomization`` chooses the quasi-Monte Carlo
    randomization; ``"none"`` gives the deterministic points), or one of the renderer's pixel
    samplers ``"pixel_independent"``, ``"pixel_stratified"``, ``"pixel_sobol"``,
    ``"pixel_padded_sobol"`` (one pixel's ``n`` samples; ``dim`` 2, 4, 6 or 8).
    The same as ``mcplay points SAMPLER --n N --dim D --seed S``.
    """
    if not isinstance(sampler, str):
        raise argument_error(f"sampler: expected a name, got {type(sampler).__name__}")
    n = whole_number(n, "n", 0)
    dim = whole_number(dim, "dim", 0)
    seed = whole_number(seed, "seed", 0)
    if sampler.startswith(_PIXEL_PREFIX):
        if randomization is not None:
            raise argument_error("randomization: the pixel samplers have their own")
        request = {
            "pixel_sampler": sampler[len(_PIXEL_PREFIX) :],
            "spp": n,
            "dim": dim,
            "seed": seed,
        }
        result = from_json(_core.call("render_pixel_points", to_json(request, "request")))
    else:
        request = {"sampler": sampler, "n": n, "dim": dim, "seed": seed}
        if randomization is not None:
            if not isinstance(randomization, str):
                raise argument_error(
                    f"randomization: expected a name, got {type(randomization).__name__}"
                )
            request["randomization"] = randomization
        result = from_json(_core.call("points", to_json(request, "request")))
    rows = result["points"]
    return np.array(rows, dtype=np.float64).reshape(len(rows), int(result["dim"]))


def _point_rows(value: Any, what: str) -> list:
    """One point set, an ``(n, d)`` array of finite numbers, as rows for the request."""
    array = np.asarray(value, dtype=np.float64) if not isinstance(value, np.ndarray) else value
    if array.ndim != 2:
        raise argument_error(
            f"{what}: expected an (n, d) array, got {array.ndim} dimension(s)"
            f" of shape {array.shape}"
        )
    if not np.issubdtype(array.dtype, np.number):
        raise argument_error(f"{what}: expected numbers, got dtype {array.dtype}")
    array = array.astype(np.float64, copy=False)
    bad = ~np.isfinite(array)
    if bad.any():
        row, column = (int(i) for i in np.argwhere(bad)[0])
        raise argument_error(
            f"{what}: row {row}, column {column} is {float(array[row, column])}, not a coordinate"
        )
    return array.tolist()


def _point_sets(points_: Any) -> list:
    """One ``(n, d)`` set as rows, or K sets (a list of arrays, or a ``(K, n, d)`` array)."""
    if (
        isinstance(points_, (list, tuple))
        and points_
        and all(isinstance(s, np.ndarray) for s in points_)
    ):
        return [_point_rows(s, f"points[{i}]") for i, s in enumerate(points_)]
    try:
        array = np.asarray(points_, dtype=np.float64)
    except (TypeError, ValueError):
        raise argument_error(
            "points: expected an (n, d) array of numbers or a list of such arrays of equal "
            f"shape, got {type(points_).__name__}"
        ) from None
    if array.ndim == 3:
        return [_point_rows(s, f"points[{i}]") for i, s in enumerate(array)]
    return _point_rows(array, "points")


def _float_array(values: Any) -> np.ndarray:
    return np.array([math.nan if v is None else v for v in values], dtype=np.float64)


@dataclass
class Analysis:
    """What the core measured of one or more point sets (means over the sets).

    Discrepancies (L2-star, centred and wrap-around L2) with their root mean square for ``n``
    independent uniform points (``expected_iid``), the minimum distances (plain and on the
    torus), the power ``spectrum`` of a 2-D projection (an ``(S, S)`` array, row ky + S/2,
    column kx + S/2; 1 is the level of independent points) and its ``radial`` average. A measure
    that was skipped is NaN, with the reason in ``skipped``.
    """

    n: int
    dim: int
    sets: int
    l2_star_discrepancy: float
    centered_l2_discrepancy: float
    wraparound_l2_discrepancy: float
    min_distance: float
    min_distance_toroidal: float
    expected_iid: dict[str, float]
    per_set: dict[str, np.ndarray]
    spectrum: np.ndarray | None
    spectrum_axes: tuple[int, int] | None
    radial: dict[str, np.ndarray] | None
    skipped: dict[str, str]
    raw: dict = field(repr=False)

    @classmethod
    def from_raw(cls, raw: dict) -> "Analysis":
        def number(key: str) -> float:
            value = raw.get(key)
            return float(value) if isinstance(value, (int, float)) else math.nan

        spectrum = radial = axes = None
        if isinstance(raw.get("spectrum"), dict):
            s = raw["spectrum"]
            size = int(s["size"])
            spectrum = _float_array(s["power"]).reshape(size, size)
            axes = tuple(int(a) for a in s.get("axes", (0, 1)))
            radial = {k: _float_array(v) for k, v in (s.get("radial") or {}).items()}
        return cls(
            n=int(raw.get("n", 0)),
            dim=int(raw.get("dim", 0)),
            sets=int(raw.get("sets", 1)),
            l2_star_discrepancy=number("l2_star_discrepancy"),
            centered_l2_discrepancy=number("centered_l2_discrepancy"),
            wraparound_l2_discrepancy=number("wraparound_l2_discrepancy"),
            min_distance=number("min_distance"),
            min_distance_toroidal=number("min_distance_toroidal"),
            expected_iid={
                k: (math.nan if v is None else float(v))
                for k, v in (raw.get("expected_iid") or {}).items()
            },
            per_set={k: _float_array(v) for k, v in (raw.get("per_set") or {}).items()},
            spectrum=spectrum,
            spectrum_axes=axes,
            radial=radial,
            skipped=dict(raw.get("skipped") or {}),
            raw=raw,
        )


def analyze(
    points: Any,
    spectrum: bool = True,
    axes: tuple[int, int] = (0, 1),
    size: int = 256,
    pairwise: bool = True,
) -> Analysis:
    """Measure point sets in [0, 1)^d: discrepancies, minimum distances, the Fourier spectrum.

    ``points``: an ``(n, d)`` array, or a list (or ``(K, n, d)`` array) of K sets of equal size
    taken as K randomizations (the measures are then means over the sets). ``spectrum``: the
    periodogram of the projection on ``axes`` (0-based) on a ``size`` x ``size`` frequency grid;
    ``pairwise=False`` skips the O(N^2 d) measures. The same as ``mcplay analyze``.
    """
    request: dict[str, Any] = {"points": _point_sets(points)}
    if spectrum:
        if isinstance(axes, (str, bytes)) or not isinstance(axes, Sequence) or len(axes) != 2:
            raise argument_error(f"axes: expected a pair of 0-based axes, got {axes!r}")
        request["spectrum"] = {
            "axes": [whole_number(a, "axes", 0) for a in axes],
            "size": whole_number(size, "size", 1),
        }
    else:
        request["spectrum"] = False
    if not isinstance(pairwise, bool):
        raise argument_error(f"pairwise: expected True or False, got {pairwise!r}")
    request["pairwise"] = pairwise
    return Analysis.from_raw(from_json(_core.call("points_analyze", to_json(request, "points"))))


@dataclass
class WarpTest:
    """A warp tested against the density it claims (docs/sampler-lab.md, Warp tests).

    ``outcome`` is ``"passed"``, ``"failed"`` or ``"unverified"`` (the test's own quadrature of the
    density could not settle the expected counts well enough to judge either way; ``verdict``
    says why); ``passed`` is True, False, or None when unverified, at the (Šidák-corrected)
    ``level``; ``verdict`` says it in words. ``where`` says where the samples' mass departs
    from the density when the test failed ("too many samples near the centre (...), in every
    direction"; None otherwise); ``off_by_constant`` is True when the density integrates to a
    constant c != 1 but the samples follow its shape. ``observed`` and ``expected`` are the
    counts in equal-measure bins of the domain's natural coordinates, arrays of shape ``bins``
    (index [i0, i1, ...] along ``coordinates``).
    """

    outcome: str
    passed: bool | None
    p_value: float
    verdict: str
    where: str | None
    off_by_constant: bool
    statistic: float
    dof: int
    level: float
    pdf_integral: float
    pdf_integral_error: float
    coordinates: list[str]
    observed: np.ndarray
    expected: np.ndarray
    worst_bins: list[dict]
    raw: dict = field(repr=False)

    @classmethod
    def from_raw(cls, raw: dict) -> "WarpTest":
        bins = [int(b) for b in raw.get("bins") or []]

        def grid(key: str) -> np.ndarray:
            flat = _float_array(raw.get(key) or [])
            if bins and flat.size == int(np.prod(bins)):
                # The first coordinate varies fastest in the core's list.
                return flat.reshape(bins[::-1]).transpose()
            return flat

        def number(key: str) -> float:
            value = raw.get(key)
            return float(value) if isinstance(value, (int, float)) else math.nan

        return cls(
            outcome=str(raw.get("outcome") or ("passed" if raw.get("passed") else "failed")),
            passed=None if raw.get("passed") is None else bool(raw.get("passed")),
            p_value=number("p_value"),
            verdict=str(raw.get("verdict", "")),
            where=raw.get("where") if isinstance(raw.get("where"), str) else None,
            off_by_constant=bool(raw.get("off_by_constant", False)),
            statistic=number("statistic"),
            dof=int(raw.get("dof") or 0),
            level=number("level"),
            pdf_integral=number("pdf_integral"),
            pdf_integral_error=number("pdf_integral_error"),
            coordinates=list(raw.get("coordinates") or []),
            observed=grid("observed"),
            expected=grid("expected"),
            worst_bins=list(raw.get("worst_bins") or []),
            raw=raw,
        )

    def __str__(self) -> str:
        return self.verdict


def _warp_part(value: Any, name: str, functions: dict, function_name: str) -> Any:
    if callable(value):
        functions[function_name] = value
        return {"function": function_name}
    if isinstance(value, str):
        return value
    if isinstance(value, Sequence) and value and all(isinstance(v, str) for v in value):
        return list(value)
    raise argument_error(
        f"{name}: expected a callable, an expression or a list of expressions, "
        f"got {type(value).__name__}"
    )


def _warp_domain(domain: Any) -> dict | None:
    if domain is None or isinstance(domain, Mapping):
        return None if domain is None else dict(domain)
    return box_domain(domain)


def warp_test(
    g: Callable | str | Sequence[str] | Mapping,
    p: Callable | str | None = None,
    domain: Any = None,
    samples: int | None = None,
    seed: int | None = None,
    bins: Sequence[int] | None = None,
    sample_dim: int | None = None,
    significance: float | None = None,
    tests: int | None = None,
) -> WarpTest:
    """Test a warp x = g(u) against the density p(x) it claims: p's integral, then a chi-square
    test of ``samples`` warped points in equal-measure bins (docs/sampler-lab.md).

    ``g``: a numpy callable taking an ``(n, sample_dim)`` array of unit-cube points and returning
    ``(n, d)`` domain points, or expressions in ``u1, u2, u3`` (one per coordinate; a string in
    1-D); or a named warp (a name such as ``"concentric_disk"`` or a dict ``{"name": ...,
    parameters}``), then ``p`` is None. ``p``: a callable taking ``(n, d)`` points and returning
    ``(n,)`` densities, or an expression in ``x y z``. ``domain``: a scene domain dict (e.g.
    ``{"type": "disk", "radius": 1}``) or (lo, hi) pairs; default the unit box of g's length.
    ``samples`` (10^6), ``seed`` (1), ``significance`` (0.01), ``tests`` (Šidák's correction for
    that many tests run together) and ``bins`` (per natural coordinate) are the core's defaults
    when None. A failed test is a result (``passed`` False); a warp that cannot be tested (g
    leaves the domain, p negative or NaN) raises :class:`McplayError` naming the point.
    """
    functions: dict[str, Callable] = {}
    if p is None:
        if isinstance(g, str):
            warp: Any = g
        elif isinstance(g, Mapping):
            warp = dict(g)
        else:
            raise argument_error(
                "p: a warp given by g needs its density p (or give g as a named warp)"
            )
        if domain is not None or sample_dim is not None:
            raise argument_error("domain: a named warp has its own domain and sample dimension")
    else:
        warp = {}
        put(warp, "domain", _warp_domain(domain))
        warp["g"] = _warp_part(g, "g", functions, "g")
        if sample_dim is not None:
            if not callable(g):
                raise argument_error("sample_dim: only a callable g needs it")
            warp["g"]["sample_dim"] = whole_number(sample_dim, "sample_dim", 1)
        warp["p"] = _warp_part(p, "p", functions, "p")
        if isinstance(warp["p"], list):
            raise argument_error("p: expected one expression or a callable, got a list")
    options: dict[str, Any] = {}
    put(options, "samples", None if samples is None else whole_number(samples, "samples", 1))
    put(options, "seed", None if seed is None else whole_number(seed, "seed", 0))
    put(options, "tests", None if tests is None else whole_number(tests, "tests", 1))
    if significance is not None:
        options["significance"] = real_number(significance, "significance", positive=True)
    if bins is not None:
        if isinstance(bins, (str, bytes)) or not isinstance(bins, Sequence):
            raise argument_error(f"bins: expected a count per coordinate, got {bins!r}")
        options["bins"] = [whole_number(b, f"bins[{i}]", 1) for i, b in enumerate(bins)]
    scene = {"name": "warp_test", "warp": warp}
    text = _core.warp_test(to_json(scene, "warp"), to_json(options, "options"), functions)
    return WarpTest.from_raw(from_json(text))
