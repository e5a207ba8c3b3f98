#!/usr/bin/env python3
"""mcplay from Python beside vegas and QMCPy on Genz's six families, one numpy callable per case.

    python_compare.py [--n N] [--reps R] [--rounds K] [--dims 4,8] [--families F,...]
                      [--jsonl PATH] [--only compare|speed] [--callable-vs-expression]

`make bench-python` (bench/python.mk) installs the package and the anchors in a venv and runs it;
docs/benchmarks.md, "From Python: beside vegas and QMCPy", has the figures.

The comparison (``--only compare``). Each case is a Genz family in dimension d with a and u drawn
once by Genz's normalisation (docs/scene-format.md, Integrands: a_i, u_i ~ U(0, 1), then
sum a_i = h / d^e) from numpy's generator seeded [PARAM_SEED, family, d]. Its exact value comes
from mcplay's closed form (``mcplay.scene_info``). The numpy callable (``genz`` of
bench/qmc_tools.py) is checked first: on the same points it gives the same estimate as the
core's own Genz integrand, and its estimate agrees with the exact value within 4 standard
errors. Every tool then integrates that callable, wrapped in one counter of evaluations:

- mcplay: round k (of ROUNDS) is one call of ``mcplay.integrate(f, estimators=[...], n=N,
  n_min=N, reps=R / ROUNDS, threads=1, exact=...)`` with seed SEED * 10^5 + case * 100 + k; the
  core gives each estimator's MSE against the exact value, the share of replicates whose own
  95% interval covered it, the seconds per estimate (the core's timer: the callable's time
  included, the call's setup not) and its flags (the table shows in how many rounds each
  warning or error was raised).
- vegas: ``vegas.Integrator`` on the batch integrand, 5 iterations of training (discarded) then
  5 of estimation, neval per iteration set by a pilot so that the 10 iterations call f about N
  times (training share 1/2); its error bar is 1.96 sdev, and the table counts the replicates
  whose Q (vegas's p-value for the iterations' agreement) is below 0.05; numpy's generator
  seeded [SEED, case, r] drives replicate r.
- QMCPy: ``CubQMCNetG`` (in QMCPy 2.4 ``CubQMCSobolG`` is the same class) and
  ``CubQMCLatticeG`` with n_init = n_limit = N (one pass of N points, no early stop); the
  interval is the cubature's [comb_bound_low, comb_bound_high], a guaranteed-style bound for
  integrands in its cone, not a 95% confidence interval; seed SEED * 10^6 + case * 1000 + r.

The tools take turns: round k of mcplay, then replicates k R / ROUNDS .. (k + 1) R / ROUNDS - 1
of each anchor, so that the shared machine's load falls on all of them alike.

Per (case, tool): relative RMSE over the R replicates, median seconds per estimate, efficiency
1 / (relMSE x seconds), coverage of the tool's own interval, evaluations per estimate (counted).
mcplay's best estimator per case is the most efficient of its candidates (a choice made after
the fact, as for the anchors' best); the ratios of sobol and sobol_walsh alone (fixed choices)
are reported beside it.

The speed check (``--only speed``): f = exp(x1 + ... + x4) as a numpy callable and as an
expression, N = 2^20, estimators uniform, sobol, vegas, threads 1 and 2, the same seeds; the
median wall time of 5 calls of ``mcplay.integrate`` per (path, estimator, threads), taking
turns; then where the callable's time goes (a constant callable against a constant expression,
numpy's own time on C-order and column-order blocks).

Every tool runs in this one process, one thread each (BLAS pinned to one thread before numpy
loads; mcplay's threads = 1). The GIL: the core calls the callable from its threads, one block
of points per call, each call holding the GIL, so a second thread would only overlap the core's
own work.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import platform
import statistics
import sys
import time
import warnings
from dataclasses import dataclass, field
from typing import Callable, Sequence

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from qmc_tools import genz  # noqa: E402  the numpy Genz families, as mcplay defines them

FAMILIES = ("oscillatory", "product_peak", "corner_peak", "gaussian", "continuous",
            "discontinuous")
#: Genz's normalisation (h, e) per family, as docs/scene-format.md states it.
GENZ_H_E = {"oscillatory": (110.0, 1.5), "product_peak": (600.0, 2.0),
            "corner_peak": (600.0, 2.0), "gaussian": (100.0, 1.0),
            "continuous": (150.0, 2.0), "discontinuous": (100.0, 2.0)}
#: mcplay's candidates; sobol_walsh is the like of QMCPy's CubQMCNetG (one net, the same bound).
MCPLAY_CANDIDATES = ("uniform", "sobol", "sobol_walsh", "lattice", "vegas", "vegas_sobol",
                     "vegas_plus", "miser")
Z95 = 1.959963984540054
#: Flags about the replicates' mean against the exact value (a chance event at 5%, and not a
#: judgement of an error bar): kept in the JSON lines, left out of the table.
CHANCE_FLAGS = ("exact_outside_ci",)


@dataclass
class Case:
    """One Genz family in dimension d with its parameters and exact value."""

    index: int
    family: str
    d: int
    a: list[float]
    u: list[float]
    exact: float = math.nan

    @property
    def name(self) -> str:
        return f"genz_{self.family}_d{self.d}"

    def integrand(self) -> dict:
        """The core's own integrand object for this case."""
        return {"type": f"genz_{self.family}", "a": self.a, "u": self.u}

    def callable(self) -> Callable[[np.ndarray], np.ndarray]:
        """The case as a numpy callable of an (n, d) array."""
        family_number = FAMILIES.index(self.family) + 1
        a, u = np.array(self.a), np.array(self.u)
        return lambda x: genz(family_number, a, u, x)


