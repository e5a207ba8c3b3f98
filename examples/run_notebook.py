#!/usr/bin/env python3
"""Execute a notebook headless and fail on any error: `make test-notebook` runs the tour with it.

    run_notebook.py NOTEBOOK [--timeout S] [--budget S] [--workdir DIR] [--executed PATH]
    run_notebook.py NOTEBOOK --strip       remove outputs and execution counts in place

Before running, it checks that the committed file has no outputs (they are not committed: a
cell with outputs or an execution count fails the run; ``--strip`` removes them). The cells
run in order in a fresh kernel of this interpreter (ipykernel, through nbclient), in
``--workdir`` (default: a new temporary folder, so that ``import mcplay`` finds the installed
package and not a source tree); a cell that raises, or a run longer than ``--budget`` seconds,
fails. ``--executed`` saves the executed copy (with its outputs) for reading.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

import nbformat
from traitlets.config import Config
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError


def cells_with_outputs(nb: nbformat.NotebookNode) -> list[int]:
    """The indices of the code cells that carry outputs or an execution count."""
    return [i for i, cell in enumerate(nb.cells)
            if cell.cell_type == "code" and (cell.get("outputs") or cell.get("execution_count"))]


def strip(path: Path) -> None:
    """Remove every code cell's outputs and execution count, in place."""
    nb = nbformat.read(path, as_version=4)
    for cell in nb.cells:
        if cell.cell_type == "code":
            cell.outputs = []
            cell.execution_count = None
    nbformat.write(nb, path)
    print(f"run_notebook: stripped {path}")


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("notebook", type=Path)
    ap.add_argument("--timeout", type=float, default=300, help="seconds per cell (300)")
    ap.add_argument("--budget", type=float, default=240, help="seconds for the whole run (240)")
    ap.add_argument("--workdir", type=Path, help="where the cells run (default: a temporary dir)")
    ap.add_argument("--executed", type=Path, help="write the executed notebook here")
    ap.add_argument("--strip", action="store_true", help="strip outputs in place and stop")
    o = ap.parse_args()
    if not o.notebook.is_file():
        print(f"run_notebook: {o.notebook}: no such file", file=sys.stderr)
        return 2
    if o.strip:
        strip(o.notebook)
        return 0

    nb = nbformat.read(o.notebook, as_version=4)
    nbformat.validate(nb)
    dirty = cells_with_outputs(nb)
    if dirty:
        print(f"run_notebook: {o.notebook}: code cells {dirty} have outputs or execution counts; "
              f"outputs are not committed (run with --strip)", file=sys.stderr)
        return 1
    code_cells = sum(cell.cell_type == "code" for cell in nb.cells)

    with tempfile.TemporaryDirectory(prefix="mcplay-notebook-") as tmp:
        workdir = o.workdir or Path(tmp)
        workdir.mkdir(parents=True, exist_ok=True)
        # "python3" is ipykernel's native kernel (this interpreter and its packages), reached
        # over local sockets in the temporary folder rather than TCP.
        config = Config()
        config.KernelManager.transport = "ipc"
        config.KernelManager.ip = str(Path(tmp) / "kernel")
        client = NotebookClient(nb, timeout=o.timeout, kernel_name="python3", config=config,
                                resources={"metadata": {"path": str(workdir)}})
        start = time.perf_counter()
        try:
            client.execute()
        except CellExecutionError as error:
            print(f"run_notebook: {o.notebook}: a cell failed:\n{error}", file=sys.stderr)
            return 1
        finally:
            if o.executed:
                o.executed.parent.mkdir(parents=True, exist_ok=True)
                nbformat.write(nb, o.executed)
        seconds = time.perf_counter() - start

    errors = [i for i, cell in enumerate(nb.cells) if cell.cell_type == "code"
              for out in cell.get("outputs", []) if out.get("output_type") == "error"]
    if errors:
        print(f"run_notebook: {o.notebook}: error outputs in cells {errors}", file=sys.stderr)
        return 1
    if seconds > o.budget:
        print(f"run_notebook: {o.notebook}: ran {seconds:.0f} s, over its budget of "
              f"{o.budget:.0f} s", file=sys.stderr)
        return 1
    print(f"run_notebook: {o.notebook}: {code_cells} code cells ran clean in {seconds:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
