# mcplay: the two commands a fresh machine needs are `make run` and `make test`.
# Both install missing Debian packages first (`make deps`). `make check` is what CI runs:
# `make test` plus the sanitized suite and the fuzz-corpus replay.

SHELL := /bin/bash
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD ?= build
BUILD_WASM ?= build-wasm
BUILD_ASAN ?= build-asan
BUILD_FUZZ ?= build-fuzz
FUZZ_TARGETS ?= scene expression gltf hdr points
FUZZ_SECONDS ?= 600
# -fork=1 runs the fuzzing in one child process at a time and goes on after a crash, a timeout
# or an OOM (each saved in findings/), so one known bug does not end the run.
FUZZ_FLAGS ?= -timeout=10 -rss_limit_mb=2048 -fork=1 -ignore_crashes=1 -ignore_timeouts=1 \
	-ignore_ooms=1
# Longest input per target: scenes and HDR images are small; the glTF seeds embed base64
# buffers (scenes/cornell_box.gltf is 58 KB); expressions are capped at 10000 bytes.
FUZZ_MAX_LEN_scene := 16384
FUZZ_MAX_LEN_expression := 12000
FUZZ_MAX_LEN_gltf := 65536
FUZZ_MAX_LEN_hdr := 16384
FUZZ_MAX_LEN_points := 16384
fuzz_max_len = $$(case $(1) in scene) echo $(FUZZ_MAX_LEN_scene);; \
	expression) echo $(FUZZ_MAX_LEN_expression);; gltf) echo $(FUZZ_MAX_LEN_gltf);; \
	*) echo $(FUZZ_MAX_LEN_hdr);; esac)
# Seed folders of a target: its own seeds (if it has any: libFuzzer stops at a missing folder),
# the scenes (for scene and gltf), tests/corpus/.
fuzz_seeds = $$([ -d fuzz/seeds/$(1) ] && echo fuzz/seeds/$(1)) \
	$$(case $(1) in scene|gltf) echo scenes;; esac) \
	$$([ -d tests/corpus ] && echo tests/corpus)
SCENE ?= scenes/exp_1d.json
ARGS ?=
PORT ?= 8000
SITE := $(BUILD)/site

# Node 20's fetch() cannot load the .wasm beside a non-ES6 Emscripten program from a file path;
# the CLI and the bench read theirs from disk (src/wasm/node_pre.js) and need no flag, the
# flag stays for any program linked without it.
NODE_RUN := node --no-experimental-fetch

# emcc's JavaScript optimiser needs Debian's acorn when node is not Debian's own.
export NODE_PATH := /usr/share/nodejs

APT_PACKAGES := cmake ninja-build g++ make googletest libgtest-dev emscripten libglm-dev \
	libstb-dev libtinygltf-dev nlohmann-json3-dev chromium clang-format ccache
# One file or command per package that tells whether it is installed.
DEP_PROBES := /usr/bin/cmake /usr/bin/ninja /usr/bin/g++ /usr/src/googletest/CMakeLists.txt \
	/usr/include/gtest/gtest.h /usr/bin/em++ /usr/include/glm/glm.hpp /usr/include/stb/stb_image_write.h \
	/usr/include/tiny_gltf.h /usr/include/nlohmann/json.hpp /usr/bin/chromium /usr/bin/clang-format \
	/usr/bin/ccache

.PHONY: all deps deps-web deps-npm build build-wasm site test test-native test-wasm test-native-check test-wasm-check test-compare test-web-core \
	test-npm test-e2e test-sanitize test-suites check run cli bench bench-mitsuba bench-embree format format-files clean help \
	fuzz fuzz-build fuzz-smoke deps-fuzz

all: build

