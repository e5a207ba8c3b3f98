"""Studies from scenes: :func:`run`, :func:`merge`, and what the core offers (:func:`catalog`)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable, Iterable, Mapping

from . import _core
from ._scenes import load
from ._util import (
    argument_error,
    estimator_list,
    from_json,
    part_pair,
    progress_adapter,
    put,
    real_number,
    to_json,
    whole_number,
)


def reference_cache_dir(cache_dir: Any) -> str | None:
    """Where render references are cached, as the CLI chooses it.

    ``None``: ``$MCPLAY_CACHE``, else ``~/.cache/mcplay`` (created; no cache when it cannot be);
    ``False``: no cache (the reference is rendered every time); a path: that folder.
    """
    if cache_dir is False:
        return None
    if cache_dir is None or cache_dir is True:
        env = os.environ.get("MCPLAY_CACHE")
        folder = Path(env) if env else Path.home() / ".cache" / "mcplay"
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError:
            if env:
                raise argument_error(
                    f"cache_dir: $MCPLAY_CACHE '{env}' cannot be created "
                    f"(the reference cache needs a folder)"
                ) from None
            return None
        return str(folder)
    if not isinstance(cache_dir, (str, os.PathLike)):
        raise argument_error(
            f"cache_dir: expected a folder, None or False, got {type(cache_dir).__name__}"
        )
    folder = Path(os.fspath(cache_dir))
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise argument_error(
            f"cache_dir: '{folder}' cannot be created ({error.strerror})"
        ) from None
    if not folder.is_dir():
        raise argument_error(f"cache_dir: '{folder}' is not a folder")
    return str(folder)


def functions_dict(functions: Any) -> dict[str, Callable]:
    """``functions``: the caller's functions a scene names, by name."""
    if functions is None:
        return {}
    if not isinstance(functions, Mapping):
        raise argument_error(
            f"functions: expected a dict of name -> callable, got {type(functions).__name__}"
        )
    for name, fn in functions.items():
        if not isinstance(name, str):
            raise argument_error(f"functions: names must be strings, got {name!r}")
        if not callable(fn):
            raise argument_error(
                f"functions[{name!r}]: expected a callable, got {type(fn).__name__}"
            )
    return dict(functions)


def run(
    scene: Any,
    *,
    estimators: Any = None,
    n_min: int | None = None,
    n_max: int | None = None,
    reps: int | None = None,
    seed: int | None = None,
    threads: int | None = None,
    rel_tol: float | None = None,
    abs_tol: float | None = None,
    part: tuple[int, int] | None = None,
    progress: Callable[[dict], Any] | None = None,
    options: Mapping[str, Any] | None = None,
    functions: Mapping[str, Callable] | None = None,
    cache_dir: Any = None,
) -> dict:
    """Run a scene's study: the same dict as ``mcplay run SCENE --format json``.

    Parameters
    ----------
    scene
        A scene dict (docs/scene-format.md, docs/render-scenes.md), a path to a scene file
        (``.json``, or a ``.gltf``/``.glb`` alone: a render scene of its own) or the name of a
        bundled scene (:func:`mcplay.scenes`).
    estimators
        Names (from the scene, or presets) or estimator objects to run instead of the scene's.
    n_min, n_max, reps, seed, threads
        Overrides of the scene's settings (for a render scene ``n_min``/``n_max`` are samples
        per pixel). ``threads=0`` uses every core; results never depend on it.
    rel_tol, abs_tol
        Stop at a requested accuracy instead of running the N ladder (``"kind": "stopping"``).
    part
        ``(i, k)``: run only the replicates r with r % k == i and return a part for :func:`merge`.
    progress
        Called with each completed level (a dict) as the study goes.
    options
        Further options of the C API (e.g. ``{"max_seconds": 10}``, ``{"width": 64}``).
    functions
        The caller's functions a scene names (``{"type": "function", "name": ...}``), by name.
    cache_dir
        Render scenes: where the reference is cached (``None``: as the CLI, ``$MCPLAY_CACHE``
        else ``~/.cache/mcplay``; ``False``: none).

    Returns
    -------
    dict
        The result (docs/result-schema.md): every number as the CLI gives it.

    Raises
    ------
    McplayError
        A bad argument or scene, with a one-line message naming it.
    """
    loaded = load(scene)
    opts: dict[str, Any] = {}
    put(opts, "estimators", estimator_list(estimators))
    for name, value in (
        ("n_min", n_min),
        ("n_max", n_max),
        ("reps", reps),
        ("seed", seed),
        ("threads", threads),
    ):
        if value is not None:
            opts[name] = whole_number(value, name, 0)
    for name, value in (("rel_tol", rel_tol), ("abs_tol", abs_tol)):
        if value is not None:
            opts[name] = real_number(value, name, positive=True)
    pair = part_pair(part)
    if pair is not None:
        opts["part"], opts["parts"] = pair
    if options is not None:
        if not isinstance(options, Mapping):
            raise argument_error(f"options: expected a dict, got {type(options).__name__}")
        opts.update(options)
    on_line = progress_adapter(progress)
    if loaded.render:
        if functions:
            raise argument_error("functions: render scenes take no caller's functions")
        for key in ("n_min", "n_max"):
            if key in opts:
                opts["spp_" + key[2:]] = opts.pop(key)
        opts.setdefault("base_dir", str(loaded.base_dir))
        cache = reference_cache_dir(cache_dir)
        if cache is not None:
            opts.setdefault("cache_dir", cache)
        text = _core.render_study_run(loaded.text, to_json(opts, "options"), on_line)
    else:
        fns = functions_dict(functions)
        text = _core.study_run(loaded.text, to_json(opts, "options"), fns, on_line)
    return from_json(text)


