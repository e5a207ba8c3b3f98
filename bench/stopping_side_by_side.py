#!/usr/bin/env python3
"""mcplay's stopping rule beside QMCPy's tolerance-based cubatures, on the same integrals.

  python3 bench/stopping_side_by_side.py PARAMS_DIR... [--reps 5] [--qmcpy QMCPY.jsonl]

PARAMS_DIR holds Genz test integrals as JSON ({"name", "family" 1-7, "d", "a", "u", "exact"}:
the format of the Genz battery harness, docs/benchmarks.md). Each is run by mcplay's CLI to a
relative tolerance, R replicates: randomized QMC (the "sobol", "lattice" and "halton" presets) at
1e-3, plain points ("uniform") at 1e-2, N doubling from 1024 to 2^24. With --qmcpy, JSON lines of QMCPy's
CubQMCNetG / CubMCCLT / CubMCG on the same files ({"method", "case", "tol", "met", "n"}, where
"met" means |estimate - I| <= tol |I|) are read and summarised beside mcplay's. A run "stops"
when it ends before the budget: what matters is how often such an answer is within the
tolerance (the promise), how often the tolerance is reached at all, and the median integrand
evaluations per run (all runs, stopped or not: a run that does not stop costs its budget).
Optional benchmark:
not part of `make test`.

  python3 bench/stopping_side_by_side.py --run-netg HARNESS_DIR PARAMS_DIR... > NETG.jsonl

runs QMCPy's CubQMCNetG alone exactly as the harness's qmcpy_tol.py does (Sobol' with LMS and a
digital shift, rel_tol 1e-3, n_limit 2^24, seeds 100 + r) and writes its JSON lines, for --qmcpy
(the harness's script also runs two slow Monte Carlo cubatures). Needs qmcpy and the harness's
genz.py.
"""
import argparse, collections, glob, json, os, subprocess, sys, tempfile

GENZ = {1: "genz_oscillatory", 2: "genz_product_peak", 3: "genz_corner_peak",
        4: "genz_gaussian", 5: "genz_continuous", 6: "genz_discontinuous"}


def integrand(p):
    """The params as an mcplay integrand: a built-in Genz family where mcplay's definition is
    the same (its discontinuous family cuts x1 and x2 only), else an expression."""
    fam, a, u = p["family"], p["a"], p["u"]
    if fam == 7:  # prod x_i^-a_i
        return {"type": "monomial", "powers": [-ai for ai in a]}
    if fam == 6 and any(ui < 1.0 for ui in u[2:]):
        cuts = " * ".join(f"step({ui!r} - x{i + 1})" for i, ui in enumerate(u))
        power = " + ".join(f"{ai!r}*x{i + 1}" for i, ai in enumerate(a))
        return {"type": "expression", "f": f"{cuts} * exp({power})"}
    return {"type": GENZ[fam], "a": a, "u": u}


ESTIMATORS = (("sobol", 1e-3), ("sobol_walsh", 1e-3), ("lattice", 1e-3), ("halton", 1e-3),
              ("uniform", 1e-2))


def run_mcplay(cli, p, estimator, tol, reps):
    scene = {"name": p["name"], "domain": {"type": "box", "dim": p["d"]}, "integrand": integrand(p),
             "estimators": [estimator], "n_min": 1024, "reps": reps, "seed": 100, "threads": 1,
             "exact": None}  # blind: mcplay is not told the answer
    with tempfile.NamedTemporaryFile("w", suffix=".json", delete=False) as f:
        json.dump(scene, f)
    try:
        out = subprocess.run([cli, "run", f.name, "--rel-tol", str(tol), "--max-seconds", "60",
                              "--format", "json", "--quiet"], capture_output=True, text=True)
    finally:
        os.unlink(f.name)
    if out.returncode:
        sys.exit(f"{p['name']}: mcplay failed: {out.stderr.strip()}")
    runs = json.loads(out.stdout)["estimators"][0]["runs"]
    return [dict(case=p["name"], stopped=r["met"],
                 within=abs(r["estimate"] - p["exact"]) <= tol * abs(p["exact"]),
                 n=r["evaluations"], seconds=r["seconds"]) for r in runs]


def median(values):
    v = sorted(values)
    if not v:
        return float("nan")
    m = len(v) // 2
    return v[m] if len(v) % 2 else 0.5 * (v[m - 1] + v[m])


def line(label, runs):
    stopped = [r for r in runs if r["stopped"]]
    kept = sum(r["within"] for r in stopped)
    within = sum(r["within"] for r in runs)
    promise = f"{kept}/{len(stopped)} ({100 * kept / len(stopped):.1f}%)" if stopped else "-"
    evals = median([r["n"] for r in runs if r["n"] > 0])
    evals_stopped = median([r["n"] for r in stopped])
    print(f"  {label:26s} {len(runs):5d} {len(stopped):8d} {promise:>16s} {within:7d} "
          f"{evals:12.3g} {evals_stopped:12.3g}")


