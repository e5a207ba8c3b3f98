#!/usr/bin/env python3
"""mcplay's stopping rule beside QMCPy's tolerance-based cubatures, on the same integrals.

  python3 bench/stopping_side_by_side.py PARAMS_DIR... [--reps 5] [--qmcpy QMCPY.jsonl]

PARAMS_DIR holds Genz test integrals as JSON ({"name", "family" 1-7, "d", "a", "u", "exact"}:
the format of the Genz battery harness, docs/benchmarks.md). Each is run by mcplay's CLI to a
relative tolerance, R replicates: Sobol' points (randomized, the "sobol" preset) at 1e-3, plain
points ("uniform") at 1e-2, N doubling from 1024 to 2^24. With --qmcpy, JSON lines of QMCPy's
CubQMCNetG / CubMCCLT / CubMCG on the same files ({"method", "case", "tol", "met", "n"}, where
"met" means |estimate - I| <= tol |I|) are read and summarised beside mcplay's. A run "stops"
when it ends before the budget: what matters is how often such an answer is within the
tolerance (the promise), and how often the tolerance is reached at all. Optional benchmark:
not part of `make test`.
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
    return [dict(stopped=r["met"], within=abs(r["estimate"] - p["exact"]) <= tol * abs(p["exact"]),
                 n=r["evaluations"], seconds=r["seconds"]) for r in runs]


def line(label, runs):
    stopped = [r for r in runs if r["stopped"]]
    kept = sum(r["within"] for r in stopped)
    within = sum(r["within"] for r in runs)
    promise = f"{kept}/{len(stopped)} ({100 * kept / len(stopped):.1f}%)" if stopped else "-"
    print(f"  {label:26s} {len(runs):5d} {len(stopped):8d} {promise:>16s} {within:7d}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dirs", nargs="+")
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--cli", default=os.environ.get("MCPLAY", "build/mcplay"))
    ap.add_argument("--qmcpy", help="JSON lines of QMCPy's runs on the same files")
    args = ap.parse_args()
    files = sorted(f for d in args.dirs for f in glob.glob(os.path.join(d, "*.json")))
    params = [json.load(open(f)) for f in files]
    mine = collections.defaultdict(list)
    for p in params:
        for estimator, tol in (("sobol", 1e-3), ("uniform", 1e-2)):
            mine[(estimator, tol)] += run_mcplay(args.cli, p, estimator, tol, args.reps)
    print(f"{len(params)} integrals x {args.reps} runs; a run 'stops' when it ends before its "
          "budget (2^24 points)")
    print(f"  {'method':26s} {'runs':>5s} {'stopped':>8s} {'within, of those':>16s} {'within':>7s}")
    line("mcplay sobol, rel 1e-3", mine[("sobol", 1e-3)])
    line("mcplay uniform, rel 1e-2", mine[("uniform", 1e-2)])
    if args.qmcpy:
        names = {p["name"] for p in params}
        theirs = collections.defaultdict(list)
        for row in map(json.loads, open(args.qmcpy)):
            if row["case"] not in names:
                continue
            stopped = row.get("error") is None and 0 < row["n"] < 2 ** 24
            theirs[(row["method"], row["tol"])].append(dict(stopped=stopped, within=row["met"]))
        for (method, tol), runs in sorted(theirs.items()):
            line(f"{method}, rel {tol:g}", runs)


if __name__ == "__main__":
    main()
