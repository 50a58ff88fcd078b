# fieldvision: `make demo` runs the main job, `make test` runs the tests. Both install missing
# Debian packages first (scripts/install-deps.sh) and build with CMake + Ninja in build/.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test demo bench format tidy clean studio

all: build

deps:
	@bash scripts/install-deps.sh

$(BUILD)/build.ninja:
	cmake -S . -B $(BUILD) -G Ninja -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

configure: deps $(BUILD)/build.ninja

build: configure
	cmake --build $(BUILD) -j $(JOBS)
	@if [ -f scripts/fetch-models.sh ]; then bash scripts/fetch-models.sh $(BUILD); fi
	@bash studio/build.sh

test: build
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) --timeout 600

demo: build
	bash scripts/demo.sh $(BUILD)

# The studio web app over the current folder (http://127.0.0.1:8470/; Ctrl-C stops).
studio: build
	$(BUILD)/bin/fieldvision studio

bench: build
	bash scripts/bench.sh $(BUILD)

format:
	find src bench -name '*.h' -o -name '*.cc' | xargs clang-format -i

tidy: configure
	find src -name '*.cc' ! -name '*_test.cc' | xargs clang-tidy -p $(BUILD) --quiet

clean:
	rm -rf $(BUILD)
