"""Tests of the Python API of mcplay (python/mcplay): every number must be the core's.

Statistical checks use fixed seeds and tolerances in standard errors. Comparisons with the CLI
need the native ``mcplay`` (``$MCPLAY_CLI``, else the repository's ``build/mcplay``); scenes are
read from the repository's ``scenes/`` or the installed package's copy.
"""

from __future__ import annotations

import concurrent.futures
import json
import math
import multiprocessing
import os
import pickle
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import mcplay

REPO = Path(__file__).resolve().parents[2]
SCENES = mcplay.scenes_dir()
EXP = (math.e - 1.0) ** 2  # the integral of exp(x1 + x2) over the unit square

#: The fields that hold seconds or thread counts: they differ between two runs of one study.
TIMING_KEYS = {"wall_time_s", "efficiency", "threads", "rays_per_second", "accel"}


def strip_timings(value):
    """``value`` without its timing fields (as tests/compare_results.mjs ignores them)."""
    if isinstance(value, dict):
        return {
            k: strip_timings(v)
            for k, v in value.items()
            if k not in TIMING_KEYS
            and not k.startswith("time_")
            and not k.startswith("training_time")
            and "seconds" not in k
        }
    if isinstance(value, list):
        return [strip_timings(v) for v in value]
    return value


def cli_path() -> str:
    path = os.environ.get("MCPLAY_CLI") or str(REPO / "build" / "mcplay")
    if not (os.path.isfile(path) and os.access(path, os.X_OK)):
        pytest.skip(f"the native CLI is not built at {path} (set MCPLAY_CLI): nothing to compare")
    return path


def cli_json(*args: str) -> dict:
    out = subprocess.run(
        [cli_path(), *args], capture_output=True, text=True, check=True, timeout=120
    )
    return json.loads(out.stdout)


@pytest.fixture(scope="module")
def cache(tmp_path_factory) -> str:
    """One reference cache for the render tests of this module."""
    return str(tmp_path_factory.mktemp("mcref"))


def exp_sum(x: np.ndarray) -> np.ndarray:
    return np.exp(x.sum(axis=1))


# --- run: the CLI's numbers, bit for bit ---------------------------------------------------------


def test_run_is_the_cli_bit_for_bit():
    scene = SCENES / "exp_1d.json"
    ours = mcplay.run(str(scene), n_max=1024, reps=4, threads=2)
    theirs = cli_json(
        "run", str(scene), "--n-max", "1024", "--reps", "4", "--format", "json", "--quiet"
    )
    assert strip_timings(ours) == strip_timings(theirs)
    # the bundled name and a dict of the file give the same study
    by_name = mcplay.run("exp_1d", n_max=1024, reps=4)
    by_dict = mcplay.run(json.loads(scene.read_text()), n_max=1024, reps=4)
    assert strip_timings(by_name) == strip_timings(ours) == strip_timings(by_dict)


def test_stopping_run_is_the_cli_bit_for_bit():
    scene = SCENES / "exp_1d.json"
    ours = mcplay.run(scene, rel_tol=1e-2, reps=3, estimators=["uniform", "sobol"])
    theirs = cli_json(
        "run",
        str(scene),
        "--rel-tol",
        "1e-2",
        "--reps",
        "3",
        "--estimators",
        "uniform,sobol",
        "--format",
        "json",
        "--quiet",
    )
    assert ours["kind"] == "stopping"
    assert strip_timings(ours) == strip_timings(theirs)


def test_render_study_is_the_cli_bit_for_bit():
    scene = SCENES / "cornell_box.json"
    small = dict(n_min=1, n_max=2, reps=2, options={"width": 12, "height": 10})
    ours = mcplay.run(scene, estimators=["bsdf", "mis_power"], cache_dir=False, **small)
    theirs = cli_json(
        "run",
        str(scene),
        "--estimators",
        "bsdf,mis_power",
        "--n-min",
        "1",
        "--n-max",
        "2",
        "--reps",
        "2",
        "--width",
        "12",
        "--height",
        "10",
        "--no-cache",
        "--quiet",
        "--format",
        "json",
    )
    assert ours["kind"] == "render"
    assert strip_timings(ours) == strip_timings(theirs)
    # a glTF alone is a render scene of its own, as the CLI reads it
    gltf = SCENES / "quad_light_floor.gltf"
    ours = mcplay.run(gltf, cache_dir=False, **small)
    theirs = cli_json("run", str(gltf), "--n-min", "1", "--n-max", "2", "--reps", "2", "--width",
                      "12", "--height", "10", "--no-cache", "--quiet", "--format", "json")
    assert ours["scene"]["name"] == "quad_light_floor"
    assert strip_timings(ours) == strip_timings(theirs)


