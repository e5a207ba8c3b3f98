"""Shared fixtures of the package's tests.

The tests run against whatever `import mcplay` finds: the installed wheel in `make test-python`
(which sets MCPLAY_EXPECT_INSTALLED=1 and checks it), or the source tree with the extension from
a native build (PYTHONPATH=python:build/python).
"""

from __future__ import annotations

import os
import pathlib

import pytest

import mcplay

REPO_ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def scenes_dir() -> pathlib.Path:
    """The bundled scenes: installed with the package, or (source tree) the repository's."""
    candidates = [pathlib.Path(mcplay.__file__).parent / "scenes"]
    if not os.environ.get("MCPLAY_EXPECT_INSTALLED"):
        candidates.append(REPO_ROOT / "scenes")
    for candidate in candidates:
        if (candidate / "exp_1d.json").is_file():
            return candidate
    raise FileNotFoundError("no bundled scenes beside the package nor in the repository")
