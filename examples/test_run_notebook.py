"""The notebook runner's own tests (`make test-notebook` runs them before the tour): it passes a
clean notebook, fails one whose cell raises or that carries outputs, and strips outputs."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import nbformat
from nbformat.v4 import new_code_cell, new_markdown_cell, new_notebook, new_output

HERE = Path(__file__).resolve().parent
RUNNER = HERE / "run_notebook.py"
TOUR = HERE / "mcplay_tour.ipynb"

sys.path.insert(0, str(HERE))
from run_notebook import cells_with_outputs  # noqa: E402


def write(path: Path, *sources: str) -> Path:
    """A notebook of one markdown cell and a code cell per source."""
    cells = [new_markdown_cell("a test notebook")] + [new_code_cell(s) for s in sources]
    nbformat.write(new_notebook(cells=cells), path)
    return path


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(RUNNER), *map(str, args)], capture_output=True,
                          text=True, timeout=300)


def test_the_committed_tour_has_no_outputs():
    assert cells_with_outputs(nbformat.read(TOUR, as_version=4)) == []


def test_a_clean_notebook_passes_and_its_outputs_are_saved(tmp_path):
    executed = tmp_path / "out.ipynb"
    done = run(write(tmp_path / "ok.ipynb", "x = 6 * 7", "print(x)"), "--executed", executed)
    assert done.returncode == 0, done.stderr
    assert "2 code cells ran clean" in done.stdout
    outputs = nbformat.read(executed, as_version=4).cells[2].outputs
    assert outputs[0]["text"] == "42\n"


def test_a_raising_cell_fails_the_run_and_is_named(tmp_path):
    done = run(write(tmp_path / "bad.ipynb", "1 + 1", "raise ValueError('broken on purpose')"))
    assert done.returncode == 1
    assert "a cell failed" in done.stderr and "broken on purpose" in done.stderr


def test_a_notebook_with_outputs_is_refused_and_strip_cleans_it(tmp_path):
    path = write(tmp_path / "dirty.ipynb", "print('hi')")
    nb = nbformat.read(path, as_version=4)
    nb.cells[1].outputs = [new_output("stream", name="stdout", text="hi\n")]
    nb.cells[1].execution_count = 1
    nbformat.write(nb, path)
    done = run(path)
    assert done.returncode == 1
    assert "code cells [1] have outputs" in done.stderr
    assert run(path, "--strip").returncode == 0
    assert cells_with_outputs(nbformat.read(path, as_version=4)) == []


def test_a_missing_notebook_is_a_one_line_error(tmp_path):
    done = run(tmp_path / "nowhere.ipynb")
    assert done.returncode == 2
    assert done.stderr.strip().endswith("no such file")