def test_run_progress_sees_every_level():
    levels = []
    result = mcplay.run("exp_1d", n_max=256, reps=4, estimators="uniform", progress=levels.append)
    assert [level["n"] for level in levels] == [16, 32, 64, 128, 256]
    assert [lv["n"] for lv in result["estimators"][0]["levels"]] == [16, 32, 64, 128, 256]


# --- integrate: every estimator family through a callable ----------------------------------------

FAMILIES = [
    "uniform",
    "stratified",
    "latin_hypercube",
    {"name": "importance", "pdf": {"type": "exponential", "rate": -0.8}},
    {"name": "stratified_importance", "pdf": {"type": "exponential", "rate": -0.8}},
    "sobol",
    "halton",
    "lattice",
    "sobol_walsh",
    "vegas",
    "vegas_sobol",
    "vegas_plus",
    "miser",
    "antithetic",
    "systematic",
    "ris_m4",
    {"name": "cv", "control_variates": [{"g": "x1 + x2", "integral": 1.0}]},
    {"name": "mis", "proposals": ["uniform", {"type": "exponential", "rate": -1}]},
]


def _kind_of(entry, preset_kinds):
    if isinstance(entry, str):
        return preset_kinds[entry]
    if "proposals" in entry:
        return "mis"
    if "control_variates" in entry:
        return "control_variates"
    return preset_kinds[entry["name"]]


def test_families_cover_every_kind_the_core_offers():
    # Derived from the core's catalog, so a new estimator kind fails here until it is added above.
    c = mcplay.catalog()
    preset_kinds = {e["name"]: e["kind"] for e in c["estimators"]}
    covered = {_kind_of(e, preset_kinds) for e in FAMILIES}
    missing = {k["name"] for k in c["kinds"]} - covered
    assert not missing, f"kinds without a callable test: {sorted(missing)}"


def test_every_family_through_a_callable_meets_the_exact_value():
    calls = []

    def f(x):
        calls.append(x.shape)
        return np.exp(x.sum(axis=1))

    r = mcplay.integrate(f, dim=2, estimators=FAMILIES, n=4096, reps=8, exact=EXP, seed=7)
    names = [e if isinstance(e, str) else e["name"] for e in FAMILIES]
    assert list(r.estimators) == names
    for name in names:
        e = r[name]
        assert e.n == 4096
        assert math.isfinite(e.estimate) and e.stderr > 0, name
        assert abs(e.estimate - EXP) < 5 * e.stderr, (name, e.estimate, e.stderr)
        assert e.error_bar > e.stderr  # a 95% half-width is about 2 standard errors
    # blocks of points, never one point at a time
    assert max(shape[0] for shape in calls) > 1
    assert all(len(shape) == 2 and shape[1] == 2 for shape in calls)
    assert r.best.name in names and r.best.trusted
    assert r.estimate == r.best.estimate and r.error_bar == r.best.error_bar


def test_best_has_the_smallest_trusted_error_bar():
    r = mcplay.integrate(
        exp_sum,
        dim=2,
        estimators=["uniform", "sobol", "latin_hypercube"],
        n=1024,
        reps=8,
        exact=EXP,
    )
    trusted = [e for e in r.estimators.values() if e.trusted]
    assert r.best is min(trusted, key=lambda e: e.error_bar)
    assert r.best.name != "uniform"


def test_expression_path_gives_the_callables_numbers():
    common = dict(dim=2, estimators=["uniform", "sobol"], n=1024, reps=4, exact=EXP, seed=3)
    by_callable = mcplay.integrate(exp_sum, **common)
    by_expression = mcplay.integrate("exp(x1 + x2)", **common)
    for name in ("uniform", "sobol"):
        a, b = by_callable[name].levels["mean"], by_expression[name].levels["mean"]
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=0)  # exp may differ in the last bit
    assert "x1 + x2" in by_expression.raw["scene"]["integrand"]


