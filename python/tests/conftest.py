"""Shared fixtures of the package's tests.

The tests run against whatever `import mcplay` finds: the installed wheel in `make test-python`
(which sets MCPLAY_EXPECT_INSTALLED=1 and checks it), or the source tree with the extension from
a native build (PYTHONPATH=python:build/python).
"""

from __future__ import annotations

import os
import pathlib
import signal
import threading

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


@pytest.fixture
def default_sigint():
    """Python's own SIGINT handler (KeyboardInterrupt) for the test, whatever the process
    inherited (a background job starts with SIGINT ignored)."""
    if threading.current_thread() is not threading.main_thread():
        pytest.skip("signals reach only the main thread")
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    yield
    signal.signal(signal.SIGINT, previous)
