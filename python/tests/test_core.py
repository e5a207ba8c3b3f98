"""The extension mcplay._core on its own: the C calls by name, McplayError, Python callables as
integrands and warps (checks on what they return, failures naming the block and the point,
threads, Ctrl-C), and the wheel's contents when installed.

Statistical checks use fixed seeds and tolerances in standard errors.
"""

from __future__ import annotations

import base64
import json
import math
import os
import pathlib
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
import _thread
from typing import Any, Callable

import numpy as np
import pytest

import mcplay
from mcplay import _core

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]
TOLERANCE_SE = 5.0
# Result fields that measure time: they differ between two runs of the same study.
TIMING_PREFIXES = ("time_", "efficiency", "training_time", "seconds", "wall_time")


def box_scene(dim: int, integrand: Any = None, **fields: Any) -> dict:
    """A scene over the unit box [0, 1]^dim whose integrand is the caller's function 'f'."""
    scene = {
        "name": "test_box",
        "domain": {"type": "box", "lower": [0.0] * dim, "upper": [1.0] * dim},
        "integrand": integrand if integrand is not None else {"type": "function", "name": "f"},
    }
    scene.update(fields)
    return scene


def run_study(scene: dict, options: dict, functions: dict[str, Callable] | None = None,
              progress: Callable[[str], object] | None = None) -> dict:
    """_core.study_run with dicts in and out."""
    return json.loads(_core.study_run(json.dumps(scene), json.dumps(options), functions, progress))


def without_timing(value: Any) -> Any:
    """value with every timing field left out (at any depth), to compare two runs' numbers."""
    if isinstance(value, dict):
        return {k: without_timing(v) for k, v in value.items()
                if not k.startswith(TIMING_PREFIXES)}
    if isinstance(value, list):
        return [without_timing(v) for v in value]
    return value


def estimator_numbers(result: dict) -> list:
    """Every estimator's levels without the timing fields."""
    return [without_timing({"name": e["name"], "levels": e["levels"]})
            for e in result["estimators"]]


def function_error(f: Callable, options: dict | None = None, dim: int = 2) -> _core.McplayError:
    """The McplayError a one-estimator study of f raises."""
    options = options or {"estimators": ["uniform"], "n_min": 4096, "n_max": 4096, "reps": 2,
                          "seed": 1, "threads": 1}
    with pytest.raises(_core.McplayError) as info:
        run_study(box_scene(dim), options, {"f": f})
    return info.value


FAST = {"estimators": ["uniform"], "n_min": 4096, "n_max": 4096, "reps": 2, "seed": 1,
        "threads": 1}
# A study long enough (minutes) that only a cancel ends it within the test's time.
LONG = {"estimators": ["uniform"], "n_min": 1 << 22, "n_max": 1 << 22, "reps": 1000, "seed": 1,
        "threads": 2}


# --- The package ----------------------------------------------------------------------------

def test_import_is_the_installed_wheel_when_expected() -> None:
    if not os.environ.get("MCPLAY_EXPECT_INSTALLED"):
        pytest.skip("MCPLAY_EXPECT_INSTALLED is not set: running against the source tree")
    package = pathlib.Path(mcplay.__file__).resolve()
    assert "site-packages" in package.parts, package
    assert REPO_ROOT / "python" not in package.parents, package


def test_wheel_ships_every_bundled_scene() -> None:
    if not os.environ.get("MCPLAY_EXPECT_INSTALLED"):
        pytest.skip("MCPLAY_EXPECT_INSTALLED is not set: the scenes are the repository's")
    installed = pathlib.Path(mcplay.__file__).parent / "scenes"
    wanted = sorted(p.name for p in (REPO_ROOT / "scenes").iterdir()
                    if p.suffix in (".json", ".gltf"))
    assert wanted, "the repository has no scenes to compare with"
    missing = [name for name in wanted if not (installed / name).is_file()]
    assert not missing, f"not in the wheel: {missing}"


def test_version_is_the_projects() -> None:
    cmake = (REPO_ROOT / "CMakeLists.txt").read_text()
    project_version = re.search(r"project\(mcplay VERSION ([0-9.]+)", cmake).group(1)
    assert _core.version() == project_version
    if os.environ.get("MCPLAY_EXPECT_INSTALLED"):
        from importlib.metadata import version
        assert version("mcplay") == project_version


