"""``render``: one image of a render scene as a numpy array, or a progressive series of them."""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping

import numpy as np

from . import _core
from ._scenes import load
from ._util import argument_error, from_json, put, to_json, whole_number
from .result import Flag
from .study import reference_cache_dir


@dataclass
class Render:
    """One rendered image: ``image`` is ``(height, width, 3)`` float32 linear RGB, row 0 at the
    top; ``relative_mse`` the image's relative MSE against the scene's reference (None without
    one); ``seconds`` the rendering time (for a progressive pass, of every pass so far)."""

    image: np.ndarray
    relative_mse: float | None
    seconds: float
    spp: int
    estimator: str
    pixel_coverage95: float | None = None
    warnings: list[Flag] = field(default_factory=list)
    raw: dict = field(default_factory=dict, repr=False)

    @property
    def width(self) -> int:
        return int(self.image.shape[1])

    @property
    def height(self) -> int:
        return int(self.image.shape[0])

    def __repr__(self) -> str:
        rel = (
            "no reference" if self.relative_mse is None else f"relative MSE {self.relative_mse:.4g}"
        )
        return (
            f"<Render {self.estimator} at {self.spp} spp, {self.width}x{self.height}, {rel}, "
            f"{self.seconds:.3g} s>"
        )


def _decode_pfm(data: bytes) -> np.ndarray:
    """A Portable Float Map (the core's: rows bottom to top, little-endian) as (H, W, 3) float32."""
    header, rest = [], data
    for _ in range(3):
        line, rest = rest.split(b"\n", 1)
        header.append(line.decode("ascii"))
    width, height = (int(v) for v in header[1].split())
    dtype = "<f4" if float(header[2]) < 0 else ">f4"
    pixels = np.frombuffer(rest, dtype=dtype, count=width * height * 3)
    return pixels.reshape(height, width, 3)[::-1].astype(np.float32)


def _decode_f32(text: str, height: int, width: int) -> np.ndarray:
    pixels = np.frombuffer(base64.b64decode(text), dtype="<f4")
    return pixels.reshape(height, width, 3).astype(np.float32)


def _number(value: Any) -> float | None:
    return float(value) if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def render(
    scene: Any,
    estimator: str | Mapping | None = None,
    spp: int | None = None,
    width: int | None = None,
    height: int | None = None,
    seed: int | None = None,
    threads: int | None = None,
    progressive: bool = False,
    pixel_sampler: str | None = None,
    *,
    long_side: int | None = None,
    reference: bool = True,
    cache_dir: Any = None,
    options: Mapping[str, Any] | None = None,
) -> "Render | ProgressiveRender":
    """Render a render scene (docs/render-scenes.md) with one estimator.

    Parameters
    ----------
    scene
        A render scene: a dict, a path (``.json``, or a ``.gltf``/``.glb`` alone) or a bundled
        name such as ``"cornell_box"``.
    estimator
        A name from the scene or an estimator object; default the scene's best (the estimator its
        reference uses), or for ``progressive`` the scene's first.
    spp
        Samples per pixel (default the scene's ``spp_max``); a power of two for ``progressive``.
    width, height
        The image size (default the scene's; for ``progressive`` the live view's, long side
        ``long_side`` (256) with the camera's aspect).
    seed, threads
        The image's seed (default 1) and worker threads (0 or None: every core).
    progressive
        Return an iterator of :class:`Render` at 1, 2, 4, ..., spp samples per pixel from one
        live session that never restarts (pixel sampler ``padded_sobol`` by default, so the
        image at n spp is the one a single render at n spp gives). The session closes when the
        iterator ends, is closed or is dropped.
    pixel_sampler
        ``independent``, ``stratified``, ``sobol`` or ``padded_sobol`` (progressive:
        ``padded_sobol`` or ``independent``).
    reference
        Measure the relative MSE against the scene's reference (rendered once and cached, see
        ``cache_dir``); False: no reference, ``relative_mse`` None.
    cache_dir
        Where references are cached (None: ``$MCPLAY_CACHE``, else ``~/.cache/mcplay``;
        False: none).
    options
        Further options of the render C API.
    """
    loaded = load(scene)
    if not loaded.render:
        raise argument_error(f"scene: '{loaded.label}' is an integration scene, not a render scene")
    opts: dict[str, Any] = {"base_dir": str(loaded.base_dir)}
    cache = reference_cache_dir(cache_dir)
    if cache is not None:
        opts["cache_dir"] = cache
    for name, value in (
        ("width", width),
        ("height", height),
        ("seed", seed),
        ("threads", threads),
        ("long_side", long_side),
    ):
        if value is not None:
            opts[name] = whole_number(value, name, 0)
    if pixel_sampler is not None:
        if not isinstance(pixel_sampler, str):
            raise argument_error(f"pixel_sampler: expected a name, got {pixel_sampler!r}")
        opts["pixel_sampler"] = pixel_sampler
    if estimator is not None and not isinstance(estimator, (str, Mapping)):
        raise argument_error(
            f"estimator: expected a name or an estimator object, got {type(estimator).__name__}"
        )
    if estimator is not None:
        estimator = dict(estimator) if isinstance(estimator, Mapping) else estimator
    if spp is not None:
        spp = whole_number(spp, "spp", 1)
    if not isinstance(reference, bool):
        raise argument_error(f"reference: expected True or False, got {reference!r}")
    if options is not None:
        if not isinstance(options, Mapping):
            raise argument_error(f"options: expected a dict, got {type(options).__name__}")
        opts.update(options)
    if progressive:
        return ProgressiveRender._open(loaded.text, opts, estimator, spp, reference)
    if long_side is not None:
        raise argument_error("long_side: sizes a progressive render; give width and height")
    put(opts, "estimator", estimator)
    put(opts, "spp", spp)
    opts["outputs"] = ["pfm", "error_png"] if reference else ["pfm"]
    raw = from_json(_core.call("render_image", loaded.text, to_json(opts, "options")))
    images = raw.pop("images", {})
    image = _decode_pfm(base64.b64decode(images["pfm"]))
    name = (
        raw.get("estimator", {}).get("name", "")
        if isinstance(raw.get("estimator"), dict)
        else str(raw.get("estimator", ""))
    )
    return Render(
        image=image,
        relative_mse=_number(raw.get("relative_mse")),
        seconds=_number(raw.get("seconds")) or 0.0,
        spp=int(raw.get("spp") or 0),
        estimator=name,
        pixel_coverage95=_number(raw.get("pixel_coverage95")),
        warnings=[Flag.from_raw(w, name) for w in raw.get("warnings") or []],
        raw=raw,
    )