class Counted:
    """A callable that counts the points it was called on (the same wrapper for every tool)."""

    def __init__(self, f: Callable[[np.ndarray], np.ndarray]):
        self.f = f
        self.points = 0

    def __call__(self, x: np.ndarray) -> np.ndarray:
        self.points += x.shape[0]
        return self.f(x)


@dataclass
class Row:
    """One (case, tool, method): the summary over its replicates."""

    case: str
    tool: str
    method: str
    reps: int
    evaluations: float
    rel_rmse: float
    seconds: float
    coverage: float
    interval: str
    extra: dict = field(default_factory=dict)

    @property
    def efficiency(self) -> float:
        rel_mse = self.rel_rmse ** 2
        if not (rel_mse > 0 and self.seconds > 0):
            return math.inf if rel_mse == 0 else math.nan
        return 1.0 / (rel_mse * self.seconds)

    def label(self) -> str:
        return f"{self.tool} {self.method}"


def draw_cases(dims: Sequence[int], families: Sequence[str], param_seed: int) -> list[Case]:
    """The cases, parameters drawn once by Genz's normalisation from fixed seeds."""
    cases = []
    for family in families:
        for d in dims:
            rng = np.random.default_rng([param_seed, FAMILIES.index(family), d])
            a = rng.random(d)
            u = rng.random(d)
            h, e = GENZ_H_E[family]
            a *= h / d ** e / a.sum()
            cases.append(Case(len(cases), family, d, a.tolist(), u.tolist()))
    return cases


def check_case(mcplay, case: Case, seed: int) -> dict:
    """The exact value from mcplay's closed form, and the callable checked against the core:
    the same points give the same estimate as the core's Genz integrand (relative 1e-12), and
    the callable's estimate is within 4 standard errors of the exact value."""
    case.exact = float(mcplay.scene_info({"integrand": case.integrand()})["exact"])
    common = dict(estimators=["sobol"], n=1 << 14, n_min=1 << 14, reps=8, seed=seed, threads=1)
    ours = mcplay.integrate(case.callable(), dim=case.d, **common)["sobol"]
    core = mcplay.integrate(case.integrand(), **common)["sobol"]
    same = abs(ours.estimate - core.estimate) <= 1e-12 * abs(core.estimate) + 1e-300
    z = (ours.estimate - case.exact) / ours.stderr
    if not same or abs(z) > 4:
        raise SystemExit(f"python_compare: {case.name}: the numpy callable disagrees with the core "
                         f"(callable {ours.estimate!r}, core's integrand {core.estimate!r}, exact "
                         f"{case.exact!r}, z = {z:.2f})")
    return {"same_points_rel_diff": abs(ours.estimate - core.estimate) / abs(core.estimate),
            "z_callable_vs_exact": z}