def test_a_domain_of_pairs_scales_the_integral():
    # the integral of x over [0, 2] x [1, 3] is 2 (area 4 x mean 1)
    r = mcplay.integrate(
        lambda x: x[:, 0], domain=[(0, 2), (1, 3)], estimators="sobol", n=1024, reps=8, exact=4.0
    )
    assert abs(r.estimate - 4.0) < 5 * r.stderr
    assert r.raw["scene"]["domain_text"] == "[0, 2] x [1, 3]"


def test_heavy_tail_is_flagged_in_words():
    r = mcplay.integrate(
        lambda x: x[:, 0] ** -0.9, dim=1, estimators="uniform", n=4096, reps=32, exact=10.0
    )
    codes = {f.code: f for f in r.flags}
    assert "heavy_tail" in codes
    flag = codes["heavy_tail"]
    assert flag.severity == "warning" and flag.estimator == "uniform"
    assert "tail" in flag.message and len(flag.message) > 20
    assert not r.best.trusted and not r.trusted
    assert str(flag).startswith("WARNING heavy_tail [uniform]: ")


def test_stopping_outcome():
    r = mcplay.integrate(exp_sum, dim=2, estimators=["uniform", "sobol"], rel_tol=1e-3, exact=EXP)
    assert r.kind == "stopping"
    s = r.stopping
    assert s.met and s.runs == 2 and s.runs_met == 2 and s.rel_tol == 1e-3
    assert s.n >= 16 and s.evaluations >= s.n and s.seconds > 0
    assert r.error_bar <= 1e-3 * abs(r.estimate)
    assert abs(r.estimate - EXP) <= 1e-3 * EXP * 1.5


def test_levels_and_to_pandas():
    r = mcplay.integrate(exp_sum, dim=2, estimators=["uniform", "sobol"], n=256, reps=4)
    levels = r.levels["sobol"]
    np.testing.assert_array_equal(levels["n"], [16, 32, 64, 128, 256])
    assert levels["n"].dtype == np.int64 and levels["variance"].dtype == np.float64
    assert levels["mean"][-1] == r["sobol"].estimate
    assert np.isnan(levels["rmse"]).all()  # no exact value given
    pd = pytest.importorskip("pandas", reason="to_pandas needs pandas")
    frame = r.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert len(frame) == 10 and set(frame["estimator"]) == {"uniform", "sobol"}
    assert frame.loc[frame.estimator == "sobol", "variance"].tolist() == levels["variance"].tolist()


def test_to_pandas_without_pandas_says_what_to_install(monkeypatch):
    r = mcplay.integrate("x", estimators="uniform", n=32, reps=2)
    monkeypatch.setitem(sys.modules, "pandas", None)
    with pytest.raises(ImportError, match="pip install pandas"):
        r.to_pandas()


def test_result_pickles_and_prints_as_the_cli():
    r = mcplay.integrate(exp_sum, dim=2, estimators=["uniform", "sobol"], n=256, reps=4, exact=EXP)
    back = pickle.loads(pickle.dumps(r))
    assert back == r and back.estimate == r.estimate and back.best.name == r.best.name
    assert [str(f) for f in back.flags] == [str(f) for f in r.flags]
    table = repr(back)
    assert table == mcplay.Result(r.raw).format("table")
    assert table.startswith("mcplay ") and "fitted order" in table and "sobol  [sampler" in table


def test_plots_with_agg(tmp_path):
    matplotlib = pytest.importorskip("matplotlib", reason="Result.plot needs matplotlib")
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    r = mcplay.integrate(exp_sum, dim=2, estimators=["uniform", "sobol"], n=1024, reps=8, exact=EXP)
    for kind in ("variance", "mse", "time"):
        ax = r.plot(kind)
        assert isinstance(ax, matplotlib.axes.Axes)
        labels = [t.get_text() for t in ax.get_legend().get_texts()]
        assert any(label.startswith("sobol") for label in labels)
        if kind != "time":
            assert "N^-1" in labels and "N^-2" in labels
            assert any("N^(" in label for label in labels)  # the fitted order
        ax.figure.savefig(tmp_path / f"{kind}.png")
    fig = r.plot("calibration")
    assert isinstance(fig, matplotlib.figure.Figure) and len(fig.axes) == 2
    plt.close("all")
    with pytest.raises(mcplay.McplayError, match="kind"):
        r.plot("histogram")


# --- catalog -------------------------------------------------------------------------------------