class ProgressiveRender:
    """An iterator of :class:`Render` at 1, 2, 4, ..., spp samples per pixel (the live view).

    One live session of the core renders every pass, adding samples to the same pixels; it is
    closed when the iteration ends, by :meth:`close`, on leaving a ``with`` block, or when the
    iterator is dropped.
    """

    def __init__(self, session: int, info: dict, spp: int):
        self._session: int | None = session
        self.info = info
        self.spp = spp
        self.width = int(info["width"])
        self.height = int(info["height"])
        estimators = info.get("estimators") or [{}]
        self.estimator = (
            str(estimators[0].get("name", ""))
            if isinstance(estimators[0], dict)
            else str(estimators[0])
        )
        self._next_spp = 1

    @classmethod
    def _open(
        cls, scene_text: str, opts: dict, estimator: Any, spp: int | None, reference: bool
    ) -> "ProgressiveRender":
        if spp is None:
            info = from_json(
                _core.call(
                    "render_scene_info",
                    scene_text,
                    to_json({"base_dir": opts["base_dir"]}, "options"),
                )
            )
            spp = int(info["settings"]["n_max"])
        if spp & (spp - 1):
            raise argument_error(f"spp: a progressive render needs a power of two, got {spp}")
        opts = dict(opts)
        if estimator is not None:
            opts["estimators"] = [estimator]
        opts["pixels"] = True
        opts["live_reference"] = "obtain" if reference else "available"
        if not reference:
            opts.pop("cache_dir", None)
        info = from_json(_core.render_live_open(scene_text, to_json(opts, "options")))
        return cls(int(info["session"]), info, spp)

    def __iter__(self) -> Iterator[Render]:
        return self

    def __next__(self) -> Render:
        if self._session is None or self._next_spp > self.spp:
            self.close()
            raise StopIteration
        spp = self._next_spp
        request = {"estimator": 0, "spp": spp, "pixels": True}
        try:
            raw = from_json(_core.render_live_pass(self._session, to_json(request, "pass")))
        except BaseException:
            self.close()
            raise
        self._next_spp *= 2
        image = _decode_f32(raw.pop("rgb_f32"), self.height, self.width)
        error = raw.get("error")
        relative_mse = None
        if isinstance(error, dict) and (error.get("terms") or 0) > 0:
            total = _number(error.get("sum"))
            if total is not None and math.isfinite(total):
                relative_mse = total / float(error["terms"])
        return Render(
            image=image,
            relative_mse=relative_mse,
            seconds=_number(raw.get("seconds")) or 0.0,
            spp=spp,
            estimator=self.estimator,
            raw=raw,
        )

    def close(self) -> None:
        """Free the core's session (again is a no-op)."""
        session, self._session = self._session, None
        if session is not None:
            _core.render_live_close(session)

    def __enter__(self) -> "ProgressiveRender":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def __del__(self) -> None:
        try:
            self.close()
        except Exception:
            pass