help:
	@echo "make run    build everything and serve the playground on http://localhost:$(PORT)/"
	@echo "make cli    build the native CLI and run it on $(SCENE)"
	@echo "make test   the contributor's loop: install what is missing, build native + wasm, run the"
	@echo "           native, wasm, Node and Chromium suites (independent ones at the same time)"
	@echo "make test-npm  the wasm core as the npm package mcplay: packed, installed from the tarball into an"
	@echo "           empty folder, run there against the native CLI and in Chromium; its types checked"
	@echo "make check  everything CI runs: make test, then the ASan/UBSan suite, make fuzz-smoke, the"
	@echo "           stopping promise runs (test-native-check) and the wasm modules make test leaves out:"
	@echo "           statistical and long modules, CLI scripts (test-wasm-check); the Python suites"
	@echo "make bench  samples per second natively and in wasm under Node, and their ratio; then bench-genz"
	@echo "make bench-genz  mcplay beside GSL plain/MISER/VEGAS on Genz's families (GENZ_ARGS=--quick: 15 s)"
	@echo "make bench-genz-peaks  vegas, vegas_plus beside GSL VEGAS on sharp product peaks (~4 min)"
	@echo "make bench-flags  the flags judged both ways: false alarms where intervals covered, confident wrong answers"
	@echo "make bench-flags-fresh  the same, blind, on new random cases (FRESH_SEEDS=a,b: seeds never used)"
	@echo "make bench-qmc  mcplay's randomized QMC beside QMCPy's and scipy's on Genz 1, 4, 5 (pip venv in build/)"
	@echo "make bench-mitsuba  the renderer beside Mitsuba 3.9.1 on three glTF scenes: time, relMSE, efficiency (ARGS: --quick, --sobol, --scalar, --widths)"
	@echo "make bench-embree  the accelerator beside Embree 3 (Debian's libembree-dev) on the same rays, one thread"
	@echo "make format clang-format every C++ source, untracked ones too (make -s format-files lists them)"
	@echo "make test-python  build the Python wheel, install it in a fresh venv, run python/tests (part of make check)"
	@echo "make test-notebook  run examples/mcplay_tour.ipynb headless with the installed wheel (part of make check)"
	@echo "make bench-python  the Python package beside vegas and QMCPy on Genz's families; callable against expression"
	@echo "make test-sanitize  the native ctest suite under ASan + UBSan ($(BUILD_ASAN); part of make check)"
	@echo "make fuzz   libFuzzer targets, $(FUZZ_SECONDS) s each (FUZZ_TARGETS=\"$(FUZZ_TARGETS)\"); docs/fuzzing.md"
	@echo "make fuzz-smoke  each fuzz target over its seed corpus only (seconds)"

deps:
	@missing=""; for p in $(DEP_PROBES); do [ -e $$p ] || missing="$$missing $$p"; done; \
	command -v node >/dev/null || missing="$$missing node"; \
	if [ -n "$$missing" ]; then \
	  echo "deps: missing$$missing"; \
	  if [ "$$(id -u)" = 0 ]; then \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends $(APT_PACKAGES); \
	  else \
	    echo "deps: not root; run: sudo apt-get install -y --no-install-recommends $(APT_PACKAGES)"; exit 1; \
	  fi; \
	fi

# npm packages of the page (uPlot; playwright-core for the browser tests), from the lock file.
deps-web: web/node_modules/.package-lock.json

web/node_modules/.package-lock.json: web/package.json web/package-lock.json | deps
	cd web && npm ci --no-audit --no-fund
	@touch $@

# ---------------------------------------------------------------------------
# The Python package (pyproject.toml, src/python, python/). build/ also builds the extension
# mcplay._core, with the virtual environment $(PY_VENV) (`make deps-python`: numpy, nanobind and
# pytest from PyPI, made before build/ is configured, while the wasm build goes on under make -j):
# ctest's python_smoke then imports it from the build tree. `make test-python`
# (in `make check`) builds a wheel with pip, installs it in a fresh virtual environment with the
# test extras and runs python/tests against the installed package.
PY_VENV := $(BUILD)/py-venv
PY_TEST_VENV := $(BUILD)/py-test-venv
PY_WHEELHOUSE := $(BUILD)/wheelhouse
# Expanded when a recipe runs, so that a venv made earlier in the same make counts.
PY_CMAKE_FLAGS = $(if $(wildcard $(PY_VENV)/installed),-DMCPLAY_PYTHON=ON \
	-DPython_EXECUTABLE=$(CURDIR)/$(PY_VENV)/bin/python \
	-Dnanobind_DIR=$$($(PY_VENV)/bin/python -m nanobind --cmake_dir))

# Build trees are configured for Ninja: it rebuilds what a changed command line concerns, where
# CMake's Makefiles make every object of a target depend on one flags file that lists its
# sources (a new test file recompiled every test file and the precompiled header). A tree
# configured earlier keeps its generator.
CMAKE_GEN := -G Ninja

# Order-only on deps: under make -j the configure step must wait for apt-get (and the venv).
$(BUILD)/CMakeCache.txt: | deps deps-python
	cmake $(CMAKE_GEN) -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(PY_CMAKE_FLAGS)

