# Thin wrapper around CMake (DESIGN.md §2).
#   make demo   install dependencies, build, run `ctid demo` on the bundled data
#   make test   install dependencies, build, run every test (ctest), then the sanitizer build's tests
#               (AddressSanitizer + UBSan, Debug with -O1: assertions on, fast enough for the Monte Carlo tests)
#   make bench  build and run the benchmarks (numbers go to docs/benchmarks.md by hand)
BUILD      ?= build
ASAN_BUILD ?= build-asan
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=

.PHONY: deps build demo test test-fast test-asan bench clean

deps:
	@scripts/install-deps.sh

build: deps
	@cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

demo: build
	@$(BUILD)/ctid demo

test-fast: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g" -DCTID_SANITIZE=ON \
		-DCTID_BUILD_BENCHMARKS=OFF >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS)
	@cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS)

test: test-fast test-asan

bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b --benchmark_min_time=0.5; done

clean:
	rm -rf $(BUILD) $(ASAN_BUILD)