def run_mcplay(mcplay, case: Case, n: int, reps: int, seed: int) -> dict[str, dict]:
    """``reps`` replicates of each of mcplay's candidates on the case's callable (one study, one
    thread): per estimator the core's mean squared error against the exact value, the share of
    the replicates whose own 95% interval covered it, the median seconds per estimate and the
    codes of its warning and error flags."""
    f = Counted(case.callable())
    wall = time.perf_counter()
    result = mcplay.integrate(f, dim=case.d, estimators=list(MCPLAY_CANDIDATES), n=n, n_min=n,
                              reps=reps, seed=seed, threads=1, exact=case.exact, name=case.name)
    wall = time.perf_counter() - wall
    out = {}
    for name in MCPLAY_CANDIDATES:
        level = result[name].raw["levels"][-1]
        out[name] = {"mse": float(level["mse"]), "covered": float(level["coverage95"]),
                     "seconds": float(level["time_median_s"]), "n": int(level["n"]),
                     "training_share": level.get("training_share"),
                     "error_method": result[name].error_method,
                     "flags": sorted({fl.code for fl in result[name].flags if fl.untrusted})}
    out["_call"] = {"wall_s": wall, "evaluations": f.points}
    return out


def mcplay_rows(case: Case, calls: list[dict[str, dict]], reps_per_call: int) -> list[Row]:
    """The mcplay rows of a case from its rounds (every number from the core): MSE and
    coverage averaged over the rounds (each of the same number of replicates), the median of
    the rounds' median seconds, and in how many rounds each warning or error flag was raised."""
    rows = []
    for name in MCPLAY_CANDIDATES:
        per_call = [call[name] for call in calls]
        flags: dict[str, int] = {}
        for c in per_call:
            for code in c["flags"]:
                flags[code] = flags.get(code, 0) + 1
        rows.append(Row(
            case.name, "mcplay", name, len(per_call) * reps_per_call,
            float(np.mean([c["n"] for c in per_call])),
            math.sqrt(statistics.fmean(c["mse"] for c in per_call)) / abs(case.exact),
            statistics.median(c["seconds"] for c in per_call),
            statistics.fmean(c["covered"] for c in per_call), "own 95% interval",
            {"error_method": per_call[0]["error_method"], "flag_rounds": flags,
             "rounds": len(calls),
             "training_share": statistics.fmean(c["training_share"] or 0.0 for c in per_call),
             "call_wall_s_median": statistics.median(c["_call"]["wall_s"] for c in calls),
             "counted_evaluations_per_call": statistics.fmean(
                 c["_call"]["evaluations"] for c in calls)}))
    return rows


@dataclass
class Replicates:
    """An anchor's replicates: estimates, the tool's own intervals, seconds, evaluations."""

    tool: str
    method: str
    interval: str
    estimates: list[float] = field(default_factory=list)
    lows: list[float] = field(default_factory=list)
    highs: list[float] = field(default_factory=list)
    seconds: list[float] = field(default_factory=list)
    evaluations: list[int] = field(default_factory=list)
    #: vegas only: each replicate's Q, the p-value of its iterations' agreement (chi-square).
    vegas_q: list[float] = field(default_factory=list)

    def add(self, estimate: float, low: float, high: float, seconds: float, evaluations: int):
        self.estimates.append(estimate)
        self.lows.append(low)
        self.highs.append(high)
        self.seconds.append(seconds)
        self.evaluations.append(evaluations)

    def row(self, case: Case) -> Row:
        """The summary row against the case's exact value."""
        err = np.asarray(self.estimates) - case.exact
        covered = [lo <= case.exact <= hi for lo, hi in zip(self.lows, self.highs)]
        return Row(case.name, self.tool, self.method, len(self.estimates),
                   float(np.mean(self.evaluations)),
                   float(np.sqrt(np.mean(err ** 2))) / abs(case.exact),
                   float(statistics.median(self.seconds)), float(np.mean(covered)),
                   self.interval)


