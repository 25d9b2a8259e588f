# keyplace — top-level entry points. `make demo` and `make test` work on a fresh Debian 12 machine.
BUILD_DIR ?= build
BUILD_TYPE ?= Release
JOBS ?= $(shell nproc)
KEYPLACE := $(BUILD_DIR)/keyplace
DEMO_LOG := data/fr079-corrected.log.gz
DEMO_OUT := $(BUILD_DIR)/demo
REPORT_DIR ?= $(BUILD_DIR)/report
KEYPLACE_SHARED ?= ../shared
SANITIZE_DIR ?= build-sanitize
# make fuzz (docs/RELIABILITY.md, Fuzzing): the libFuzzer build and how long each harness runs.
FUZZ_DIR ?= build-fuzz
# make tidy: clang-tidy's own configuration (compile commands of single files).
TIDY_DIR ?= build-tidy
FUZZ_SECONDS ?= 60
FUZZ_SEED ?= 1
# The sanitizer run (docs/RELIABILITY.md, Sanitizers): the first report ends the test program
# with its stack. allocator_may_return_null: an impossible allocation throws std::bad_alloc as in
# the ordinary build (tests check the messages) instead of ending the process. Leaks of system
# libraries only are suppressed (tests/sanitizers/lsan.supp).
SANITIZE_ENV := ASAN_OPTIONS=halt_on_error=1:detect_leaks=1:allocator_may_return_null=1:check_initialization_order=1 \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
  LSAN_OPTIONS=suppressions=$(CURDIR)/tests/sanitizers/lsan.supp:print_suppressions=0
# Not run under the sanitizers, for time only (docs/RELIABILITY.md, Sanitizers): comparisons of
# one answer against another way of computing it (oracles, thread counts, thresholds, the place
# database, all-scan loop queries, keypoints given or extracted, loop queries with and without
# the submaps nearby, tracking queries against words and exact; 28-310 s each sanitized) and the
# whole-log bag map. The library code they run runs sanitized in the smaller tests of the same
# classes.
SANITIZE_SKIP_TESTS := GlobalLocalizer.StreamingGivesTheBatchAnswerOnEverySecondQueryOfTheBundledLog \
  DescriptorIndex.SameAnswerAsExhaustiveOnEverySecondQueryOfTheBundledLog \
  BagMap.Fr079BagGivesTheMapOfTheLogRebuiltFromIt \
  OnlineSlam.LoopQueriesUseTheKeypointsOfAllScans \
  OnlineSlam.AllScanLoopQueriesFindTheLoopsStableOnesMissInANoisyWorld \
  ParallelRecognition.SameAnswerAtOneTwoAndFourThreadsOnTheBundledLog \
  RecognitionThresholds.EachAnswerIsThatOfARecognizerWithThoseThresholds \
  PlaceDatabase.AddAndRemoveGiveTheAnswersOfARecognizerBuiltAtOnceOnTheBundledLog \
  ParallelQueries.RecordsAndSummaryAreTheSameAtOneAndTwoThreads \
  SlamEvaluation.KeypointsExtractedBesideSlamGiveTheSameRun \
  OnlineSlam.LoopQueriesAlsoPairTheSubmapsTheEstimatePutsNearby \
  GlobalLocalizer.WithRetrievalAutoATrackingQueryIsAnsweredByTheWordsASearchingOneByAll
empty :=
space := $(empty) $(empty)
SANITIZE_SKIP := ^($(subst $(space),|,$(strip $(SANITIZE_SKIP_TESTS))))$$

.PHONY: all deps deps-demo configure configure-demo build build-demo demo test test-fast test-slow build-sanitize \
  test-sanitize fuzz bench report format format-check tidy-configure tidy tidy-ci install \
  clean

all: build

deps:
	@bash scripts/install-deps.sh

# Only the packages the demo builds with: a fresh machine's `make demo` does not wait for the test
# tools (GoogleTest, clang, Chromium, roscore, ...).
deps-demo:
	@bash scripts/install-deps.sh --demo

CONFIGURE := cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

# Tests and benchmarks are part of the build: a missing package fails here, not by skipping them.
configure: deps
	@$(CONFIGURE) -DKEYPLACE_BUILD_TESTS=ON -DKEYPLACE_BUILD_BENCHMARKS=ON >/dev/null

build: configure
	@cmake --build $(BUILD_DIR) -j $(JOBS)

# The demo's configuration keeps the tests and benchmarks where their packages are there (after a
# `make test`) and leaves them out on a machine that has only the demo's; the Python module and
# the ROS nodes are left out by CMake itself when their packages are missing.
TEST_PACKAGES_THERE = $(shell bash scripts/install-deps.sh --check >/dev/null 2>&1 && echo ON || echo OFF)
configure-demo: deps-demo
	@$(CONFIGURE) -DKEYPLACE_BUILD_TESTS=$(TEST_PACKAGES_THERE) -DKEYPLACE_BUILD_BENCHMARKS=$(TEST_PACKAGES_THERE) >/dev/null

# What the demo runs and nothing else: the library, the keyplace command and the streaming example
# (no tests, fuzz replays, benchmarks or Python module; `make test` builds those).
build-demo: configure-demo
	@cmake --build $(BUILD_DIR) -j $(JOBS) --target keyplace_cli localize_stream

# The main job on the bundled data set, printing its results.
demo: build-demo
	@bash scripts/demo.sh $(KEYPLACE) $(DEMO_LOG) $(DEMO_OUT)