# --- call() and McplayError -----------------------------------------------------------------

def test_call_catalog_and_points() -> None:
    catalog = json.loads(_core.call("catalog"))
    assert "uniform" in [e["name"] for e in catalog["estimators"]]
    points = json.loads(_core.call("points", json.dumps(
        {"sampler": "sobol", "n": 8, "dim": 3, "seed": 5})))
    assert np.array(points["points"]).shape == (8, 3)


def test_call_with_options_reaches_the_second_argument(scenes_dir: pathlib.Path) -> None:
    result = run_study(json.loads((scenes_dir / "exp_1d.json").read_text()),
                       {"estimators": ["uniform"], "n_max": 256, "reps": 4})
    csv = _core.call("result_format", json.dumps(result), "csv")
    assert csv.splitlines()[0].count(",") > 3
    with pytest.raises(_core.McplayError) as info:
        _core.call("result_format", json.dumps(result), "yaml")
    assert info.value.status_name == "ARGUMENT"


def test_mcplay_error_is_a_value_error_with_status() -> None:
    assert issubclass(_core.McplayError, ValueError)
    with pytest.raises(ValueError) as info:
        _core.call("scene_info", "{")
    error = info.value
    assert isinstance(error, _core.McplayError)
    assert (error.status, error.status_name) == (2, "SCENE")
    assert "\n" not in str(error) and "scene" in str(error)
    assert _core.STATUS_NAMES[error.status] == error.status_name


@pytest.mark.parametrize("args, words", [
    (("no_such_call", "{}"), "unknown function 'no_such_call'"),
    (("catalog", "{}"), "takes no request"),
    (("points", "{}", "{}"), "takes no options"),
    (("scene_info", '{"name": "a\0b"}'), "NUL character"),
])
def test_bad_calls_are_argument_errors(args: tuple, words: str) -> None:
    with pytest.raises(_core.McplayError) as info:
        _core.call(*args)
    assert info.value.status_name == "ARGUMENT"
    assert words in str(info.value)


def test_bad_functions_argument_is_named() -> None:
    with pytest.raises(_core.McplayError, match=r"functions\['f'\]: expected a callable, got int"):
        run_study(box_scene(2), FAST, {"f": 1})
    with pytest.raises(_core.McplayError, match="functions: expected a dict"):
        _core.study_run(json.dumps(box_scene(2)), None, [lambda x: x])
    with pytest.raises(_core.McplayError, match="progress: expected a callable"):
        run_study(box_scene(2), FAST, {"f": lambda x: x.sum(1)}, progress=3)


def test_scene_naming_an_absent_function_is_an_error() -> None:
    with pytest.raises(_core.McplayError) as info:
        run_study(box_scene(2), FAST, {"g": lambda x: x.sum(1)})
    assert "'f'" in str(info.value)


# --- Callables: the numbers -----------------------------------------------------------------

def test_callable_gives_the_expressions_numbers_bit_for_bit() -> None:
    # x1 * x2 + x1 in numpy and in the core's expression: the same doubles, point by point.
    options = {"estimators": ["uniform", "sobol"], "n_min": 1024, "n_max": 16384, "reps": 4,
               "seed": 11, "threads": 2}
    by_callable = run_study(box_scene(2), options, {"f": lambda x: x[:, 0] * x[:, 1] + x[:, 0]})
    by_expression = run_study(box_scene(2, "x1 * x2 + x1"), options)
    assert estimator_numbers(by_callable) == estimator_numbers(by_expression)


def test_callable_integral_within_standard_errors_of_exact() -> None:
    exact = (math.e - 1.0) ** 2
    result = run_study(box_scene(2), {"estimators": ["uniform", "sobol", "stratified"],
                                      "n_max": 16384, "reps": 8, "seed": 3, "threads": 2},
                       {"f": lambda x: np.exp(x.sum(1))})
    for estimator in result["estimators"]:
        level = estimator["levels"][-1]
        assert abs(level["mean"] - exact) < TOLERANCE_SE * level["std_error"], estimator["name"]