def vegas_neval(vegas, case: Case, n: int, seed: int) -> int:
    """neval per iteration such that 10 iterations call f about n times (two untimed pilots)."""
    neval = n // 10
    for _ in range(2):
        f = Counted(case.callable())
        rng = np.random.default_rng([seed, case.index, 1 << 30])
        integ = vegas.Integrator([[0.0, 1.0]] * case.d, ran_array_generator=rng.random)
        batch = vegas.lbatchintegrand(f)
        integ(batch, nitn=5, neval=neval)
        integ(batch, nitn=5, neval=neval)
        neval = max(16, int(round(neval * n / f.points)))
    return neval


def run_vegas(vegas, case: Case, neval: int, seed: int, r: int, out: Replicates) -> None:
    """Replicate r of vegas.Integrator: 5 training iterations (discarded), then 5 estimating."""
    f = Counted(case.callable())
    batch = vegas.lbatchintegrand(f)
    rng = np.random.default_rng([seed, case.index, r])
    integ = vegas.Integrator([[0.0, 1.0]] * case.d, ran_array_generator=rng.random)
    start = time.perf_counter()
    integ(batch, nitn=5, neval=neval)
    result = integ(batch, nitn=5, neval=neval)
    seconds = time.perf_counter() - start
    out.add(result.mean, result.mean - Z95 * result.sdev, result.mean + Z95 * result.sdev,
            seconds, f.points)
    out.vegas_q.append(float(result.Q))


def run_qmcpy(qp, case: Case, n: int, seed: int, r: int, lattice: bool,
              out: Replicates) -> None:
    """Replicate r of QMCPy's CubQMCNetG (= CubQMCSobolG) or CubQMCLatticeG: one pass of n
    points (n_init = n_limit = n, tolerances 0)."""
    f = Counted(case.callable())
    s = seed * 1_000_000 + case.index * 1000 + r
    points = qp.Lattice(case.d, seed=s) if lattice else qp.DigitalNetB2(case.d, seed=s)
    integrand = qp.CustomFun(qp.Uniform(points), g=f)
    cls = qp.CubQMCLatticeG if lattice else qp.CubQMCNetG
    cubature = cls(integrand, abs_tol=0.0, rel_tol=0.0, n_init=n, n_limit=n)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # MaxSamplesWarning: n_limit is the budget
        start = time.perf_counter()
        solution, data = cubature.integrate()
        seconds = time.perf_counter() - start
    out.add(float(solution), float(data.comb_bound_low), float(data.comb_bound_high), seconds,
            f.points)


def fmt_row(row: Row) -> str:
    """A table line; the flags: mcplay's warning and error codes with the share of rounds that
    raised them, vegas's replicates whose Q (iterations' agreement) is below 0.05."""
    if "flag_rounds" in row.extra:
        shown = {c: k for c, k in row.extra["flag_rounds"].items() if c not in CHANCE_FLAGS}
        flags = " ".join(f"{c} {k}/{row.extra['rounds']}" for c, k in sorted(shown.items()))
    elif "q_below_0.05" in row.extra:
        flags = f"Q<0.05 {row.extra['q_below_0.05']}/{row.reps}"
    else:
        flags = ""
    return (f"  {row.label():<26} {row.evaluations:>8.0f} {row.rel_rmse:>10.3e} "
            f"{row.seconds:>9.2e} {row.efficiency:>11.3e} {row.coverage:>6.2f}  {flags}")