# Every test: the fast ones first (unit tests, fuzz replays, short scripts; a failure stops here),
# then the end-to-end scripts labelled `slow` (minutes each; tests/CMakeLists.txt).
test: build format-check test-fast test-slow

test-fast: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -LE '^slow$$'

test-slow: build
	@cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) -L '^slow$$'

# The library and its tests built with AddressSanitizer + UndefinedBehaviorSanitizer in
# $(SANITIZE_DIR) (-O1, with debug lines for the stacks), then those tests and the fuzz replays
# under them. Not built there, for CI's time: the front ends (the keyplace command, keyplace_tools,
# examples; their script tests run the library code the unit tests run) and the benchmarks
# (docs/RELIABILITY.md, Sanitizers).
build-sanitize: deps
	@cmake -S . -B $(SANITIZE_DIR) -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DKEYPLACE_SANITIZE=ON \
	  -DKEYPLACE_BUILD_BENCHMARKS=OFF -DKEYPLACE_BUILD_APPS=OFF -DKEYPLACE_BUILD_EXAMPLES=OFF \
	  $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
	@cmake --build $(SANITIZE_DIR) -j $(JOBS)

test-sanitize: build-sanitize
	@cd $(SANITIZE_DIR) && $(SANITIZE_ENV) ctest --output-on-failure -j $(JOBS) -LE '^slow$$' \
	  -E '$(SANITIZE_SKIP)'

# The libFuzzer harnesses of tests/fuzz, built with clang, ASan and UBSan in $(FUZZ_DIR) (the
# library and the harnesses only), each run for FUZZ_SECONDS with seed FUZZ_SEED on a scratch
# copy of its seed corpus; inputs of findings are kept in $(FUZZ_DIR)/findings/.
fuzz: deps
	@cmake -S . -B $(FUZZ_DIR) -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1 -DNDEBUG" -DKEYPLACE_FUZZ=ON \
	  -DKEYPLACE_BUILD_TESTS=OFF -DKEYPLACE_BUILD_APPS=OFF -DKEYPLACE_BUILD_BENCHMARKS=OFF \
	  -DKEYPLACE_BUILD_EXAMPLES=OFF \
	  $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
	@cmake --build $(FUZZ_DIR) -j $(JOBS) --target fuzzers
	@bash tests/fuzz/run_fuzzers.sh $(FUZZ_DIR) $(FUZZ_SECONDS) $(FUZZ_SEED)

# Every bench/*_bench program (docs/BENCHMARKS.md), medians of 3 repetitions.
bench: build
	@set -e; for program in $(BUILD_DIR)/bench/*_bench; do \
	  echo "== $$program"; \
	  $$program --benchmark_repetitions=3 --benchmark_report_aggregates_only=true; \
	done

# Every figure and table of the paper for all six data sets, ours beside the paper's, in
# $(REPORT_DIR)/index.html (docs/REPORT.md: what it runs and how long it takes). Resumable.
report: build
	@$(KEYPLACE) report --out $(REPORT_DIR) --data $(KEYPLACE_SHARED)/data --threads $(JOBS)

format:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format -i

format-check:
	@git ls-files '*.cpp' '*.hpp' | xargs clang-format --dry-run --Werror
	@echo "format-check: clang-format clean"

# clang-tidy's compile commands: a configuration of its own in $(TIDY_DIR), one command per file
# (not the batches of KEYPLACE_UNITY_BUILD, which would also hide a missing include), of which
# only the generated headers are built.
tidy-configure: deps
	@cmake -S . -B $(TIDY_DIR) -DCMAKE_BUILD_TYPE=$(BUILD_TYPE) -DKEYPLACE_UNITY_BUILD=OFF \
	  -DKEYPLACE_BUILD_TESTS=OFF -DKEYPLACE_BUILD_BENCHMARKS=OFF -DKEYPLACE_BUILD_PYTHON=OFF \
	  -DKEYPLACE_BUILD_ROS=OFF >/dev/null
	@cmake --build $(TIDY_DIR) --target keyplace_generated_headers >/dev/null

tidy: tidy-configure
	@git ls-files 'src/*.cpp' 'apps/*.cpp' 'tools/*.cpp' 'examples/*.cpp' | xargs -P $(JOBS) -n 4 clang-tidy -p $(TIDY_DIR) --quiet 2>/dev/null
	@echo "tidy: clang-tidy clean"

# What CI runs: every check of .clang-tidy on the library's sources (src/, the code a robot runs
# and every reader of untrusted input), and all but the clang static analyzer (its path-sensitive
# checks take about three quarters of tidy's time) on the front ends (apps/, tools/, examples/).
tidy-ci: tidy-configure
	@git ls-files 'src/*.cpp' | xargs -P $(JOBS) -n 4 clang-tidy -p $(TIDY_DIR) --quiet 2>/dev/null
	@git ls-files 'apps/*.cpp' 'tools/*.cpp' 'examples/*.cpp' | xargs -P $(JOBS) -n 4 \
	  clang-tidy -p $(TIDY_DIR) --quiet --checks='-clang-analyzer-*' 2>/dev/null
	@echo "tidy-ci: clang-tidy clean"

install: build
	@cmake --install $(BUILD_DIR) --prefix $(or $(PREFIX),/usr/local)

clean:
	@rm -rf $(BUILD_DIR)