def test_two_threads_give_the_numbers_of_one() -> None:
    options = {"estimators": ["uniform", "latin_hypercube", "sobol", "vegas"], "n_max": 8192,
               "reps": 4, "seed": 5}
    f = {"f": lambda x: np.exp(-((x - 0.3) ** 2).sum(1) * 4.0)}
    one = run_study(box_scene(3), {**options, "threads": 1}, f)
    two = run_study(box_scene(3), {**options, "threads": 2}, f)
    assert estimator_numbers(one) == estimator_numbers(two)


def test_callable_gets_blocks_of_read_only_points_in_the_domain() -> None:
    seen: list[np.ndarray] = []

    def f(x: np.ndarray) -> np.ndarray:
        assert x.dtype == np.float64 and x.ndim == 2 and not x.flags.writeable
        assert x.flags.f_contiguous  # one array per coordinate, as the core holds them
        seen.append(x.copy())
        return x.sum(1)

    scene = box_scene(3)
    scene["domain"] = {"type": "box", "lower": [-1, 0, 2], "upper": [0, 1, 5]}
    run_study(scene, FAST, {"f": f})
    points = np.concatenate(seen)
    # the study's 2 x 4096 points, and once the 2^15 uniform points at which the study judges
    # the integrand's tail (an estimator whose variance follows f's: docs/result-schema.md)
    tail_probes = 1 << 15
    assert points.shape == (4096 * 2 + tail_probes, 3)
    seen.clear()
    run_study(scene, {**FAST, "estimators": ["uniform", "latin_hypercube"]}, {"f": f})
    assert np.concatenate(seen).shape == (2 * 4096 * 2 + tail_probes, 3), "probed once a study"
    assert len(seen) * 256 <= len(points), "called per block, not per point"
    assert (points.min(0) >= [-1, 0, 2]).all() and (points.max(0) <= [0, 1, 5]).all()


def test_values_convertible_to_float64_are_taken() -> None:
    shapes = {
        "column": lambda x: x[:, :1] * 2.0,                    # (n, 1)
        "float32": lambda x: (2.0 * x[:, 0]).astype(np.float32),
        "list": lambda x: (2.0 * x[:, 0]).tolist(),
        "strided": lambda x: np.repeat(2.0 * x[:, :1], 2, axis=1)[:, 0],
    }
    for name, f in shapes.items():
        result = run_study(box_scene(1), {**FAST, "n_max": 16384, "n_min": 16384, "reps": 4},
                           {"f": f})
        level = result["estimators"][0]["levels"][-1]
        assert abs(level["mean"] - 1.0) < TOLERANCE_SE * level["std_error"], name


def test_points_the_callable_kept_stay_valid() -> None:
    kept: list[tuple[np.ndarray, np.ndarray]] = []

    def f(x: np.ndarray) -> np.ndarray:
        kept.append((x, x.copy()))
        return x.sum(1)

    run_study(box_scene(2), {**FAST, "reps": 4, "threads": 2}, {"f": f})
    run_study(box_scene(2), {**FAST, "seed": 2}, {"f": lambda x: x.sum(1)})  # reuses buffers
    assert len(kept) > 2
    assert all(np.array_equal(x, copy) for x, copy in kept)


# --- Callables: failures ----------------------------------------------------------------------

def test_raising_callable_names_block_point_and_cause() -> None:
    calls = []

    def f(x: np.ndarray) -> np.ndarray:
        calls.append(x.copy())
        if len(calls) == 3:
            return 1 / 0
        return x.sum(1)

    error = function_error(f, {**FAST, "reps": 8})
    assert error.status == 5 and error.status_name == "FUNCTION"
    n = len(calls[0])
    first = 2 * n
    message = str(error)
    assert message.startswith(f"function 'f' on block 3 (points {first}..{first + n - 1}): "
                              "raised ZeroDivisionError: division by zero at the block's first "
                              "point ["), message
    quoted = [float(v) for v in message.rsplit("[", 1)[1].rstrip("]").split(", ")]
    assert quoted == calls[2][0].tolist()
    assert isinstance(error.__cause__, ZeroDivisionError)
    assert len(calls) == 3, "no call after the failing one"