def merge(parts: Iterable[Any]) -> dict:
    """The whole study from the parts of :func:`run` ``(..., part=(i, k))``, in any order.

    Every number is the one a single run of the whole study gives, but the timings
    (``wall_time_s``, ``settings.threads``, the levels' ``time_*``, ``training_time_mean_s``,
    ``efficiency``, a stopping run's seconds). Parts of other scenes or settings, a part missing
    or given twice are refused with the field named. Integration studies, stopping runs and
    render studies alike.
    """
    if isinstance(parts, (str, bytes, Mapping)):
        raise argument_error("parts: expected a list of the parts (dicts from run(..., part=...))")
    items = list(parts)
    if not items:
        raise argument_error("parts: the list is empty")
    decoded = []
    for i, item in enumerate(items):
        if isinstance(item, str):
            try:
                item = from_json(item)
            except ValueError:
                raise argument_error(f"parts[{i}]: not valid JSON") from None
        if not isinstance(item, Mapping):
            raise argument_error(f"parts[{i}]: expected a dict, got {type(item).__name__}")
        decoded.append(item)
    request = to_json({"parts": decoded}, "parts")
    study = decoded[0].get("kind") in ("study_part", "stopping_part")
    text = _core.call("study_merge" if study else "render_study_merge", request)
    return from_json(text)


def plan(
    scene: Any,
    *,
    options: Mapping[str, Any] | None = None,
    functions: Mapping[str, Callable] | None = None,
    cache_dir: Any = False,
) -> dict:
    """What a study of ``scene`` would cost, from a short timed pilot, without running it."""
    loaded = load(scene)
    opts = dict(options or {})
    if loaded.render:
        opts.setdefault("base_dir", str(loaded.base_dir))
        cache = reference_cache_dir(cache_dir)
        if cache is not None:
            opts.setdefault("cache_dir", cache)
        return from_json(_core.call("render_study_plan", loaded.text, to_json(opts, "options")))
    return from_json(
        _core.study_plan(loaded.text, to_json(opts, "options"), functions_dict(functions))
    )


def scene_info(scene: Any) -> dict:
    """A scene validated and summarised by the core (its estimators, domain, exact value...)."""
    loaded = load(scene)
    if loaded.render:
        opts = {"base_dir": str(loaded.base_dir)}
        return from_json(_core.call("render_scene_info", loaded.text, to_json(opts, "options")))
    return from_json(_core.call("scene_info", loaded.text))


def catalog() -> dict:
    """What the core offers: estimator presets (name, kind, sampler, needs_pdf, summary), kinds,
    samplers, randomizations, pdfs, integrands, domains and named warps."""
    return from_json(_core.call("catalog", ""))


def estimators() -> list[dict]:
    """The estimator presets, each ``{"name", "kind", "sampler", "needs_pdf", "summary"}``."""
    return catalog()["estimators"]