def compare(mcplay, o: argparse.Namespace, out) -> None:
    """The side-by-side comparison on the Genz cases."""
    import qmcpy as qp
    import vegas

    families = FAMILIES if o.families == "all" else tuple(o.families.split(","))
    cases = draw_cases(o.dims, families, o.param_seed)
    print(f"# mcplay {mcplay.__version__}, vegas {vegas.__version__}, qmcpy {qp.__version__}, "
          f"numpy {np.__version__}; N = {o.n}, {o.reps} replicates, seed {o.seed}, "
          f"params seed {o.param_seed}; one thread each", flush=True)
    summary: list[dict] = []
    coverage: dict[str, list[float]] = {}
    for case in cases:
        checks = check_case(mcplay, case, o.seed)
        neval = vegas_neval(vegas, case, o.n, o.seed)
        anchors = [Replicates("vegas", "Integrator", "mean +- 1.96 sdev"),
                   Replicates("qmcpy", "CubQMCNetG", "guaranteed-style bound"),
                   Replicates("qmcpy", "CubQMCLatticeG", "guaranteed-style bound")]
        rounds = []
        per_round = o.reps // o.rounds
        # The tools take turns, one round of replicates each, so that the shared machine's load
        # falls on all of them alike.
        for k in range(o.rounds):
            seed = o.seed * 100_000 + case.index * 100 + k
            rounds.append(run_mcplay(mcplay, case, o.n, per_round, seed))
            for r in range(k * per_round, (k + 1) * per_round):
                run_vegas(vegas, case, neval, o.seed, r, anchors[0])
                run_qmcpy(qp, case, o.n, o.seed, r, False, anchors[1])
                run_qmcpy(qp, case, o.n, o.seed, r, True, anchors[2])
        rows = mcplay_rows(case, rounds, per_round)
        q_low = sum(q < 0.05 for q in anchors[0].vegas_q)
        anchors = [a.row(case) for a in anchors]
        anchors[0].extra.update({"neval": neval, "q_below_0.05": q_low})
        best = max(rows, key=lambda r: r.efficiency)
        anchor = max(anchors, key=lambda r: r.efficiency)
        alone = {r.method: r.efficiency / anchor.efficiency for r in rows}
        line = {"case": case.name, "family": case.family, "d": case.d, "exact": case.exact,
                "a": case.a, "u": case.u, "checks": checks,
                "best_mcplay": best.method, "best_anchor": anchor.label(),
                "coverage_best_mcplay": best.coverage, "coverage_best_anchor": anchor.coverage,
                "ratio_best": best.efficiency / anchor.efficiency,
                "ratio_sobol": alone["sobol"], "ratio_sobol_walsh": alone["sobol_walsh"]}
        summary.append(line)
        print(f"\n{case.name}  exact {case.exact:.10g}  (callable vs core's integrand on the same "
              f"points: relative difference {checks['same_points_rel_diff']:.1e}; z against exact "
              f"{checks['z_callable_vs_exact']:+.2f})")
        print(f"  {'tool method':<26} {'evals':>8} {'rel.RMSE':>10} {'s/est':>9} "
              f"{'efficiency':>11} {'cover':>6}  flags (rounds)")
        for row in rows + anchors:
            print(fmt_row(row) + ("  <- best mcplay" if row is best else "")
                  + ("  <- best anchor" if row is anchor else ""))
            out.write(json.dumps({"kind": "row", "case": case.name, "tool": row.tool,
                                  "method": row.method, "reps": row.reps,
                                  "evaluations": row.evaluations, "rel_rmse": row.rel_rmse,
                                  "seconds_median": row.seconds,
                                  "efficiency": row.efficiency, "coverage": row.coverage,
                                  "interval": row.interval, **row.extra}) + "\n")
            coverage.setdefault(row.label(), []).append(row.coverage)
        print(f"  mcplay best / anchor best = {line['ratio_best']:.3g}x "
              f"({best.method} / {anchor.label()}); sobol alone {alone['sobol']:.3g}x, "
              f"sobol_walsh alone {alone['sobol_walsh']:.3g}x", flush=True)
        out.write(json.dumps({"kind": "case", **line}) + "\n")
        out.flush()

    def geomean(key: str) -> float:
        return math.exp(statistics.fmean(math.log(s[key]) for s in summary))

    leads = sum(s["ratio_best"] > 1 for s in summary)
    print("\n# summary: efficiency of mcplay's best estimator / the best anchor's "
          "(coverage of each one's own interval)")
    print(f"  {'case':<26} {'mcplay best':<12} {'cover':>5}  {'best anchor':<21} {'cover':>5} "
          f"{'ratio':>8} {'sobol':>8} {'s_walsh':>8}")
    for s in summary:
        print(f"  {s['case']:<26} {s['best_mcplay']:<12} {s['coverage_best_mcplay']:>5.2f}  "
              f"{s['best_anchor']:<21} {s['coverage_best_anchor']:>5.2f} {s['ratio_best']:>8.3g} "
              f"{s['ratio_sobol']:>8.3g} {s['ratio_sobol_walsh']:>8.3g}")
    geo = {key: geomean(key) for key in ("ratio_best", "ratio_sobol", "ratio_sobol_walsh")}
    print(f"  geometric mean of the ratio: best {geo['ratio_best']:.3g}x, sobol alone "
          f"{geo['ratio_sobol']:.3g}x, sobol_walsh alone {geo['ratio_sobol_walsh']:.3g}x; "
          f"mcplay's best leads in {leads} of {len(summary)} cases")
    print("\n# coverage of each tool's own interval over the cases: mean, lowest")
    for label, values in coverage.items():
        print(f"  {label:<26} {statistics.fmean(values):.3f}  {min(values):.2f}")
    out.write(json.dumps({"kind": "summary", "geometric_mean_ratio": geo["ratio_best"],
                          "geometric_mean_ratio_sobol": geo["ratio_sobol"],
                          "geometric_mean_ratio_sobol_walsh": geo["ratio_sobol_walsh"],
                          "leads": leads, "cases": len(summary),
                          "coverage_mean": {k: statistics.fmean(v) for k, v in coverage.items()},
                          "coverage_min": {k: min(v) for k, v in coverage.items()}}) + "\n")