@pytest.mark.parametrize("returned, words", [
    (lambda x: x.sum(1)[:10], "returned shape (10,), expected ({n},)"),
    (lambda x: x, "returned shape ({n}, 2), expected ({n},)"),
    (lambda x: 3.0, "returned a scalar (shape ()), expected ({n},)"),
    (lambda x: x.sum(1) + 0j, "returned an array of dtype complex128"),
    (lambda x: np.array([object()] * len(x)), "returned an array of dtype object"),
    (lambda x: np.array(["a"] * len(x)), "returned an array of dtype <U1"),
    (lambda x: None, "returned None, expected real (float64) values of shape ({n},)"),
    (lambda x: [[1.0], [2.0, 3.0]], "returned a list that numpy cannot make an array of"),
])
def test_wrong_values_are_named(returned: Callable, words: str) -> None:
    error = function_error(returned)
    message = str(error)
    assert error.status_name == "FUNCTION"
    assert message.startswith("function 'f' on block 1 (points 0.."), message
    n = int(re.search(r"points 0\.\.(\d+)", message).group(1)) + 1
    assert words.format(n=n) in message, message


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_value_names_the_point(bad: float) -> None:
    blocks: list[np.ndarray] = []

    def f(x: np.ndarray) -> np.ndarray:
        blocks.append(x.copy())
        values = x.sum(1)
        if len(blocks) == 2:
            values[17] = bad
        return values

    message = str(function_error(f))
    assert f"on block 2 " in message
    assert f"returned {bad!r}".replace("nan", "nan") in message.replace("-nan", "nan"), message
    assert "at point 17 of the block, x = [" in message
    quoted = [float(v) for v in message.rsplit("[", 1)[1].rstrip("]").split(", ")]
    assert quoted == blocks[1][17].tolist()


def test_writing_to_the_points_is_a_named_failure() -> None:
    def f(x: np.ndarray) -> np.ndarray:
        x[0, 0] = 1.0
        return x.sum(1)

    error = function_error(f)
    assert "raised ValueError" in str(error) and "read-only" in str(error)
    assert isinstance(error.__cause__, ValueError)


def test_failure_with_two_threads_is_one_clear_error() -> None:
    def f(x: np.ndarray) -> np.ndarray:
        if x[:, 0].max() > 0.999:
            raise RuntimeError("edge reached")
        return x.sum(1)

    error = function_error(f, {**FAST, "reps": 16, "threads": 2})
    assert "raised RuntimeError: edge reached" in str(error)
    assert isinstance(error.__cause__, RuntimeError)


def test_system_exit_in_a_callable_is_raised_as_it_is() -> None:
    def f(x: np.ndarray) -> np.ndarray:
        sys.exit(3)

    with pytest.raises(SystemExit):
        run_study(box_scene(2), FAST, {"f": f})


# --- Progress, Ctrl-C -----------------------------------------------------------------------

def test_progress_gets_each_level_and_its_exception_cancels() -> None:
    levels: list[dict] = []
    run_study(box_scene(2), {**FAST, "n_min": 256, "n_max": 1024},
              {"f": lambda x: x.sum(1)}, lambda text: levels.append(json.loads(text)))
    assert [level["n"] for level in levels] == [256, 512, 1024]

    class Stop(Exception):
        pass

    def progress(text: str) -> None:
        raise Stop("enough")

    calls = []
    with pytest.raises(Stop, match="enough"):
        run_study(box_scene(2), {**FAST, "n_min": 256, "n_max": 1 << 20},
                  {"f": lambda x: calls.append(1) or x.sum(1)}, progress)
    assert len(calls) < 64


def test_ctrl_c_from_a_timer_cancels_a_long_study_quickly(default_sigint: None) -> None:
    timer = threading.Timer(0.5, signal.raise_signal, (signal.SIGINT,))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        run_study(box_scene(2), LONG, {"f": lambda x: np.exp(x.sum(1))})
    elapsed = time.perf_counter() - start
    timer.join()
    assert elapsed < 3.0, elapsed
    # Nothing is left behind: the next study runs.
    assert run_study(box_scene(2), FAST, {"f": lambda x: x.sum(1)})["estimators"]


