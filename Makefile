# fieldvision: `make demo` runs the main job, `make test` runs the tests. Both install missing
# Debian packages first (scripts/install-deps.sh) and build with CMake + Ninja in build/.
BUILD ?= build
JOBS ?= $(shell nproc)
CMAKE_FLAGS ?=

.PHONY: all deps configure build test demo bench format tidy clean studio sweep fuzz sanitize install

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

# The program, its codecs plugin, the model and the studio's front end under PREFIX (bin/,
# lib/fieldvision/, share/fieldvision/); the tree may be moved as a whole.
PREFIX ?= /usr/local
install: build
	cmake --install $(BUILD) --prefix $(PREFIX)

# The studio web app over the current folder (http://127.0.0.1:8470/; Ctrl-C stops).
studio: build
	$(BUILD)/bin/fieldvision studio

bench: build
	bash scripts/bench.sh $(BUILD)

format:
	find src bench -name '*.h' -o -name '*.cc' | xargs clang-format -i

tidy: configure
	find src -name '*.cc' ! -name '*_test.cc' | xargs clang-tidy -p $(BUILD) --quiet

# Issue 18's checks. `make sweep`: every bad-input case of scripts/sweep_bad_inputs.sh (CTest runs
# its --quick subset). `make fuzz`: the libFuzzer harnesses (clang, ASan + UBSan) FUZZ_SECONDS each,
# two at a time. `make sanitize`: the unit tests built with clang's ASan + UBSan (the same build as
# the fuzzers, with the NanoDet model of scripts/fetch-models.sh in it) and run with
# scripts/sanitize.supp naming the third-party leaks.
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 600
SAN_ENV = ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:fast_unwind_on_malloc=0 \
	LSAN_OPTIONS=suppressions=$(CURDIR)/scripts/sanitize.supp:print_suppressions=0 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

sweep: build
	bash scripts/sweep_bad_inputs.sh $(BUILD)/bin/fieldvision $(BUILD)/sweep

$(FUZZ_BUILD)/build.ninja:
	CC=clang CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -G Ninja -DFV_FUZZ=ON -DFV_BUILD_BENCH=OFF

fuzz: deps $(FUZZ_BUILD)/build.ninja
	cmake --build $(FUZZ_BUILD) -j $(JOBS) --target fuzzers
	bash fuzz/run.sh $(FUZZ_BUILD) $(FUZZ_SECONDS) 2

sanitize: deps $(FUZZ_BUILD)/build.ninja
	cmake --build $(FUZZ_BUILD) -j $(JOBS)
	bash scripts/fetch-models.sh $(FUZZ_BUILD)
	cd $(FUZZ_BUILD) && $(SAN_ENV) ctest --output-on-failure -j $(JOBS) --timeout 1800 -E studio_browser

clean:
	rm -rf $(BUILD)
