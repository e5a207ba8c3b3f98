# ---------------------------------------------------------------------------
# The example notebook (examples/mcplay_tour.ipynb), executed headless: examples/run_notebook.py
# (nbclient, nbformat, ipykernel) refuses a committed notebook with outputs, runs every cell in a
# fresh kernel from a folder outside the source tree and fails on any error; its own tests
# (examples/test_run_notebook.py) run first. It uses the installed wheel of $(NOTEBOOK_VENV)
# (make test-python builds it, with the notebook's tools among the test extras; make check runs
# this target right after it); when that venv lacks them, it installs the package from this
# repository (pip install .) and the tools into $(NOTEBOOK_OWN_VENV). The executed copy, with its
# outputs, is left in $(BUILD)/notebook/ for reading.
.PHONY: test-notebook
NOTEBOOK_VENV ?= $(BUILD)/py-test-venv
NOTEBOOK_OWN_VENV := $(BUILD)/notebook-venv
NOTEBOOK_TOOLS := nbclient nbformat ipykernel matplotlib pandas pytest
NOTEBOOK_PROBE := import mcplay, nbclient, nbformat, ipykernel, matplotlib, pandas, pytest

test-notebook: deps | deps-venv
	@py=$(abspath $(NOTEBOOK_VENV))/bin/python; \
	if ! $$py -c '$(NOTEBOOK_PROBE)' 2>/dev/null; then \
	  py=$(abspath $(NOTEBOOK_OWN_VENV))/bin/python; \
	  echo "test-notebook: $(NOTEBOOK_VENV) lacks the package or the notebook's tools (make test-python makes it); installing into $(NOTEBOOK_OWN_VENV)"; \
	  { [ -x $$py ] || python3 -m venv $(NOTEBOOK_OWN_VENV); } && \
	  $(NOTEBOOK_OWN_VENV)/bin/pip install -q . $(NOTEBOOK_TOOLS) || exit 1; \
	fi; \
	mkdir -p $(BUILD)/notebook && cd $(BUILD)/notebook && \
	$$py -m pytest -q -p no:cacheprovider $(CURDIR)/examples/test_run_notebook.py && \
	$$py $(CURDIR)/examples/run_notebook.py $(CURDIR)/examples/mcplay_tour.ipynb \
	  --executed $(abspath $(BUILD))/notebook/mcplay_tour.executed.ipynb
