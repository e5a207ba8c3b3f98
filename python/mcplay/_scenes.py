"""Finding a scene: a dict, a file (.json, or a .gltf/.glb alone) or a bundled scene's name."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

from ._util import argument_error, to_json

#: Scene files are read up to the core's limit (docs/scene-format.md, Limits and paths).
_MAX_SCENE_BYTES = 64 << 20


def scenes_dir() -> Path:
    """The folder of the bundled scenes: ``mcplay/scenes`` in a wheel, ``scenes/`` in a checkout."""
    here = Path(__file__).resolve().parent
    installed = here / "scenes"
    if installed.is_dir():
        return installed
    return here.parent.parent / "scenes"


def scene_names() -> list[str]:
    """The names of the bundled scenes (integration and render), sorted."""
    folder = scenes_dir()
    if not folder.is_dir():
        return []
    return sorted(p.stem for p in folder.glob("*.json"))


@dataclass(frozen=True)
class Scene:
    """A scene ready for the core: its JSON text, the folder its files are relative to."""

    text: str
    base_dir: Path
    render: bool
    label: str


def load(scene: Any, what: str = "scene") -> Scene:
    """A scene given as a dict, a path (str or os.PathLike) or a bundled scene's name."""
    if isinstance(scene, Mapping):
        text = to_json(dict(scene), what)
        return Scene(text, Path.cwd(), "render" in scene, str(scene.get("name", "scene")))
    if not isinstance(scene, (str, os.PathLike)):
        raise argument_error(
            f"{what}: expected a dict, a file path or a bundled scene's name, "
            f"got {type(scene).__name__}"
        )
    path = Path(os.fspath(scene))
    if not path.exists():
        named = scenes_dir() / f"{path.name}.json"
        if isinstance(scene, str) and "/" not in scene and os.sep not in scene and named.is_file():
            path = named
        else:
            raise argument_error(
                f"{what}: no scene file '{os.fspath(scene)}' (nor a bundled scene of that name; "
                f"mcplay.scenes() lists them)"
            )
    if path.is_dir():
        raise argument_error(f"{what}: '{path}' is a directory, not a scene file")
    if not path.is_file():
        raise argument_error(f"{what}: '{path}' is not a regular file")
    if path.stat().st_size > _MAX_SCENE_BYTES:
        raise argument_error(f"{what}: '{path}' is larger than 64 MiB, the limit of a scene file")
    if path.suffix.lower() in (".gltf", ".glb"):
        # A glTF alone is a render scene of its own, its settings in its extras.mcplay.
        text = json.dumps({"name": path.stem, "render": {"gltf": path.name}})
        return Scene(text, path.parent, True, str(path))
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError:
        raise argument_error(f"{what}: '{path}' is not UTF-8 text") from None
    return Scene(text, path.parent, _is_render_text(text), str(path))


def _is_render_text(text: str) -> bool:
    """Whether the text is a render scene (a "render" object); text that does not parse goes to
    the core, which says why."""
    try:
        parsed = json.loads(text)
    except ValueError:
        return False
    return isinstance(parsed, dict) and "render" in parsed