$(BUILD_WASM)/CMakeCache.txt: | deps
	emcmake cmake $(CMAKE_GEN) -S . -B $(BUILD_WASM) -DCMAKE_BUILD_TYPE=Release

build: deps deps-python $(BUILD)/CMakeCache.txt
	@if [ -e $(PY_VENV)/installed ] && ! grep -q '^MCPLAY_PYTHON:BOOL=ON' $(BUILD)/CMakeCache.txt; then \
	  echo "build: $(PY_VENV) exists: configuring $(BUILD) with the Python extension"; \
	  cmake -S . -B $(BUILD) $(PY_CMAKE_FLAGS); \
	fi
	cmake --build $(BUILD) -j $(JOBS) $(if $(BUILD_EXTRA),--target all $(BUILD_EXTRA))

# Targets built with the native build when a target below asks for them: the site's references
# (CMake target site_references, run within the native build once the CLI is linked; `make
# build` alone renders none).
BUILD_EXTRA :=
test-suites run site: BUILD_EXTRA := site_references

build-wasm: deps $(BUILD_WASM)/CMakeCache.txt
	cmake --build $(BUILD_WASM) -j $(JOBS)

# The statistical promise runs (label statistical: test_stopping_promise, hundreds of stopping
# runs per estimator) and the modules of long statistical loops (label long: 5-40 s each
# natively, 10-100 s under Node; about 150 s of CPU natively) wait for `make check`, natively and
# under Node. Under Node one more label waits: the CLI's scripts ("cli": cli and corpus, minutes
# under Node; the loop runs them natively, and test-compare every scene through the wasm CLI).
NATIVE_CHECK_LABELS := ^(statistical|long)$$
WASM_CHECK_LABELS := ^(statistical|cli|long)$$
test-native: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -LE '$(NATIVE_CHECK_LABELS)'

test-native-check: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) -L '$(NATIVE_CHECK_LABELS)'

test-wasm: build-wasm
	ctest --test-dir $(BUILD_WASM) --output-on-failure -j $(JOBS) -LE '$(WASM_CHECK_LABELS)'

test-wasm-check: build-wasm
	ctest --test-dir $(BUILD_WASM) --output-on-failure -j $(JOBS) -L '$(WASM_CHECK_LABELS)'

# The same study through the native CLI and the wasm CLI under Node must agree.
test-compare: build build-wasm
	bash tests/compare_native_wasm.sh $(BUILD)/mcplay "$(NODE_RUN) $(BUILD_WASM)/mcplay.js"

# The page's unit tests (web/test/) under Node's test runner: its pure modules, and web/core.js and
# web/render_core.js (the only callers of the browser wasm modules) compared with the native CLI.
test-web-core: build build-wasm deps-web
	MCPLAY_WASM_DIR=$(BUILD_WASM) MCPLAY_NATIVE=$(BUILD)/mcplay node --test web/test/

# TypeScript for checking the npm package's declarations, from npm/package-lock.json (a
# devDependency of npm/ only: the package itself has no dependencies).
deps-npm: npm/node_modules/.package-lock.json

npm/node_modules/.package-lock.json: npm/package.json npm/package-lock.json | deps
	cd npm && npm ci --no-audit --no-fund
	@touch $@

# The wasm core as the npm package "mcplay" (npm/README.md): staged from npm/, web/core.js,
# web/render_core.js and the wasm build, packed (build-wasm/mcplay-<version>.tgz), installed from
# the tarball into an empty folder with no registry, and run there by its package name against
# the native CLI (npm/test/installed.test.mjs) and by URL in headless Chromium, in a page and a
# module Worker (npm/test/browser.test.mjs, playwright-core from deps-web); its .d.ts files
# type-checked with a user's code (npm/test/types_usage.ts).
test-npm: build build-wasm deps-npm deps-web
	cd npm && npx --no-install tsc -p test/tsconfig.json
	@tgz=$$(node npm/tools/stage.mjs --wasm-dir $(BUILD_WASM)) && \
	tmp=$$(mktemp -d) && trap 'rm -rf "$$tmp"' EXIT && \
	cp npm/test/installed.test.mjs "$$tmp"/ && cd "$$tmp" && \
	npm install --no-audit --no-fund --offline --loglevel=error "$$tgz" && \
	MCPLAY_ROOT=$(CURDIR) MCPLAY_NATIVE=$(abspath $(BUILD))/mcplay \
	  node --test installed.test.mjs $(CURDIR)/npm/test/browser.test.mjs

