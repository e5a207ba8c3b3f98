# mcplay: the two commands a fresh machine needs are `make run` and `make test`.
# Both install missing Debian packages first (`make deps`).

SHELL := /bin/bash
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
BUILD ?= build
BUILD_WASM ?= build-wasm
SCENE ?= scenes/exp_1d.json
ARGS ?=
PORT ?= 8000
SITE := $(BUILD)/site

# Node 20's fetch() cannot load the .wasm beside a non-ES6 Emscripten program from a file path.
NODE_RUN := node --no-experimental-fetch

# emcc's JavaScript optimiser needs Debian's acorn when node is not Debian's own.
export NODE_PATH := /usr/share/nodejs

APT_PACKAGES := cmake g++ make googletest libgtest-dev emscripten libglm-dev libstb-dev \
	libtinygltf-dev nlohmann-json3-dev chromium
# One file or command per package that tells whether it is installed.
DEP_PROBES := /usr/bin/cmake /usr/bin/g++ /usr/src/googletest/CMakeLists.txt \
	/usr/include/gtest/gtest.h /usr/bin/em++ /usr/include/glm/glm.hpp /usr/include/stb/stb_image_write.h \
	/usr/include/tiny_gltf.h /usr/include/nlohmann/json.hpp /usr/bin/chromium

.PHONY: all deps deps-web build build-wasm site test test-native test-wasm test-compare test-web-core \
	test-e2e run cli bench format clean help

all: build

help:
	@echo "make run    build everything and serve the playground on http://localhost:$(PORT)/"
	@echo "make cli    build the native CLI and run it on $(SCENE)"
	@echo "make test   install what is missing, build native + wasm, run every test suite"
	@echo "make bench  samples per second natively and in wasm under Node, and their ratio"
	@echo "make format clang-format every C++ source"

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

web/node_modules/.package-lock.json: web/package.json web/package-lock.json
	cd web && npm ci --no-audit --no-fund
	@touch $@

$(BUILD)/CMakeCache.txt:
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release

$(BUILD_WASM)/CMakeCache.txt:
	emcmake cmake -S . -B $(BUILD_WASM) -DCMAKE_BUILD_TYPE=Release

build: deps $(BUILD)/CMakeCache.txt
	cmake --build $(BUILD) -j $(JOBS)

build-wasm: deps $(BUILD_WASM)/CMakeCache.txt
	cmake --build $(BUILD_WASM) -j $(JOBS)

test-native: build
	ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS)

test-wasm: build-wasm
	ctest --test-dir $(BUILD_WASM) --output-on-failure -j $(JOBS)

# The same study through the native CLI and the wasm CLI under Node must agree.
test-compare: build build-wasm
	bash tests/compare_native_wasm.sh $(BUILD)/mcplay "$(NODE_RUN) $(BUILD_WASM)/mcplay.js"

# web/core.js (the only caller of the browser wasm module build-wasm/mcplay_web.mjs) under
# Node's test runner, compared with the native CLI.
test-web-core: build build-wasm deps-web
	MCPLAY_WASM_DIR=$(BUILD_WASM) MCPLAY_NATIVE=$(BUILD)/mcplay node --test web/test/

# The playground: page, wasm module, uPlot and the scenes with their manifest.
site: build-wasm deps-web
	node web/tools/build-site.mjs $(SITE) $(BUILD_WASM)

# The page in headless Chromium, checked against the native CLI; screenshots in build/e2e.
test-e2e: build site
	MCPLAY_SITE=$(SITE) MCPLAY_NATIVE=$(BUILD)/mcplay MCPLAY_SHOTS=$(BUILD)/e2e node --test web/e2e/playground.e2e.mjs

test: test-native test-wasm test-compare test-web-core test-e2e
	@echo "make test: all suites passed"

run: build site
	PORT=$(PORT) node web/tools/serve.mjs $(SITE)

cli: build
	./$(BUILD)/mcplay run $(SCENE) $(ARGS)

bench: build build-wasm site
	bash bench/run_bench.sh $(BUILD)/mcplay_bench "$(NODE_RUN) --no-liftoff $(BUILD_WASM)/mcplay_bench.js"
	node web/e2e/first_plot.bench.mjs $(SITE) exp_1d 5

format:
	clang-format -i $$(git ls-files '*.cpp' '*.h')

clean:
	rm -rf $(BUILD) $(BUILD_WASM)