def median_seconds(mcplay, fs: dict, runs: int, **kwargs) -> tuple[dict, dict]:
    """Median wall seconds of ``runs`` calls of mcplay.integrate per entry of ``fs`` (the
    entries take turns), and each entry's last (estimate, standard error)."""
    times: dict[str, list[float]] = {key: [] for key in fs}
    means = {}
    for _ in range(runs):
        for key, f in fs.items():
            start = time.perf_counter()
            r = mcplay.integrate(f, **kwargs)
            times[key].append(time.perf_counter() - start)
            means[key] = (r.estimate, r.stderr)
    return {key: statistics.median(t) for key, t in times.items()}, means


def speed(mcplay, o: argparse.Namespace, out) -> None:
    """The callable path against the expression path, f = exp(x1 + x2 + x3 + x4), and where
    the callable's time goes."""
    d, n, reps, runs = 4, 1 << 20, 4, 5
    paths = {"callable": lambda x: np.exp(x.sum(1)),
             "expression": "exp(" + " + ".join(f"x{i + 1}" for i in range(d)) + ")"}
    common = dict(dim=d, n=n, n_min=n, reps=reps, seed=o.seed)
    print(f"\n# callable vs expression: exp(sum x) in d = {d}, N = {n}, {reps} replicates per "
          f"call, median wall seconds of {runs} calls of mcplay.integrate (taking turns)")
    print(f"  {'estimator':<10} {'threads':>7} {'callable s':>11} {'expression s':>13} "
          f"{'ratio':>6} {'|mean diff|/se':>15}")
    for threads in (1, 2):
        for estimator in ("uniform", "sobol", "vegas"):
            walls, means = median_seconds(mcplay, paths, runs, estimators=[estimator],
                                          threads=threads, **common)
            ratio = walls["callable"] / walls["expression"]
            diff = abs(means["callable"][0] - means["expression"][0]) / means["expression"][1]
            print(f"  {estimator:<10} {threads:>7} {walls['callable']:>11.3f} "
                  f"{walls['expression']:>13.3f} {ratio:>6.2f} {diff:>15.1e}", flush=True)
            out.write(json.dumps({"kind": "speed", "estimator": estimator, "threads": threads,
                                  "n": n, "reps": reps, "runs": runs,
                                  "callable_s": walls["callable"],
                                  "expression_s": walls["expression"], "ratio": ratio,
                                  "mean_diff_over_se": diff}) + "\n")

    # Where the callable's time goes (uniform, one thread): a callable that returns a constant
    # against the expression "1" (the cost of a call across the bridge), and numpy's own time
    # for f on the same blocks, as the core passes them (C order, (4096, d)) and in column
    # order (the core's coordinate arrays).
    ones = np.ones(4096)
    walls, _ = median_seconds(
        mcplay, {"constant callable": lambda x: ones[: x.shape[0]].copy(),
                 "constant expression": "1 + 0 * x1",
                 "callable, copied to column order": lambda x: np.exp(
                     np.asfortranarray(x).sum(1))},
        runs, estimators=["uniform"], threads=1, **common)
    block = np.random.default_rng(1).random((4096, d))
    calls = reps * n // 4096
    for order, x in (("C order", block), ("column order", np.asfortranarray(block))):
        start = time.perf_counter()
        for _ in range(calls):
            paths["callable"](x)
        walls[f"numpy alone, {order}"] = time.perf_counter() - start
    print(f"\n# where the callable's time goes (uniform, 1 thread, {calls} blocks of 4096)")
    for key, seconds in walls.items():
        print(f"  {key:<34} {seconds:>7.3f} s")
    out.write(json.dumps({"kind": "speed_detail", "calls": calls, **walls}) + "\n")