def test_catalog_and_the_docstring_list_every_preset():
    presets = mcplay.estimators()
    names = [p["name"] for p in presets]
    assert {"uniform", "sobol", "vegas", "miser", "antithetic"} <= set(names)
    assert all(p["summary"] for p in presets)
    for name in names:
        assert f"``{name}``" in mcplay.integrate.__doc__
    assert "box" in mcplay.catalog()["domains"]


# --- the sampler lab -----------------------------------------------------------------------------


def test_points_are_the_clis(tmp_path):
    ours = mcplay.points("sobol", 64, 3, seed=5)
    out = subprocess.run(
        [cli_path(), "points", "sobol", "--n", "64", "--dim", "3", "--seed", "5"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    theirs = np.loadtxt(out.splitlines()[1:], delimiter=",")
    assert ours.shape == (64, 3) and ours.dtype == np.float64
    np.testing.assert_array_equal(ours, theirs)
    assert mcplay.points("pixel_sobol", 16, 2).shape == (16, 2)
    deterministic = mcplay.points("sobol", 8, 2, randomization="none")
    np.testing.assert_array_equal(deterministic[:2], [[0, 0], [0.5, 0.5]])


def test_analyze_is_the_clis(tmp_path):
    pts = mcplay.points("halton", 128, 2, seed=2)
    csv = tmp_path / "p.csv"
    np.savetxt(csv, pts, delimiter=",", fmt="%.17g", header="x1,x2", comments="")
    theirs = cli_json("analyze", str(csv), "--format", "json", "--spectrum-size", "32")
    ours = mcplay.analyze(pts, size=32)
    for key in (
        "l2_star_discrepancy",
        "centered_l2_discrepancy",
        "wraparound_l2_discrepancy",
        "min_distance",
        "min_distance_toroidal",
    ):
        assert getattr(ours, key) == theirs[key], key
    assert ours.expected_iid == theirs["expected_iid"]
    np.testing.assert_array_equal(ours.radial["power"], theirs["spectrum"]["radial"]["power"])
    assert ours.spectrum.shape == (32, 32) and ours.spectrum[16, 16] == 128  # P(0) = N
    # several sets: the means over them, and each set's measure
    sets = mcplay.analyze([mcplay.points("sobol", 64, 2, seed=s) for s in (1, 2)], spectrum=False)
    assert sets.sets == 2 and sets.spectrum is None
    assert sets.l2_star_discrepancy == pytest.approx(sets.per_set["l2_star_discrepancy"].mean())


def _disk(radius_of_u1):
    def g(u):
        r, phi = radius_of_u1(u[:, 0]), 2 * np.pi * u[:, 1]
        return np.column_stack([r * np.cos(phi), r * np.sin(phi)])

    return g


def uniform_disk_pdf(x):
    return np.full(len(x), 1 / np.pi)


def test_warp_test_wrong_and_right():
    disk = {"type": "disk", "radius": 1}
    common = dict(p=uniform_disk_pdf, domain=disk, samples=100_000, sample_dim=2, seed=3)
    wrong = mcplay.warp_test(_disk(lambda u: u), **common)
    right = mcplay.warp_test(_disk(np.sqrt), **common)
    assert wrong.passed is False and wrong.outcome == "failed"
    assert wrong.p_value < 1e-10 and wrong.verdict.startswith("rejected")
    assert right.passed is True and right.outcome == "passed"
    assert right.p_value > 0.01 and right.verdict.startswith("passed")
    # where the mass is wrong, said for the wrong warp alone
    assert wrong.where.startswith("too many samples near the centre"), wrong.where
    assert wrong.where in wrong.verdict
    assert right.where is None and not right.off_by_constant
    # the counts pile up at small radius (the first natural coordinate, |x|^2) for r = u1
    assert wrong.observed.shape == wrong.expected.shape == tuple(wrong.raw["bins"])
    assert wrong.observed[0].sum() > 2 * wrong.expected[0].sum()
    worst = wrong.worst_bins[0]
    assert wrong.observed[tuple(worst["index"])] == worst["observed"]
    # expressions and a named warp give the same verdicts
    exprs = mcplay.warp_test(
        ["u1*cos(2*pi*u2)", "u1*sin(2*pi*u2)"], "1/pi", domain=disk, samples=100_000
    )
    assert not exprs.passed
    assert mcplay.warp_test("concentric_disk", samples=100_000).passed


def test_warp_test_says_when_it_cannot_verify():
    # A table of 4096 x 256 cells is more than the test's quadrature budget resolves: neither
    # passed nor failed (docs/sampler-lab.md).
    values = np.random.default_rng(5).random(4096 * 256).round(6).tolist()
    t = mcplay.warp_test({"name": "tabulated_2d", "values": values, "nx": 4096, "ny": 256},
                         samples=100_000, seed=1)
    assert t.outcome == "unverified" and t.passed is None, t.verdict
    assert t.verdict.startswith("could not verify")


# --- render --------------------------------------------------------------------------------------


def test_render_an_image(cache):
    r = mcplay.render("cornell_box", spp=4, width=16, height=12, cache_dir=cache)
    assert r.image.shape == (12, 16, 3) and r.image.dtype == np.float32
    assert np.isfinite(r.image).all() and r.image.max() > 0
    assert r.relative_mse is not None and 0 < r.relative_mse < 10
    assert r.seconds > 0 and r.spp == 4 and r.estimator
    assert pickle.loads(pickle.dumps(r)).image.tobytes() == r.image.tobytes()
    assert (
        mcplay.render("cornell_box", spp=1, width=8, height=8, reference=False).relative_mse is None
    )


def test_progressive_render_is_the_one_shot_image(cache):
    steps = list(
        mcplay.render(
            "cornell_box",
            estimator="mis_power",
            spp=8,
            width=16,
            height=12,
            progressive=True,
            cache_dir=cache,
        )
    )
    assert [s.spp for s in steps] == [1, 2, 4, 8]
    assert all(s.image.shape == (12, 16, 3) and s.image.dtype == np.float32 for s in steps)
    assert steps[-1].relative_mse < steps[0].relative_mse
    one_shot = mcplay.render(
        "cornell_box",
        estimator="mis_power",
        spp=8,
        width=16,
        height=12,
        pixel_sampler="padded_sobol",
        cache_dir=cache,
    )
    assert one_shot.image.tobytes() == steps[-1].image.tobytes()


def test_progressive_sessions_close_when_dropped():
    # the core holds at most 16 live sessions: dropped or closed iterators must free theirs
    for _ in range(20):
        it = mcplay.render(
            "cornell_box", spp=4, width=8, height=8, progressive=True, reference=False
        )
        next(it)
        del it
    for _ in range(20):
        with mcplay.render(
            "cornell_box", spp=2, width=8, height=8, progressive=True, reference=False
        ) as it:
            next(it)


# --- parts and merge -----------------------------------------------------------------------------


STUDIES = [
    ("exp_1d", dict(n_max=512, reps=6)),
    ("exp_1d", dict(rel_tol=1e-2, reps=3, estimators=["uniform", "sobol"])),
    (
        "cornell_box",
        dict(
            n_min=1,
            n_max=2,
            reps=3,
            estimators=["bsdf"],
            cache_dir=False,
            options={"width": 10, "height": 8},
        ),
    ),
]


@pytest.fixture(scope="module")
def pool():
    context = multiprocessing.get_context("spawn")
    with concurrent.futures.ProcessPoolExecutor(2, mp_context=context) as executor:
        yield executor


@pytest.mark.parametrize("scene,kwargs", STUDIES, ids=["ladder", "stopping", "render"])
def test_parts_over_a_process_pool_merge_bit_for_bit(pool, scene, kwargs):
    k = 3
    # mcplay.run itself goes to the workers (a function of the test module would not unpickle
    # where pytest imports it under another name)
    futures = [pool.submit(mcplay.run, str(SCENES / f"{scene}.json"), part=(i, k), **kwargs)
               for i in range(k)]
    parts = [future.result() for future in futures]
    assert all(p.get("part", {}).get("of") == k for p in parts)
    merged = mcplay.merge(reversed(parts))
    whole = mcplay.run(scene, **kwargs)
    assert strip_timings(merged) == strip_timings(whole)


def test_merge_refuses_a_missing_part():
    parts = [mcplay.run("exp_1d", n_max=64, reps=4, part=(i, 2)) for i in range(2)]
    with pytest.raises(mcplay.McplayError, match="part"):
        mcplay.merge(parts[:1])


def test_parts_over_a_dask_cluster_merge_bit_for_bit():
    distributed = pytest.importorskip("dask.distributed", reason="dask[distributed] not installed")
    kwargs = dict(n_max=256, reps=4)
    with (
        distributed.LocalCluster(
            processes=True, n_workers=2, threads_per_worker=1, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        futures = [
            client.submit(mcplay.run, "exp_1d", part=(i, 4), pure=False, **kwargs) for i in range(4)
        ]
        parts = client.gather(futures)
    assert strip_timings(mcplay.merge(parts)) == strip_timings(mcplay.run("exp_1d", **kwargs))


# --- errors --------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "call,named",
    [
        (lambda: mcplay.integrate(exp_sum), "dim"),
        (lambda: mcplay.integrate(exp_sum, dim=2.5), "dim"),
        (lambda: mcplay.integrate(exp_sum, domain=[(0, 1, 2)]), "domain[0]"),
        (lambda: mcplay.integrate(exp_sum, dim=3, domain=[(0, 1), (0, 1)]), "dim"),
        (lambda: mcplay.integrate(42, dim=1), "f"),
        (lambda: mcplay.integrate(exp_sum, dim=2, estimators=[1]), "estimators[0]"),
        (lambda: mcplay.integrate(exp_sum, dim=2, rel_tol=-1), "rel_tol"),
        (lambda: mcplay.integrate(exp_sum, dim=2, estimators="stratifed"), "stratified"),
        (lambda: mcplay.integrate("sinn(x)"), "sinn"),
        (lambda: mcplay.run("no_such_scene"), "no_such_scene"),
        (lambda: mcplay.run("exp_1d", part=(0,)), "part"),
        (lambda: mcplay.run("exp_1d", reps=1), "reps"),
        (lambda: mcplay.points("sobol", 3.5, 2), "n"),
        (lambda: mcplay.points("sobool", 4, 2), "sobool"),
        (lambda: mcplay.analyze(np.array([[0.1, np.nan]])), "row 0, column 1"),
        (lambda: mcplay.analyze(np.zeros(4)), "points"),
        (lambda: mcplay.warp_test(_disk(np.sqrt)), "p"),
        (lambda: mcplay.render("exp_1d"), "render"),
        (lambda: mcplay.merge([]), "parts"),
    ],
)
def test_bad_arguments_raise_one_line_naming_them(call, named):
    with pytest.raises(mcplay.McplayError) as info:
        call()
    message = str(info.value)
    assert named in message and "\n" not in message
    assert isinstance(info.value, ValueError)


def test_errors_of_the_callable_name_the_block_and_keep_the_cause():
    def fails(x):
        raise ZeroDivisionError("no")

    with pytest.raises(mcplay.McplayError, match="block") as info:
        mcplay.integrate(fails, dim=2, n=64, reps=2)
    assert isinstance(info.value.__cause__, ZeroDivisionError)
    with pytest.raises(mcplay.McplayError, match="shape"):
        mcplay.integrate(lambda x: x, dim=2, n=64, reps=2)
    with pytest.raises(mcplay.McplayError, match="nan"):
        mcplay.integrate(lambda x: np.full(len(x), np.nan), dim=2, n=64, reps=2)


def test_ctrl_c_cancels_within_blocks(default_sigint):
    calls = []

    def f(x):
        calls.append(len(x))
        if len(calls) == 5:
            signal.raise_signal(signal.SIGINT)  # as Ctrl-C does
        return np.exp(x.sum(axis=1))

    with pytest.raises(KeyboardInterrupt):
        mcplay.integrate(f, dim=2, n=2**22, reps=32, estimators="uniform")
    # the whole study would take 2^28 points; it stopped within a few blocks per thread
    assert sum(calls) < 2**22


def test_a_scene_may_name_the_callers_function():
    scene = {
        "name": "fn",
        "integrand": {"type": "function", "name": "g"},
        "domain": {"type": "box", "dim": 2},
        "estimators": ["sobol"],
        "n_max": 256,
        "reps": 4,
        "exact": EXP,
    }
    by_scene = mcplay.run(scene, functions={"g": exp_sum})
    by_integrate = mcplay.integrate(exp_sum, dim=2, estimators="sobol", n=256, reps=4, exact=EXP)
    assert by_scene["estimators"][0]["levels"][-1]["mean"] == by_integrate.estimate
    with pytest.raises(mcplay.McplayError):
        mcplay.run(scene)  # the function is not given


def test_scenes_are_listed_and_found():
    names = mcplay.scenes()
    assert "exp_1d" in names and "cornell_box" in names
    info = mcplay.scene_info("exp_1d")
    assert info["dimension"] == 1 and info["exact"] == pytest.approx(math.e - 1)
