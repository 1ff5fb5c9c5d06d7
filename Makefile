# Thin wrapper around CMake (docs/architecture.md, "Build").
#   make demo   install dependencies, build the library and the command-line tool only (unity build,
#               CTID_UNITY_BUILD, with RELEASE_CXX), run `ctid demo` on the bundled data
#   make test   install dependencies, build, run every test (ctest), then the sanitizer build's tests
#               (AddressSanitizer + UBSan, Debug with -O1 and line tables only (-g1: file:line in every report,
#               40 % less compile time than -g): assertions on; the long Monte Carlo tests, ctest label
#               montecarlo, and the real-data gallery, label realdata, run in the Release build only)
#               (between the two: each libFuzzer target for FUZZ_SECONDS (30 s; longer: make fuzz FUZZ_SECONDS=600)
#               under ASan + UBSan, `make fuzz`, clang)
#   make bench  build and run the benchmarks (numbers go to docs/benchmarks.md by hand)
BUILD      ?= build
ASAN_BUILD ?= build-asan
JOBS       ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_ARGS ?=
FUZZ_BUILD ?= build-fuzz
FUZZ_SECONDS ?= 30
# The Release build (make demo, build, test, bench) compiles with clang++ when there is one (scripts/install-deps.sh
# installs it for the fuzz targets): it compiles our Eigen-heavy sources in a third less time than GCC 12 at the same
# -O3 (library + command-line tool, unity batches, 2 cores, same machine and run: clang 14 116 s wall / 214 s CPU,
# GCC 12 169 s wall / 327 s CPU, peak memory per compiler 1.6 GB vs 3.3 GB).
# The sanitizer build stays with the default compiler (GCC), so both compilers build and pass the whole suite.
# The compiler of a build directory is fixed when it is first configured: `make clean` (or another BUILD) to switch.
RELEASE_CXX ?= $(shell command -v clang++ >/dev/null 2>&1 && echo clang++ || echo c++)

.PHONY: deps build demo test test-fast test-asan fuzz bench clean

deps:
	@scripts/install-deps.sh

build: deps
	@CXX=$(RELEASE_CXX) cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DCTID_UNITY_BUILD=ON $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS)

demo: deps
	@CXX=$(RELEASE_CXX) cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DCTID_UNITY_BUILD=ON $(CMAKE_ARGS) >/dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target ctid_cli
	@$(BUILD)/ctid demo

test-fast: build
	@cd $(BUILD) && ctest --output-on-failure -j $(JOBS)

test-asan: deps
	@cmake -S . -B $(ASAN_BUILD) -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g1" -DCTID_SANITIZE=ON \
		-DCTID_BUILD_BENCHMARKS=OFF >/dev/null
	@cmake --build $(ASAN_BUILD) -j $(JOBS)
	@cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS) -LE 'montecarlo|realdata'

fuzz: deps
	@CXX=clang++ cmake -S . -B $(FUZZ_BUILD) -DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -gline-tables-only" -DCTID_BUILD_FUZZ=ON \
		-DCTID_BUILD_TESTS=OFF -DCTID_BUILD_APPS=OFF -DCTID_BUILD_BENCHMARKS=OFF -DCTID_BUILD_PYTHON=OFF >/dev/null
	@cmake --build $(FUZZ_BUILD) -j $(JOBS)
	@mkdir -p $(FUZZ_BUILD)/fuzz-artifacts
	@for t in expression csv json mat; do \
		rm -rf $(FUZZ_BUILD)/corpus-$$t && cp -r tests/fuzz/corpus/$$t $(FUZZ_BUILD)/corpus-$$t && \
		$(FUZZ_BUILD)/tests/fuzz/$${t}_fuzz -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 \
			-artifact_prefix=$(FUZZ_BUILD)/fuzz-artifacts/$$t- -print_final_stats=1 $(FUZZ_BUILD)/corpus-$$t \
			>$(FUZZ_BUILD)/fuzz-$$t.log 2>&1 || { tail -40 $(FUZZ_BUILD)/fuzz-$$t.log; exit 1; }; \
		echo "fuzz $$t: no finding in $(FUZZ_SECONDS) s ($$(grep -o 'stat::number_of_executed_units: *[0-9]*' $(FUZZ_BUILD)/fuzz-$$t.log | grep -o '[0-9]*$$' || true) inputs)"; \
	done
	@echo "fuzz: 4 passed, 0 failed"

test: test-fast fuzz test-asan

bench: build
	@for b in $(BUILD)/bench/bench_*; do echo "== $$b"; $$b --benchmark_min_time=0.5; done

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) $(FUZZ_BUILD)