# The playground: page, wasm module, uPlot and the scenes with their manifest.
site: build build-wasm deps-web
	node web/tools/build-site.mjs $(SITE) $(BUILD_WASM) $(BUILD)/mcplay

# The page in headless Chromium, checked against the native CLI; screenshots in build/e2e. Two
# files at a time (Node's default on 2 cores is one): each waits on its page most of the time.
# The longest files first (playground 52 s, page_view 29 s of 149 s), so that the two lanes end
# together.
E2E_LONGEST := web/e2e/playground.e2e.mjs web/e2e/page_view.e2e.mjs
E2E_FILES := $(wildcard $(E2E_LONGEST)) $(filter-out $(E2E_LONGEST),$(sort $(wildcard web/e2e/*.e2e.mjs)))
test-e2e: build site
	MCPLAY_SITE=$(SITE) MCPLAY_NATIVE=$(BUILD)/mcplay MCPLAY_SHOTS=$(BUILD)/e2e node --test \
	  --test-concurrency=2 $(E2E_FILES)

# The native suite again, built with g++ -fsanitize=address,undefined (CMake option MCPLAY_SANITIZE):
# a leak, an out-of-bounds access or undefined behaviour fails the test that triggers it.
# -O1 with assertions on: about 3x slower than Release, and every assert() is checked.
$(BUILD_ASAN)/CMakeCache.txt: | deps
	cmake $(CMAKE_GEN) -S . -B $(BUILD_ASAN) -DMCPLAY_SANITIZE=ON -DMCPLAY_UNITY=OFF -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g"

test-sanitize: deps $(BUILD_ASAN)/CMakeCache.txt
	cmake --build $(BUILD_ASAN) -j $(JOBS)
	ctest --test-dir $(BUILD_ASAN) --output-on-failure -j $(JOBS)

# The contributor's loop. The native and the wasm build, and the suites that need only one of
# them, run at the same time (make -j2: two builds of -j $(JOBS) each), so their lines of output
# interleave; a failure ends with make naming the target (test-native, test-wasm, ...) that failed.
TEST_JOBS ?= 2
test:
	@start=$$(date +%s); \
	$(MAKE) --no-print-directory -j $(TEST_JOBS) test-suites && \
	echo "make test: all suites passed in $$(( $$(date +%s) - start )) s"

# `site` first: it is the chain before test-e2e (its references are rendered during the native
# build, BUILD_EXTRA above), so that make -j assembles it as soon as the builds are done.
test-suites: site test-native test-wasm test-compare test-web-core test-npm test-e2e

# Everything: the loop, then the suites too slow for it (sanitizers; the fuzz targets, built with
# clang, over their seed corpus and past findings; the Python wheel's tests and the notebook).
# .ci/run runs this.
check:
	@start=$$(date +%s); \
	$(MAKE) --no-print-directory test && \
	$(MAKE) --no-print-directory -j 2 test-sanitize fuzz-smoke test-native-check test-wasm-check test-python && \
	$(MAKE) --no-print-directory test-notebook && \
	echo "make check: all suites passed in $$(( $$(date +%s) - start )) s"

run: build site
	PORT=$(PORT) node web/tools/serve.mjs $(SITE)

cli: build
	./$(BUILD)/mcplay run $(SCENE) $(ARGS)

# mcplay's renderer beside Mitsuba 3.9.1 on the same glTF scenes (not part of make test): installs
# Debian's libllvm19 (drjit 1.5 needs LLVM >= 16) and Mitsuba into a virtual environment under
# build/ with pip, then bench/mitsuba/bench_mitsuba.py (about 10 minutes on 2 cores).
MITSUBA_VENV := $(BUILD)/mitsuba-venv
LIBLLVM19 := /usr/lib/x86_64-linux-gnu/libLLVM.so.19.1
bench-mitsuba: build
	@[ -e $(LIBLLVM19) ] || { if [ "$$(id -u)" = 0 ]; then DEBIAN_FRONTEND=noninteractive apt-get install -y -q libllvm19; \
	  else echo "bench-mitsuba: run as root, or: sudo apt-get install libllvm19"; exit 1; fi; }
	@[ -x $(MITSUBA_VENV)/bin/python ] || python3 -m venv $(MITSUBA_VENV)
	@$(MITSUBA_VENV)/bin/python -c "import mitsuba, numpy" 2>/dev/null || \
	  $(MITSUBA_VENV)/bin/pip install -q mitsuba==3.9.1 drjit==1.5.0 numpy
	DRJIT_LIBLLVM_PATH=$(LIBLLVM19) $(MITSUBA_VENV)/bin/python bench/mitsuba/bench_mitsuba.py --mcplay $(BUILD)/mcplay $(ARGS)

bench: build build-wasm site
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_bench
	cmake --build $(BUILD_WASM) -j $(JOBS) --target mcplay_bench
	bash bench/run_bench.sh $(BUILD)/mcplay_bench "$(NODE_RUN) --no-liftoff $(BUILD_WASM)/mcplay_bench.js"
	bash bench/kernels.sh $(BUILD) $(BUILD_WASM)
	node web/e2e/first_plot.bench.mjs $(SITE) all 3
	node web/e2e/live_view.bench.mjs $(SITE) all 3 2
	$(MAKE) --no-print-directory bench-genz
	$(MAKE) --no-print-directory bench-flags

# ---------------------------------------------------------------------------
# The accelerator beside Embree 3, the kernels under Mitsuba's llvm variants (docs/benchmarks.md):
# bench/embree_compare.cpp, built with g++ against the CMake-built static libraries and
# Debian's libembree-dev; rays per second of one thread on `make bench`'s ray sets.
.PHONY: bench-embree deps-embree
EMBREE_ARGS ?= scenes

deps-embree:
	@if [ ! -e /usr/include/embree3/rtcore.h ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends libembree-dev; \
	  else \
	    echo "deps-embree: not root; run: sudo apt-get install -y --no-install-recommends libembree-dev"; exit 1; \
	  fi; \
	fi

$(BUILD)/embree_compare: bench/embree_compare.cpp bench/bench_rays.h $(BUILD)/libmcplay_render_api.a \
		$(BUILD)/libmcplay_render.a $(BUILD)/libmcplay_api.a $(BUILD)/libmcplay_core.a $(wildcard src/*/*.h)
	g++ -O2 -std=c++17 -ffp-contract=off -Isrc -I$(BUILD)/deps_include bench/embree_compare.cpp \
	  $(BUILD)/libmcplay_render_api.a $(BUILD)/libmcplay_render.a $(BUILD)/libmcplay_api.a \
	  $(BUILD)/libmcplay_core.a -lembree3 -pthread -o $@

bench-embree: deps deps-embree $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_render_api
	$(MAKE) --no-print-directory $(BUILD)/embree_compare
	$(BUILD)/embree_compare $(EMBREE_ARGS)

# ---------------------------------------------------------------------------
# GSL's plain, MISER and VEGAS beside mcplay's estimators on Genz's six families
# (docs/benchmarks.md): bench/genz_compare.cpp, built with g++ against the CMake-built static
# libraries and Debian's libgsl-dev. `make bench-genz GENZ_ARGS=--quick` for a fast look.
.PHONY: bench-genz deps-gsl
GENZ_ARGS ?=
GENZ_JSON ?= $(BUILD)/genz_compare.jsonl

deps-gsl:
	@if ! command -v gsl-config >/dev/null; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends libgsl-dev; \
	  else \
	    echo "deps-gsl: not root; run: sudo apt-get install -y --no-install-recommends libgsl-dev"; exit 1; \
	  fi; \
	fi

$(BUILD)/genz_compare: bench/genz_compare.cpp $(BUILD)/libmcplay_api.a $(BUILD)/libmcplay_core.a \
		$(wildcard src/*/*.h)
	g++ -O2 -std=c++17 -ffp-contract=off -Isrc -I$(BUILD)/deps_include $$(gsl-config --cflags) \
	  bench/genz_compare.cpp $(BUILD)/libmcplay_api.a $(BUILD)/libmcplay_core.a \
	  $$(gsl-config --libs) -pthread -o $@

bench-genz: deps deps-gsl $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_api
	$(MAKE) --no-print-directory $(BUILD)/genz_compare
	set -o pipefail; $(BUILD)/genz_compare --json $(GENZ_JSON) $(GENZ_ARGS) | tee $(BUILD)/genz_compare.txt

# Sharp separable peaks: GSL's VEGAS beside mcplay's vegas and vegas_plus (docs/benchmarks.md).
.PHONY: bench-genz-peaks
bench-genz-peaks:
	$(MAKE) --no-print-directory bench-genz GENZ_JSON=$(BUILD)/genz_peaks.jsonl \
	  GENZ_ARGS="--peaks --gsl vegas --methods vegas,vegas_plus $(GENZ_ARGS)"

# ---------------------------------------------------------------------------
# The flags judged both ways (docs/benchmarks.md): bench/calibrate.cpp runs studies through the
# C API, as the CLI and the page run them, and reports the share of fine cells that carry an
# alarm and the confident wrong answers. Two runs:
#  - held out: Genz's six families and singular products (finite and infinite variance) at
#    d = 2, 4, 8, 16 with parameter seeds the rules were never tuned on (7001, 7002), each N of
#    FLAGS_NS alone, R = 32 (the CLI's default), a cell fine by its coverage (29 of 32 within
#    1.96 t se, none beyond 3.5); --recheck 20 runs 20 flagged and 20 unflagged fine cells again
#    with 100 replicates, to judge the alarms by what they claim;
#  - the integration scenes with an exact value, their own estimators and each preset, N ladder.
# `make bench-flags` runs N = 16384 (about 5 minutes on 2 cores); FLAGS_NS=16384,1048576 adds
# 2^20, hours on 2 cores (45 minutes of CPU on 2026-12-04 did not finish it).
.PHONY: bench-flags
FLAGS_ARGS ?=
FLAGS_NS ?= 16384

$(BUILD)/calibrate: bench/calibrate.cpp $(BUILD)/libmcplay_api.a $(BUILD)/libmcplay_core.a \
		$(wildcard src/*/*.h)
	g++ -O2 -std=c++17 -ffp-contract=off -Wall -Wextra -Isrc -I$(BUILD)/deps_include \
	  bench/calibrate.cpp $(BUILD)/libmcplay_api.a $(BUILD)/libmcplay_core.a -pthread -o $@

bench-flags: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_api
	$(MAKE) --no-print-directory $(BUILD)/calibrate
	mkdir -p $(BUILD)/calibrate-empty
	set -o pipefail; $(BUILD)/calibrate --singular --dims 2,4,8,16 --param-seeds 7001,7002 \
	  --ns $(FLAGS_NS) --reps 32 --fine coverage --scenes $(BUILD)/calibrate-empty \
	  --cells $(BUILD)/calibrate-heldout.jsonl --recheck 20 $(FLAGS_ARGS) 2>/dev/null \
	  | tee $(BUILD)/calibrate-heldout.txt
	set -o pipefail; $(BUILD)/calibrate --no-genz --scenes scenes --reps 32 --fine coverage \
	  --json $(BUILD)/calibrate.jsonl $(FLAGS_ARGS) 2>/dev/null | tee $(BUILD)/calibrate.txt

# Fresh cases judged blind (issue 48): Genz's six families, the singular products and the
# products on either side of an infinite variance (--border) at parameter seeds FRESH_SEEDS
# (choose new ones for each look: cases the rules were never tuned on), d = 3, 5, 7, 10,
# N = 8192, R = 32, the studies not told the exact value (--blind), as a user's own integrand
# runs; judged against it. About 2.5 minutes on 2 cores.
.PHONY: bench-flags-fresh
FRESH_SEEDS ?= 48201,48202
bench-flags-fresh: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_api
	$(MAKE) --no-print-directory $(BUILD)/calibrate
	mkdir -p $(BUILD)/calibrate-empty
	set -o pipefail; $(BUILD)/calibrate --blind --singular --border --dims 3,5,7,10 \
	  --param-seeds $(FRESH_SEEDS) --ns 8192 --reps 32 --fine coverage \
	  --scenes $(BUILD)/calibrate-empty --cells $(BUILD)/calibrate-fresh.jsonl $(FLAGS_ARGS) \
	  2>/dev/null | tee $(BUILD)/calibrate-fresh.txt

# ---------------------------------------------------------------------------
# Randomized QMC beside QMCPy's and scipy's (docs/benchmarks.md): genz_compare writes the
# cases' parameters, bench/qmc_tools.py runs the other tools on them (installed with pip into a
# virtual environment under $(BUILD); nothing else uses it), genz_compare runs mcplay's RQMC
# estimators and GSL's plain and MISER and prints all of them in one table.
# QMC_REPS replicates per (case, method); `make bench-qmc QMC_REPS=5` for a fast look. Every
# knob is a variable; both sides get the same N (QMC_N) and K randomizations of N/K points
# (QMC_K; 1 = one net: QMC_METHODS=sobol_walsh on mcplay's side). Issue 49's oscillatory study
# (docs/performance-notes.md):
#   make bench-qmc QMC_CASES="--families 1 --dims 3,5,10,20" QMC_PARAM_SEED=52 QMC_REPS=100 \
#     QMC_GSL=none QMC_METHODS=sobol,sobol:lms_shift QMC_TOOLS=qmcpy_lms,scipy_sobol QMC_K=4
.PHONY: bench-qmc deps-venv
QMC_REPS ?= 40
QMC_N ?= 1048576
QMC_K ?= 16
QMC_PARAM_SEED ?= 1
QMC_DIR ?= $(BUILD)/bench-qmc
QMC_VENV := $(BUILD)/bench-venv
QMC_CASES ?= --families 1,4,5 --dims 2,4,8,16
QMC_GSL ?= plain,miser
QMC_METHODS ?= sobol,sobol:lms_shift,sobol:digital_shift,lattice,halton
QMC_TOOLS ?= qmcpy_lms,qmcpy_lattice,scipy_sobol

# After deps: two apt-get runs at once fail (their package cache is shared).
deps-venv: deps
	@if ! python3 -c 'import ensurepip, venv' 2>/dev/null; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends python3-venv; \
	  else \
	    echo "deps-venv: not root; run: sudo apt-get install -y --no-install-recommends python3-venv"; exit 1; \
	  fi; \
	fi

# The build tree's Python: numpy, nanobind (the extension's build) and pytest.
.PHONY: deps-python test-python
deps-python: $(PY_VENV)/installed

$(PY_VENV)/installed: | deps-venv
	python3 -m venv $(PY_VENV)
	$(PY_VENV)/bin/pip install -q numpy nanobind pytest
	@touch $@

# The wheel as a user gets it: built by pip from the project's own files (scikit-build-core and
# nanobind from PyPI, in pip's isolated build environment; objects kept in build/skbuild), installed
# with the test extras into a virtual environment made anew each run; pytest runs from a folder
# outside the source tree, so `import mcplay` finds only the installed package.
# The native CLI is built first: the tests compare the package's numbers with its output.
test-python: build | deps-venv
	rm -rf $(PY_TEST_VENV) $(PY_WHEELHOUSE)
	python3 -m venv $(PY_TEST_VENV)
	$(PY_TEST_VENV)/bin/pip wheel -q --no-deps -w $(PY_WHEELHOUSE) .
	$(PY_TEST_VENV)/bin/pip install -q "$$(ls $(PY_WHEELHOUSE)/mcplay-*.whl)[test]"
	mkdir -p $(BUILD)/py-test-run
	cd $(BUILD)/py-test-run && MCPLAY_EXPECT_INSTALLED=1 MCPLAY_CLI=$(CURDIR)/$(BUILD)/mcplay \
	  $(CURDIR)/$(PY_TEST_VENV)/bin/python -m pytest -rs \
	  -p no:cacheprovider --import-mode=importlib --rootdir $(CURDIR) $(CURDIR)/python/tests

$(QMC_VENV)/installed: | deps-venv
	python3 -m venv $(QMC_VENV)
	$(QMC_VENV)/bin/pip install -q qmcpy==2.4 scipy numpy
	@touch $@

bench-qmc: deps deps-gsl $(BUILD)/CMakeCache.txt $(QMC_VENV)/installed
	cmake --build $(BUILD) -j $(JOBS) --target mcplay_api
	$(MAKE) --no-print-directory $(BUILD)/genz_compare
	rm -rf $(QMC_DIR)/params && $(BUILD)/genz_compare $(QMC_CASES) --param-seed $(QMC_PARAM_SEED) \
	  --write-params $(QMC_DIR)/params
	$(QMC_VENV)/bin/python bench/qmc_tools.py $(QMC_DIR)/params --n $(QMC_N) --reps $(QMC_REPS) \
	  --randomizations $(QMC_K) --methods $(QMC_TOOLS) > $(QMC_DIR)/tools.jsonl
	set -o pipefail; $(BUILD)/genz_compare $(QMC_CASES) --params-dir $(QMC_DIR)/params \
	  --external $(QMC_DIR)/tools.jsonl --n $(QMC_N) --reps $(QMC_REPS) --gsl $(QMC_GSL) \
	  --randomizations $(QMC_K) --methods $(QMC_METHODS) \
	  --json $(QMC_DIR)/compare.jsonl | tee $(QMC_DIR)/compare.txt

# The C++ sources, tracked and untracked (not ignored): a new file is formatted before its first
# commit. `make -s format-files` lists them (tests/make_format_test.sh).
FORMAT_FILES = git ls-files --cached --others --exclude-standard '*.cpp' '*.h' | sort -u | \
	while read -r f; do [ -e "$$f" ] && echo "$$f"; done

format-files:
	@$(FORMAT_FILES)

format: deps
	$(FORMAT_FILES) | xargs -r clang-format -i

# ---------------------------------------------------------------------------
# libFuzzer (docs/fuzzing.md): clang 14 + libclang-rt-14-dev, a build of its own ($(BUILD_FUZZ)),
# one target per parser. `make fuzz` runs the targets one after the other, FUZZ_SECONDS each;
# crashes, timeouts and OOMs go to $(BUILD_FUZZ)/findings/<target>/, the grown corpus to
# $(BUILD_FUZZ)/corpus/<target>/, the log to $(BUILD_FUZZ)/logs/<target>.log.
# `make fuzz FUZZ_TARGETS=scene FUZZ_SECONDS=60` runs one target for a minute.
# Debian's clang and its libFuzzer runtime, installed like `make deps` does.
deps-fuzz: deps
	@if ! command -v clang++ >/dev/null || [ ! -e /usr/lib/llvm-14/lib/clang/14.0.6/lib/linux/libclang_rt.fuzzer-x86_64.a ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    apt-get update -q && DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends clang libclang-rt-14-dev; \
	  else \
	    echo "fuzz: not root; run: sudo apt-get install -y --no-install-recommends clang libclang-rt-14-dev"; exit 1; \
	  fi; \
	fi

$(BUILD_FUZZ)/CMakeCache.txt: | deps-fuzz
	CC=clang CXX=clang++ cmake $(CMAKE_GEN) -S . -B $(BUILD_FUZZ) -DMCPLAY_FUZZ=ON -DMCPLAY_UNITY=OFF -DCMAKE_BUILD_TYPE=Debug \
	  -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g"

fuzz-build: deps-fuzz $(BUILD_FUZZ)/CMakeCache.txt
	cmake --build $(BUILD_FUZZ) -j $(JOBS) --target $(addprefix fuzz_,$(FUZZ_TARGETS))

fuzz: fuzz-build
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(BUILD_FUZZ)/corpus/$$t $(BUILD_FUZZ)/findings/$$t $(BUILD_FUZZ)/logs; \
	  echo "fuzz: $$t for $(FUZZ_SECONDS) s (log $(BUILD_FUZZ)/logs/$$t.log)"; \
	  $(BUILD_FUZZ)/fuzz_$$t $(FUZZ_FLAGS) -max_total_time=$(FUZZ_SECONDS) -max_len=$(call fuzz_max_len,$$t) \
	    -dict=fuzz/$$t.dict -artifact_prefix=$(BUILD_FUZZ)/findings/$$t/ \
	    $(BUILD_FUZZ)/corpus/$$t $(call fuzz_seeds,$$t) >$(BUILD_FUZZ)/logs/$$t.log 2>&1; \
	  echo "fuzz: $$t exit $$?: $$(grep -E '^#[0-9]+' $(BUILD_FUZZ)/logs/$$t.log | tail -1)"; \
	  ls $(BUILD_FUZZ)/findings/$$t/ 2>/dev/null | sed "s|^|fuzz: $$t finding: |"; \
	done

# Every seed once (no mutation), plus fuzz/findings/ (what earlier runs found, now fixed):
# a few seconds; any crash fails.
fuzz-smoke: fuzz-build
	@for t in $(FUZZ_TARGETS); do \
	  mkdir -p $(BUILD_FUZZ)/smoke/$$t; \
	  $(BUILD_FUZZ)/fuzz_$$t -runs=0 -timeout=10 -rss_limit_mb=2048 -max_len=$(call fuzz_max_len,$$t) \
	    -artifact_prefix=$(BUILD_FUZZ)/smoke/$$t/ $(call fuzz_seeds,$$t) \
	    $$(ls -d fuzz/findings/$$t 2>/dev/null) >$(BUILD_FUZZ)/smoke/$$t.log 2>&1 \
	    || { tail -40 $(BUILD_FUZZ)/smoke/$$t.log; echo "fuzz-smoke: $$t FAILED"; exit 1; }; \
	  echo "fuzz-smoke: $$t $$(grep -Eo '^Done [0-9]+ runs in [0-9]+ second' $(BUILD_FUZZ)/smoke/$$t.log)s"; \
	done

clean:
	rm -rf $(BUILD) $(BUILD_WASM) $(BUILD_ASAN) $(BUILD_FUZZ)
include bench/python.mk
include examples/notebook.mk
