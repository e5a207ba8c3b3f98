"""Figures of a study with matplotlib (an optional dependency): the page's four plots.

Only drawing happens here: the points, bands, fitted orders and coverages are the core's.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from ._util import argument_error

if TYPE_CHECKING:  # pragma: no cover
    from .result import Result

KINDS = ("variance", "mse", "time", "calibration")


def _pyplot():
    try:
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError(
            "Result.plot() needs matplotlib, which is not installed: pip install matplotlib"
        ) from None
    return plt


def _axes(ax):
    if ax is not None:
        return ax
    plt = _pyplot()
    _, ax = plt.subplots(figsize=(6.4, 4.4))
    return ax


def _fit_label(fit: Any, what: str) -> str:
    if not (isinstance(fit, dict) and fit.get("valid")):
        return ""
    label = f" ({what} ~ N^({fit['order']:.2f} ± {fit['order_se']:.2f}))"
    p_value = fit.get("p_value")
    if isinstance(p_value, (int, float)) and p_value < 1e-3:
        label = f" (not a power law, χ² p = {p_value:.2g})"
    return label


def _reference_slopes(ax, n: np.ndarray, y: np.ndarray) -> None:
    """Dashed N^-1 and N^-2 through the first finite point, as the page draws them."""
    finite = np.isfinite(y) & (y > 0)
    if not finite.any():
        return
    n0, y0 = n[finite][0], y[finite][0]
    grid = np.array([n.min(), n.max()], dtype=float)
    for slope, style in ((-1, "--"), (-2, ":")):
        ax.plot(
            grid, y0 * (grid / n0) ** slope, style, color="0.5", linewidth=1, label=f"N^{slope}"
        )


def _ladder(result: "Result", kind: str, ax):
    ax = _axes(ax)
    measure = "mse" if kind == "mse" else "variance"
    fit_key = "mse_fit" if kind == "mse" else "fit"
    first = None
    for name, e in result.estimators.items():
        t = e.levels
        y = t[measure]
        if not np.isfinite(y).any():
            continue
        (line,) = ax.plot(
            t["n"], y, "o-", markersize=3, label=name + _fit_label(getattr(e, fit_key), measure)
        )
        if kind == "variance":
            ax.fill_between(
                t["n"],
                t["variance_lo"],
                t["variance_hi"],
                color=line.get_color(),
                alpha=0.15,
                linewidth=0,
            )
        fit = getattr(e, fit_key)
        if isinstance(fit, dict) and fit.get("valid") and fit.get("intercept") is not None:
            lo, hi = fit.get("n_first") or t["n"][0], fit.get("n_last") or t["n"][-1]
            grid = np.array([lo, hi], dtype=float)
            ax.plot(
                grid,
                np.exp(fit["intercept"]) * grid ** fit["order"],
                "-",
                color=line.get_color(),
                alpha=0.5,
                linewidth=3,
            )
        if first is None:
            first = (t["n"].astype(float), y)
    if first is None:
        what = "an exact value" if kind == "mse" else "a variance"
        raise argument_error(f"kind: no estimator has {what} to plot ({kind!r})")
    _reference_slopes(ax, *first)
    ax.set_xscale("log", base=2)
    ax.set_yscale("log")
    ax.set_xlabel(_n_name(result))
    ax.set_ylabel("MSE" if kind == "mse" else "variance of one estimate")
    ax.set_title(_title(result))
    ax.legend(fontsize="small")
    return ax


def _time(result: "Result", ax):
    ax = _axes(ax)
    has_exact = result.exact is not None
    for name, e in result.estimators.items():
        t = e.levels
        x = t["time_median_s"] if np.isfinite(t["time_median_s"]).any() else t["time_mean_s"]
        y = t["error"]
        keep = np.isfinite(x) & np.isfinite(y) & (y > 0)
        if not keep.any():
            continue
        (line,) = ax.plot(x[keep], y[keep], "o-", markersize=3, label=name)
        lo, hi = t["time_median_lo_s"][keep], t["time_median_hi_s"][keep]
        if np.isfinite(lo).all() and np.isfinite(hi).all():
            ax.hlines(y[keep], lo, hi, color=line.get_color(), alpha=0.4)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("median time per estimate (s)")
    ax.set_ylabel("RMSE" if has_exact else "standard deviation of one estimate")
    ax.set_title(_title(result))
    ax.legend(fontsize="small")
    return ax


def _z_scores(e, exact: float | None) -> np.ndarray:
    """(estimate - exact) / SE of every replicate; levels exact to round-off are left out."""
    z = []
    for level in e.raw.get("levels") or []:
        if level.get("exact_to_roundoff"):
            continue
        rep = level.get("replicates") or {}
        reference = exact if exact is not None else level.get("mean")
        if not isinstance(reference, (int, float)):
            continue
        for est, se in zip(rep.get("estimate") or [], rep.get("std_error") or [], strict=False):
            if isinstance(est, (int, float)) and isinstance(se, (int, float)) and se > 0:
                z.append((est - reference) / se)
    return np.array(z, dtype=float)


def _calibration(result: "Result", ax):
    plt = _pyplot()
    if ax is None:
        fig, (hist_ax, cover_ax) = plt.subplots(1, 2, figsize=(11, 4.2))
    else:
        try:
            hist_ax, cover_ax = ax
        except (TypeError, ValueError):
            raise argument_error("ax: the calibration plot needs a pair of Axes") from None
        fig = hist_ax.figure
    exact = result.exact
    edges = np.arange(-5.0, 5.0 + 1e-9, 0.5)
    grid = np.linspace(-5, 5, 201)
    hist_ax.plot(
        grid, np.exp(-0.5 * grid**2) / math.sqrt(2 * math.pi), "k-", linewidth=1.5, label="N(0, 1)"
    )
    for name, e in result.estimators.items():
        z = _z_scores(e, exact)
        if z.size:
            outside = int(np.sum(np.abs(z) >= 5))
            label = f"{name} ({z.size} runs" + (f", {outside} beyond ±5)" if outside else ")")
            hist_ax.hist(
                np.clip(z, -5, 5 - 1e-9),
                bins=edges,
                density=True,
                histtype="step",
                linewidth=1.5,
                label=label,
            )
        t = e.levels
        if np.isfinite(t["coverage95"]).any():
            cover_ax.plot(t["n"], t["coverage95"], "o-", markersize=3, label=name)
    reference = "exact" if exact is not None else "the level's mean"
    hist_ax.set_xlabel(f"(estimate - {reference}) / standard error")
    hist_ax.set_ylabel("density")
    hist_ax.set_title("calibration of the error bars")
    hist_ax.legend(fontsize="small")
    cover_ax.axhline(0.95, color="0.5", linestyle="--", linewidth=1, label="95%")
    cover_ax.set_xscale("log", base=2)
    cover_ax.set_ylim(0, 1.02)
    cover_ax.set_xlabel(_n_name(result))
    cover_ax.set_ylabel("coverage of the 95% intervals")
    if exact is None:
        cover_ax.set_title("coverage needs the exact value")
    cover_ax.legend(fontsize="small")
    return fig


def _n_name(result: "Result") -> str:
    return "samples per pixel" if result.raw.get("kind") == "render" else "N (samples per estimate)"


def _title(result: "Result") -> str:
    return str((result.raw.get("scene") or {}).get("name", ""))


def plot(result: "Result", kind: str = "variance", ax=None):
    """Draw ``result`` (see :meth:`mcplay.Result.plot`)."""
    if kind not in KINDS:
        raise argument_error(f"kind: expected one of {', '.join(KINDS)}, got {kind!r}")
    _pyplot()
    if result.kind == "stopping":
        raise argument_error(
            "kind: a run to a requested accuracy has no N ladder to plot; run without rel_tol/"
            "abs_tol to compare how the estimators converge"
        )
    if kind == "mse" and result.exact is None:
        raise argument_error("kind: 'mse' needs the exact value (give exact=...)")
    if kind in ("variance", "mse"):
        return _ladder(result, kind, ax)
    if kind == "time":
        return _time(result, ax)
    return _calibration(result, ax)