def test_ctrl_c_from_inside_the_callable_stops_within_blocks(default_sigint: None) -> None:
    calls = []

    def f(x: np.ndarray) -> np.ndarray:
        calls.append(time.perf_counter())
        if len(calls) == 3:
            _thread.interrupt_main()
        return x.sum(1)

    with pytest.raises(KeyboardInterrupt):
        run_study(box_scene(2), LONG, {"f": f})
    # The wait checks signals every 50 ms: the core stops soon after.
    assert calls[-1] - calls[2] < 1.0


def test_ctrl_c_cancels_an_expression_study_too(default_sigint: None) -> None:
    timer = threading.Timer(0.3, signal.raise_signal, (signal.SIGINT,))
    start = time.perf_counter()
    timer.start()
    with pytest.raises(KeyboardInterrupt):
        run_study(box_scene(4, "exp(x1 + x2 + x3 + x4)"), LONG)
    timer.join()
    assert time.perf_counter() - start < 3.0


# --- Plans and warps with callables ---------------------------------------------------------

def test_study_plan_with_a_callable() -> None:
    plan = json.loads(_core.study_plan(json.dumps(box_scene(2)), json.dumps(FAST),
                                       {"f": lambda x: x.sum(1)}))
    assert plan["evaluations"] == 4096 * 2
    assert plan["predicted_seconds"] > 0


def polar_disk(u: np.ndarray) -> np.ndarray:
    """The course notes' disk warp: r = sqrt(u1), phi = 2 pi u2 (uniform on the unit disk)."""
    r, phi = np.sqrt(u[:, 0]), 2.0 * np.pi * u[:, 1]
    return np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)


def warp_scene() -> dict:
    return {"warp": {"domain": {"type": "disk", "radius": 1},
                     "g": {"function": "g", "sample_dim": 2}, "p": {"function": "p"}}}


def test_warp_test_with_callables_passes_and_fails() -> None:
    options = json.dumps({"samples": 200000, "seed": 4})
    uniform = lambda x: np.full(len(x), 1.0 / np.pi)
    right = json.loads(_core.warp_test(json.dumps(warp_scene()), options,
                                       {"g": polar_disk, "p": uniform}))
    assert right["passed"] is True
    # The course notes' mistake: r = u1 is not uniform on the disk.
    wrong_g = lambda u: polar_disk(np.stack([u[:, 0] ** 2, u[:, 1]], axis=1))
    wrong = json.loads(_core.warp_test(json.dumps(warp_scene()), options,
                                       {"g": wrong_g, "p": uniform}))
    assert wrong["passed"] is False


def test_warp_map_of_the_wrong_shape_is_named() -> None:
    with pytest.raises(_core.McplayError) as info:
        _core.warp_test(json.dumps(warp_scene()), None,
                        {"g": lambda u: u[:, 0], "p": lambda x: np.full(len(x), 1 / np.pi)})
    assert re.search(r"function 'g' on block 1 .*returned shape \(\d+,\), expected \(\d+, 2\)",
                     str(info.value)), str(info.value)


# --- The interpreter survives ---------------------------------------------------------------

def test_hostile_callables_never_crash_the_interpreter(tmp_path: pathlib.Path) -> None:
    """Each case in a child interpreter: it must end with an exception, never a signal."""
    script = tmp_path / "hostile.py"
    script.write_text(textwrap.dedent("""
        import gc, json, sys, numpy as np
        from mcplay import _core
        scene = json.dumps({"name": "h", "domain": {"type": "box", "lower": [0, 0],
                            "upper": [1, 1]}, "integrand": {"type": "function", "name": "f"}})
        options = json.dumps({"estimators": ["uniform", "vegas"], "n_max": 8192, "reps": 4,
                              "threads": 2})
        class Weird:
            def __array__(self, *a, **k): raise RuntimeError("no array")
        nested_runs = []
        def nested(x):  # a study inside a callable of a study (once: it is not quick)
            if not nested_runs:
                nested_runs.append(_core.study_run(scene, options, {"f": lambda y: y.sum(1)}))
            return x.sum(1)
        def recursion(x):
            return recursion(x)
        cases = {
            "weird": lambda x: Weird(),
            "huge": lambda x: np.zeros((len(x), 1000)),
            "nested": nested,
            "recursion": recursion,
            "memory": lambda x: np.zeros(1 << 62),
            "gc": lambda x: (gc.collect(0), x.sum(1))[1],
            "generator": lambda x: (v for v in x.sum(1)),
        }
        for name, f in cases.items():
            try:
                _core.study_run(scene, options, {"f": f})
                print(name, "ok")
            except Exception as e:
                print(name, type(e).__name__, str(e)[:100])
        print("done")
    """))
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120, env={**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)})
    assert done.returncode == 0, done.stderr[-2000:]
    lines = done.stdout.splitlines()
    assert lines[-1] == "done", done.stdout
    assert any(line.startswith("nested ok") for line in lines), done.stdout
    assert any(line.startswith("weird McplayError") for line in lines), done.stdout


