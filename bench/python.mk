# ---------------------------------------------------------------------------
# mcplay from Python beside vegas and QMCPy (docs/benchmarks.md, "From Python: beside vegas and
# QMCPy"): bench/python_compare.py in a virtual environment of its own under $(BUILD), with the
# anchors at pinned versions and the package installed from this repository (`pip install .`,
# incremental after the first build). Not in make test or make check.
#   make bench-python                                  the whole run (about 5 minutes)
#   make bench-python BENCH_PY_ARGS="--reps 10 --dims 4"   a quicker look
#   make bench-python BENCH_PY_ARGS=--callable-vs-expression   the speed check alone
.PHONY: bench-python
BENCH_PY_VENV := $(BUILD)/bench-python-venv
BENCH_PY_DIR := $(BUILD)/bench-python
BENCH_PY_ARGS ?=
BENCH_PY_PINS := vegas==6.4.1 qmcpy==2.4 numpy scipy

$(BENCH_PY_VENV)/installed: | deps-venv
	python3 -m venv $(BENCH_PY_VENV)
	$(BENCH_PY_VENV)/bin/pip install -q $(BENCH_PY_PINS)
	@touch $@

bench-python: deps $(BENCH_PY_VENV)/installed
	$(BENCH_PY_VENV)/bin/pip install -q .
	mkdir -p $(BENCH_PY_DIR)
	cd $(BENCH_PY_DIR) && set -o pipefail && $(CURDIR)/$(BENCH_PY_VENV)/bin/python \
	  $(CURDIR)/bench/python_compare.py --jsonl compare.jsonl $(BENCH_PY_ARGS) | tee compare.txt