def run_netg(harness, dirs, reps):
    """CubQMCNetG on every params file, as the harness's qmcpy_tol.py runs it."""
    import time, warnings
    sys.path.insert(0, harness)
    import numpy as np, qmcpy as qp, genz
    warnings.filterwarnings("ignore")
    for path in sorted(f for d in dirs for f in glob.glob(os.path.join(d, "*.json"))):
        p = json.load(open(path))
        exact, f = p["exact"], (lambda x, p=p: genz.f_np(p, x))
        for r in range(reps):
            start = time.perf_counter()
            try:
                sol, data = qp.CubQMCNetG(qp.CustomFun(qp.Uniform(qp.DigitalNetB2(p["d"], seed=100 + r)),
                                                       g=f), abs_tol=0, rel_tol=1e-3,
                                          n_limit=2 ** 24).integrate()
                est, n, err = float(np.squeeze(sol)), int(np.squeeze(data.n_total)), None
            except Exception as e:  # the harness records a failed run, so does this
                est, n, err = float("nan"), -1, str(e)[:120]
            print(json.dumps(dict(method="qmcpy_netg", case=p["name"], tol=1e-3, est=est,
                                  exact=exact, met=bool(abs(est - exact) <= 1e-3 * abs(exact)),
                                  n=n, seconds=time.perf_counter() - start, error=err)),
                  flush=True)


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--run-netg":
        reps = int(os.environ.get("REPS", "5"))
        return run_netg(sys.argv[2], sys.argv[3:], reps)
    ap = argparse.ArgumentParser()
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--cli", default=os.environ.get("MCPLAY", "build/mcplay"))
    ap.add_argument("--qmcpy", help="JSON lines of QMCPy's runs on the same files")
    ap.add_argument("--estimators", help="comma-separated subset of " +
                    ",".join(e for e, _ in ESTIMATORS))
    ap.add_argument("--only-qmcpy-cases", action="store_true",
                    help="run only the integrals the --qmcpy file has runs of")
    args = ap.parse_args()
    files = sorted(f for d in args.dirs for f in glob.glob(os.path.join(d, "*.json")))
    params = [json.load(open(f)) for f in files]
    if args.only_qmcpy_cases and args.qmcpy:
        done = {json.loads(row)["case"] for row in open(args.qmcpy)}
        params = [p for p in params if p["name"] in done]
    chosen = [(e, t) for e, t in ESTIMATORS
              if not args.estimators or e in args.estimators.split(",")]
    mine = collections.defaultdict(list)
    for p in params:
        for estimator, tol in chosen:
            mine[(estimator, tol)] += run_mcplay(args.cli, p, estimator, tol, args.reps)
    print(f"{len(params)} integrals x {args.reps} runs; a run 'stops' when it ends before its "
          "budget (2^24 points)")
    print(f"  {'method':26s} {'runs':>5s} {'stopped':>8s} {'within, of those':>16s} {'within':>7s} "
          f"{'median evals':>12s} {'(stopped)':>12s}")
    for estimator, tol in chosen:
        line(f"mcplay {estimator}, rel {tol:g}", mine[(estimator, tol)])
    if args.qmcpy:
        names = {p["name"] for p in params}
        theirs = collections.defaultdict(list)
        for row in map(json.loads, open(args.qmcpy)):
            if row["case"] not in names:
                continue
            stopped = row.get("error") is None and 0 < row["n"] < 2 ** 24
            theirs[(row["method"], row["tol"])].append(
                dict(case=row["case"], stopped=stopped, within=row["met"], n=row["n"]))
        for (method, tol), runs in sorted(theirs.items()):
            line(f"{method}, rel {tol:g}", runs)
    # Per integral: the median evaluations of each method (runs in brackets).
    tables = [(f"mcplay {e}", mine[(e, t)]) for e, t in chosen]
    if args.qmcpy:
        tables += [(m, runs) for (m, _), runs in sorted(theirs.items())]
    print("\nmedian evaluations per integral (runs)")
    print(f"  {'integral':16s}" + "".join(f" {label[:22]:>22s}" for label, _ in tables))
    for p in params:
        cells = []
        for _, runs in tables:
            ns = [r["n"] for r in runs if r["case"] == p["name"] and r["n"] > 0]
            cells.append(f"{median(ns):.3g} ({len(ns)})" if ns else "-")
        print(f"  {p['name']:16s}" + "".join(f" {c:>22s}" for c in cells))


if __name__ == "__main__":
    main()