def dims_list(text: str) -> list[int]:
    """``--dims``: comma-separated dimensions, each 2..64 (Genz's discontinuous family uses two
    coordinates)."""
    try:
        dims = [int(part) for part in text.split(",")]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected integers like 4,8, got {text!r}") from None
    if not dims or any(not 2 <= d <= 64 for d in dims):
        raise argparse.ArgumentTypeError(f"each dimension must be in 2..64, got {text!r}")
    return dims


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=1 << 16, help="evaluations per estimate (2^16)")
    ap.add_argument("--reps", type=int, default=100, help="replicates per (case, tool) (100)")
    ap.add_argument("--rounds", type=int, default=4,
                    help="the tools take turns in this many rounds of reps / rounds replicates")
    ap.add_argument("--dims", type=dims_list, default=[4, 8], help="comma-separated (4,8)")
    ap.add_argument("--families", default="all", help="comma-separated, e.g. gaussian,continuous")
    ap.add_argument("--seed", type=int, default=47, help="the replicates' seeds derive from it")
    ap.add_argument("--param-seed", type=int, default=2026, help="the Genz parameters' seed")
    ap.add_argument("--jsonl", default="build/bench-python/compare.jsonl",
                    help="where the JSON lines go (one per row, case, summary, speed cell)")
    ap.add_argument("--only", choices=("compare", "speed"), help="one part only")
    ap.add_argument("--callable-vs-expression", action="store_true",
                    help="the same as --only speed")
    o = ap.parse_args()
    if o.callable_vs_expression:
        o.only = "speed"
    if o.n < 1024 or o.n & (o.n - 1):
        ap.error("--n must be a power of two >= 1024 (QMCPy's nets)")
    if o.rounds < 1 or o.reps % o.rounds or o.reps // o.rounds < 2 or o.reps > 1000:
        ap.error("--reps must be at most 1000 and a multiple of --rounds, with at least 2 "
                 "replicates per round (mcplay's variance needs two)")
    unknown = set(o.families.split(",")) - set(FAMILIES) if o.families != "all" else set()
    if unknown:
        ap.error(f"--families: unknown {sorted(unknown)}; known: {', '.join(FAMILIES)}")

    import mcplay

    os.makedirs(os.path.dirname(os.path.abspath(o.jsonl)), exist_ok=True)
    print(f"# {time.strftime('%Y-%m-%d %H:%M')} on {platform.node()}: {os.cpu_count()} cores, "
          f"load {os.getloadavg()[0]:.2f}; python {platform.python_version()}; "
          f"{' '.join(sys.argv)}", flush=True)
    start = time.perf_counter()
    with open(o.jsonl, "w") as out:
        if o.only in (None, "compare"):
            compare(mcplay, o, out)
        if o.only in (None, "speed"):
            speed(mcplay, o, out)
    print(f"\n# {time.perf_counter() - start:.0f} s; load {os.getloadavg()[0]:.2f}; "
          f"JSON lines in {o.jsonl}")


if __name__ == "__main__":
    main()
