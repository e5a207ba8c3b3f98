"""A study's result as Python objects: :class:`Result`, :class:`EstimatorResult`, :class:`Flag`.

Every number is read from the core's result dict (``Result.raw``); nothing is recomputed but the
95% half-width of an interval the core gives, (hi - lo) / 2.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

import numpy as np

from . import _core
from ._util import argument_error, to_json

#: Severities that say an estimate or its error bar cannot be trusted (docs/result-schema.md).
UNTRUSTED = ("error", "warning")
_SEVERITY_ORDER = {"error": 0, "warning": 1, "info": 2}

#: The per-level columns of ``levels`` and ``to_pandas()``: column name -> the level's field.
LEVEL_COLUMNS: dict[str, tuple[str, ...]] = {
    "n": ("n",),
    "reps": ("reps",),
    "mean": ("mean",),
    "variance": ("variance",),
    "variance_lo": ("variance_ci95", "0"),
    "variance_hi": ("variance_ci95", "1"),
    "std_error": ("std_error",),
    "ci_lo": ("ci95", "0"),
    "ci_hi": ("ci95", "1"),
    "bias": ("bias",),
    "mse": ("mse",),
    "rmse": ("rmse",),
    "error": ("error",),
    "coverage95": ("coverage95",),
    "mean_run_std_error": ("mean_run_std_error",),
    "run_dof": ("run_dof",),
    "time_mean_s": ("time_mean_s",),
    "time_median_s": ("time_median_s",),
    "time_median_lo_s": ("time_median_ci95_s", "0"),
    "time_median_hi_s": ("time_median_ci95_s", "1"),
    "efficiency": ("efficiency",),
    "training_share": ("training_share",),
    "ess": ("ess",),
    "tail_index": ("tail_index",),
    "nonfinite": ("diagnostics", "nonfinite"),
    "zero_pdf": ("diagnostics", "zero_pdf"),
    "max_weight_share": ("diagnostics", "max_weight_share"),
}
_INTEGER_COLUMNS = ("n", "reps")


def _field(level: Mapping, path: tuple[str, ...]) -> float:
    value: Any = level
    for key in path:
        if isinstance(value, list):
            value = value[int(key)] if int(key) < len(value) else None
        elif isinstance(value, Mapping):
            value = value.get(key)
        else:
            value = None
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return math.nan
    return float(value)


def level_columns(levels: list[Mapping]) -> dict[str, np.ndarray]:
    """The levels of one estimator as numpy columns (null and missing numbers are NaN)."""
    table: dict[str, np.ndarray] = {}
    for name, path in LEVEL_COLUMNS.items():
        values = [_field(level, path) for level in levels]
        if name in _INTEGER_COLUMNS:
            table[name] = np.array(values, dtype=np.int64)
        else:
            table[name] = np.array(values, dtype=np.float64)
    return table


@dataclass(frozen=True)
class Flag:
    """A diagnostic the core raised: its stable ``code``, ``severity`` and ``message`` in words.

    ``severity`` is ``"error"`` (the estimate or its error bar is wrong), ``"warning"`` (the error
    bar cannot be trusted at this N) or ``"info"`` (worth knowing). ``estimator`` and ``n`` say
    where it was raised (``n`` None: about the estimator as a whole); ``details`` holds the other
    fields the core gave (``value``, ``threshold``, ...).
    """

    code: str
    severity: str
    message: str
    estimator: str | None = None
    n: int | None = None
    details: Mapping[str, Any] = field(default_factory=dict, compare=False)

    @classmethod
    def from_raw(cls, raw: Mapping, estimator: str | None = None, n: int | None = None) -> "Flag":
        details = {k: v for k, v in raw.items() if k not in ("code", "severity", "message")}
        return cls(
            code=str(raw.get("code", "")),
            # A flag without a severity (a hand-made result) reads as a warning, as on the page.
            severity=str(raw.get("severity", "warning")),
            message=str(raw.get("message", "")),
            estimator=estimator,
            n=n,
            details=details,
        )

    @property
    def untrusted(self) -> bool:
        """Whether the flag says the estimate or its error bar cannot be trusted."""
        return self.severity in UNTRUSTED

    def __str__(self) -> str:
        severity = self.severity.upper() if self.untrusted else self.severity
        where = f" [{self.estimator}]" if self.estimator else ""
        return f"{severity} {self.code}{where}: {self.message}"


def _flags_of(raw_flags: Any, estimator: str | None, n: int | None) -> list[Flag]:
    return [Flag.from_raw(f, estimator, n) for f in raw_flags or [] if isinstance(f, Mapping)]


def _sorted(flags: list[Flag]) -> list[Flag]:
    return sorted(flags, key=lambda f: _SEVERITY_ORDER.get(f.severity, 1))


@dataclass(frozen=True)
class Stopping:
    """How a run to a requested accuracy ended, for one estimator.

    ``met`` is true when every replicate's run met the tolerance under the stopping rule (its
    error bar trusted and confirmed by the run at N/2); ``n`` and ``evaluations`` are the first
    replicate's, the answer :attr:`Result.estimate` reports; ``seconds`` its time.
    """

    met: bool
    runs_met: int
    runs: int
    reason: str
    n: int
    evaluations: int
    seconds: float
    evaluations_median: float
    seconds_median: float
    within_tolerance: int | None
    rel_tol: float | None
    abs_tol: float | None


class EstimatorResult:
    """One estimator of a study: its estimate at the largest N, error bar, fitted order, flags
    and per-level table. Read from ``raw`` (the estimator's object in the result dict)."""

    def __init__(self, raw: Mapping, kind: str, stopping: Mapping | None = None):
        self.raw = raw
        self.name: str = raw.get("name", "")
        self.kind: str | None = raw.get("kind")
        self.method: str | None = raw.get("method")
        self.sampler: str | None = raw.get("sampler")
        self.pdf: str | None = raw.get("pdf")
        self.pdf_text: str | None = raw.get("pdf_text")
        self.error_method: str | None = raw.get("error_method")
        self._study_kind = kind
        levels = raw.get("levels") or []
        self.levels: dict[str, np.ndarray] = level_columns(levels)
        self.fit: Mapping = raw.get("fit") or {}
        self.mse_fit: Mapping = raw.get("mse_fit") or {}
        flags = _flags_of(raw.get("warnings"), self.name, None)
        self.stopping: Stopping | None = None
        if kind == "stopping":
            runs = raw.get("runs") or []
            first = runs[0] if runs else {}
            self.estimate = _number(first.get("estimate"))
            self.stderr = _number(first.get("std_error"))
            self.error_bar = _number(first.get("half_width"))
            self.n = int(first.get("n") or 0)
            for flag in first.get("flags") or []:
                flags.append(Flag.from_raw(flag, self.name, self.n))
            self.stopping = Stopping(
                met=bool(runs) and all(r.get("met") for r in runs),
                runs_met=int(raw.get("met") or 0),
                runs=len(runs),
                reason=str(first.get("reason", "")),
                n=self.n,
                evaluations=int(first.get("evaluations") or 0),
                seconds=_number(first.get("seconds")),
                evaluations_median=_number(raw.get("evaluations_median")),
                seconds_median=_number(raw.get("seconds_median")),
                within_tolerance=raw.get("within_tolerance"),
                rel_tol=(stopping or {}).get("rel_tol"),
                abs_tol=(stopping or {}).get("abs_tol"),
            )
            self._last_level: Mapping = {}
        else:
            last = levels[-1] if levels else {}
            self._last_level = last
            self.n = int(last.get("n") or 0)
            self.estimate = _number(last.get("mean"))
            self.stderr = _number(last.get("std_error"))
            ci = last.get("ci95")
            if isinstance(ci, list) and len(ci) == 2 and all(_is_number(v) for v in ci):
                self.error_bar = (ci[1] - ci[0]) / 2.0
            else:
                self.error_bar = math.nan
            # Level flags repeat from N to N: each code once, at the largest N it was raised
            # (as the CLI's table shows them); the largest level's flags are all kept.
            seen: dict[str, Flag] = {}
            for level in levels:
                for flag in _flags_of(level.get("warnings"), self.name, level.get("n")):
                    seen[flag.code] = flag
            flags.extend(seen.values())
        self.flags: list[Flag] = _sorted(flags)

    @property
    def order(self) -> float:
        """The fitted order of the variance (relative MSE for renders) against N (NaN if none)."""
        return _number(self.fit.get("order")) if self.fit.get("valid") else math.nan

    @property
    def order_se(self) -> float:
        """The fitted order's standard error (NaN if no valid fit)."""
        return _number(self.fit.get("order_se")) if self.fit.get("valid") else math.nan

    @property
    def trusted(self) -> bool:
        """Whether the error bar at the largest N can be believed: an estimate and a finite error
        bar, no error or warning flag of the estimator or of its largest level (for a stopping
        run: of its first replicate's answer), and a random estimator (a deterministic point set
        has no error bar)."""
        if not (math.isfinite(self.estimate) and math.isfinite(self.error_bar)):
            return False
        if self._last_level.get("deterministic"):
            return False
        if any(f.untrusted and (f.n is None or f.n == self.n) for f in self.flags):
            return False
        return True

    def __repr__(self) -> str:
        order = (
            "" if math.isnan(self.order) else f", order {self.order:.3f} +/- {self.order_se:.3f}"
        )
        flags = f", {len(self.flags)} flag(s)" if self.flags else ""
        return (
            f"<EstimatorResult {self.name}: {self.estimate:.10g} +/- {self.error_bar:.3g} "
            f"(95%) at N = {self.n}{order}{flags}>"
        )


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _number(value: Any) -> float:
    return float(value) if _is_number(value) else math.nan


class Result:
    """A study's result: the recommended estimate with its error bar, each estimator, the flags.

    ``Result(d)`` wraps the dict :func:`mcplay.run` returns for an integration study or a run to
    a requested accuracy; :func:`mcplay.integrate` returns one.

    The recommended estimator, :attr:`best`, is the one with the smallest 95% error bar at the
    largest N among those whose error bar can be trusted (:attr:`EstimatorResult.trusted`: no
    error or warning flag of the estimator or of that level, a random estimator); when none can
    be, the smallest error bar among all, and :attr:`trusted` is False. For a run to a requested
    accuracy, the estimator whose replicates all met the tolerance with the fewest evaluations
    (median over the replicates), else the one of the smallest error bar.
    """

    def __init__(self, raw: Mapping):
        if not isinstance(raw, Mapping) or not isinstance(raw.get("estimators"), list):
            raise argument_error("result: expected a study result dict (with an estimators list)")
        if raw.get("kind") in ("study_part", "stopping_part"):
            raise argument_error("result: a part of a study; merge the parts first (mcplay.merge)")
        if raw.get("kind") == "render":
            raise argument_error("result: a render study; Result reads integration studies")
        self._set(dict(raw))

    def _set(self, raw: dict) -> None:
        self.raw: dict = raw
        self.kind: str = raw.get("kind") or "study"
        stopping = raw.get("stopping") if self.kind == "stopping" else None
        self.estimators: dict[str, EstimatorResult] = {}
        for e in raw["estimators"]:
            self.estimators[e.get("name", "")] = EstimatorResult(e, self.kind, stopping)
        self.best: EstimatorResult | None = self._choose()

    def _choose(self) -> EstimatorResult | None:
        candidates = list(self.estimators.values())
        if not candidates:
            return None
        if self.kind == "stopping":
            met = [e for e in candidates if e.stopping and e.stopping.met and e.trusted]
            if met:
                return min(met, key=lambda e: e.stopping.evaluations_median)
        trusted = [e for e in candidates if e.trusted]
        pool = trusted or [e for e in candidates if math.isfinite(e.error_bar)] or candidates
        return min(pool, key=lambda e: e.error_bar if math.isfinite(e.error_bar) else math.inf)

    # --- the recommended estimate -------------------------------------------------------------
    @property
    def estimate(self) -> float:
        """The recommended estimator's estimate (the mean of its replicates at the largest N)."""
        return self.best.estimate if self.best else math.nan

    @property
    def error_bar(self) -> float:
        """Its 95% error bar: the half-width of the Student-t interval of that mean."""
        return self.best.error_bar if self.best else math.nan

    @property
    def stderr(self) -> float:
        """Its standard error."""
        return self.best.stderr if self.best else math.nan

    @property
    def trusted(self) -> bool:
        """Whether the recommended estimator's error bar can be trusted (see :attr:`best`)."""
        return bool(self.best and self.best.trusted)

    @property
    def exact(self) -> float | None:
        """The exact value, when the scene gives or knows it."""
        value = (self.raw.get("scene") or {}).get("exact")
        return float(value) if _is_number(value) else None

    @property
    def flags(self) -> list[Flag]:
        """Every estimator's flags, most severe first (each names its estimator and N)."""
        return _sorted([f for e in self.estimators.values() for f in e.flags])

    @property
    def levels(self) -> dict[str, dict[str, np.ndarray]]:
        """Per estimator, its levels as numpy columns (``n``, ``mean``, ``variance``, ...)."""
        return {name: e.levels for name, e in self.estimators.items()}

    @property
    def stopping(self) -> Stopping | None:
        """For a run to a requested accuracy: how the recommended estimator's runs ended."""
        return self.best.stopping if self.best else None

    def __getitem__(self, name: str) -> EstimatorResult:
        try:
            return self.estimators[name]
        except KeyError:
            known = ", ".join(self.estimators)
            raise KeyError(f"no estimator {name!r} in this result (it has: {known})") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self.estimators)

    def __len__(self) -> int:
        return len(self.estimators)

    def to_pandas(self):
        """The levels in long format: one row per estimator and N (pandas needed)."""
        try:
            import pandas as pd
        except ImportError:
            raise ImportError(
                "Result.to_pandas() needs pandas, which is not installed: pip install pandas"
            ) from None
        frames = []
        for name, e in self.estimators.items():
            if self.kind == "stopping":
                frames.append(pd.DataFrame(_stopping_rows(name, e.raw)))
                continue
            frame = pd.DataFrame(e.levels)
            frame.insert(0, "estimator", name)
            frames.append(frame)
        if not frames:
            return pd.DataFrame()
        return pd.concat(frames, ignore_index=True)

    def format(self, fmt: str = "table") -> str:
        """The result as the CLI prints it: ``"table"``, ``"csv"`` or ``"json"``."""
        return _core.call("result_format", to_json(self.raw, "result"), fmt)

    def __repr__(self) -> str:
        return self.format("table")

    def __str__(self) -> str:
        return self.format("table")

    def plot(self, kind: str = "variance", ax=None):
        """Plot the study as the page does (matplotlib needed).

        ``kind``: ``"variance"`` (variance against N on log-log axes, 95% bands, the fitted
        order and the reference slopes N^-1 and N^-2), ``"mse"`` (the same of the MSE; needs
        the exact value), ``"time"`` (RMSE, or the standard deviation without an exact value,
        against the median time per estimate) or ``"calibration"`` (histogram of
        (estimate - exact) / SE over every replicate against N(0, 1), beside the coverage of the
        95% intervals per N). Returns the matplotlib Axes (a Figure for ``"calibration"``,
        which draws two panels; ``ax`` may then be a pair of Axes).
        """
        from . import plot as _plot

        return _plot.plot(self, kind, ax)

    def __getstate__(self) -> dict:
        return {"raw": self.raw}

    def __setstate__(self, state: dict) -> None:
        self._set(state["raw"])

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Result) and other.raw == self.raw

    __hash__ = None  # type: ignore[assignment]


def _stopping_rows(name: str, raw: Mapping) -> list[dict]:
    rows = []
    for i, run in enumerate(raw.get("runs") or []):
        rows.append(
            {
                "estimator": name,
                "replicate": i,
                "estimate": _number(run.get("estimate")),
                "std_error": _number(run.get("std_error")),
                "half_width": _number(run.get("half_width")),
                "target": _number(run.get("target")),
                "met": bool(run.get("met")),
                "reason": run.get("reason"),
                "n": int(run.get("n") or 0),
                "evaluations": int(run.get("evaluations") or 0),
                "seconds": _number(run.get("seconds")),
                "within_tolerance": run.get("within_tolerance"),
            }
        )
    return rows