# --- Rendering ------------------------------------------------------------------------------

def render_scene(scenes_dir: pathlib.Path) -> tuple[str, dict]:
    """A small render scene (closed-form pixels) and options that keep it to milliseconds."""
    scene = (scenes_dir / "quad_light_floor.json").read_text()
    options = {"base_dir": str(scenes_dir), "width": 16, "height": 16, "spp_min": 1, "spp_max": 4,
               "reps": 2, "estimators": ["light_area", "mis_balance"], "threads": 2}
    return scene, options


def test_render_study_run_with_progress(scenes_dir: pathlib.Path) -> None:
    scene, options = render_scene(scenes_dir)
    lines: list[dict] = []
    result = json.loads(_core.render_study_run(scene, json.dumps(options),
                                               lambda text: lines.append(json.loads(text))))
    assert [e["name"] for e in result["estimators"]] == ["light_area", "mis_balance"]
    assert lines, "progress was never called"

    class Stop(Exception):
        pass

    def stop(text: str) -> None:
        raise Stop()

    with pytest.raises(Stop):
        _core.render_study_run(scene, json.dumps(options), stop)


def test_render_image_and_reference(scenes_dir: pathlib.Path) -> None:
    scene, options = render_scene(scenes_dir)
    image = json.loads(_core.call("render_image", scene,
                                  json.dumps({**options, "estimator": "light_area", "spp": 2})))
    assert image["kind"] == "render_image" and image["spp"] == 2
    assert base64.b64decode(image["images"]["png"])[:4] == b"\x89PNG"
    reference = json.loads(_core.render_reference(scene, json.dumps(options)))
    assert reference["kind"] == "render_reference" and reference["reference_data"]


def test_render_live_session(scenes_dir: pathlib.Path) -> None:
    scene, options = render_scene(scenes_dir)
    live = json.loads(_core.render_live_open(
        scene, json.dumps({"base_dir": options["base_dir"], "long_side": 16,
                           "estimators": ["light_area"], "pixels": True})))
    session = live["session"]
    try:
        first = json.loads(_core.render_live_pass(session, json.dumps({"estimator": 0, "spp": 1,
                                                                       "pixels": True})))
        second = json.loads(_core.render_live_pass(session, json.dumps({"estimator": 0,
                                                                        "spp": 4})))
        assert (first["spp"], second["spp"]) == (1, 4)
        pixels = np.frombuffer(base64.b64decode(first["rgb_f32"]), "<f4")
        assert pixels.size == live["width"] * live["height"] * 3 and np.isfinite(pixels).all()
        with pytest.raises(_core.McplayError):
            _core.render_live_pass(session, json.dumps({"estimator": 0, "spp": 2}))  # not more
    finally:
        _core.render_live_close(session)
    with pytest.raises(_core.McplayError):
        _core.render_live_close(session)


def test_warp_map_non_finite_names_the_first_point() -> None:
    def g(u: np.ndarray) -> np.ndarray:
        x = polar_disk(u)
        x[9, 1] = np.nan   # second coordinate of point 9
        x[12, 0] = np.inf  # a later point
        return x

    with pytest.raises(_core.McplayError) as info:
        _core.warp_test(json.dumps(warp_scene()), None,
                        {"g": g, "p": lambda x: np.full(len(x), 1 / np.pi)})
    assert "function 'g' on block 1 " in str(info.value)
    assert "returned nan at point 9 of the block" in str(info.value), str(info.value)
