# SAFECASS — the two commands a newcomer needs: `make demo` and `make test`.
# Each does its own set-up (system packages, configure, build).

JOBS ?= $(shell nproc)
# `make test` runs one test more than there are cores: the multi-process tests spend most of their
# time waiting on heartbeats and timeouts, and a core they leave idle is another test's
# (docs/contributing.md, "Continuous integration"). Tests that compute on several cores say so
# (ctest's PROCESSORS).
TEST_JOBS ?= $(shell echo $$(( $$(nproc) + 1 )))
BUILD := build
# Tests labelled known-defect show a defect that is documented and not fixed yet: they fail by
# design until it is, so `make test` leaves them out and `make known-defects` runs them.
CTEST_ARGS ?= -LE known-defect

.PHONY: all deps configure build demo ros-demo ros2-demo cluster-demo test stress-test known-defects fuzz-tree fuzz fuzz-coverage fuzz-keep fuzz-smoke bench bench-check bench-peers bench-scale-out bench-verify asan tsan package lint clean

all: build

deps:
	@./scripts/install-deps.sh
	@if [ ! -f web/node_modules/.package-lock.json ] || [ web/package-lock.json -nt web/node_modules/.package-lock.json ]; then \
	  npm ci --prefix web --no-audit --no-fund --loglevel=error; fi

configure: deps
	@test -f $(BUILD)/build.ninja || cmake --preset dev >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The case study of the paper (examples/robodoc) in simulated time; the history lands in build/demo/.
# It builds only what it runs (the `safecass` command, robodoc_demo and their libraries); `make
# test` builds the rest of the tree.
DEMO_TARGETS := safecass robodoc_demo
demo: configure
	@cmake --build $(BUILD) -j $(JOBS) --target $(DEMO_TARGETS)
	@mkdir -p $(BUILD)/demo
	@./$(BUILD)/bin/robodoc_demo examples/robodoc/story.json $(BUILD)/demo/robodoc-history.jsonl
	@./$(BUILD)/bin/safecass timeline $(BUILD)/demo/robodoc-history.jsonl --html $(BUILD)/demo/timeline.html
	@echo "Timeline of the run (open in a browser): $(BUILD)/demo/timeline.html"
	@echo "Model-checking robodoc's hazard reactions with SPIN (safecass verify):"
	@./$(BUILD)/bin/safecass verify examples/robodoc/robodoc.json --out $(BUILD)/demo/counterexamples
	@./$(BUILD)/bin/safecass verify examples/robodoc/robodoc.json --json >$(BUILD)/demo/verify.jsonl 2>/dev/null
	@echo "Model-checking the bus protocol of robodoc's deployment (safecass verify --bus, about a minute):"
	@./$(BUILD)/bin/safecass verify --bus examples/robodoc/robodoc.json >$(BUILD)/demo/verify-bus.txt \
	  || { cat $(BUILD)/demo/verify-bus.txt; exit 1; }
	@grep -E '^P[1-5] |proved' $(BUILD)/demo/verify-bus.txt | cut -c1-120
	@./$(BUILD)/bin/safecass trace examples/robodoc/robodoc.json --scenarios examples/robodoc/story.json \
	  examples/robodoc/injection.json examples/robodoc/warnings.json examples/robodoc/overload.json --verify $(BUILD)/demo/verify.jsonl --csv $(BUILD)/demo/trace.csv \
	  --html $(BUILD)/demo/trace.html >$(BUILD)/demo/trace.txt 2>/dev/null \
	  || { cat $(BUILD)/demo/trace.txt; echo "trace: a gap of error severity (above)"; exit 1; }
	@grep '^Coverage' $(BUILD)/demo/trace.txt
	@echo "Hazard trace report (open in a browser, prints to PDF): $(BUILD)/demo/trace.html (matrix: $(BUILD)/demo/trace.txt, CSV: $(BUILD)/demo/trace.csv)"
	@./$(BUILD)/bin/safecass analyze examples/robodoc/robodoc.json --scenarios examples/robodoc/story.json \
	  examples/robodoc/injection.json examples/robodoc/warnings.json examples/robodoc/overload.json \
	  --verify $(BUILD)/demo/verify.jsonl --mef $(BUILD)/demo/fault-trees.xml --html $(BUILD)/demo/analysis.html \
	  >$(BUILD)/demo/analysis.txt 2>/dev/null \
	  || { cat $(BUILD)/demo/analysis.txt; echo "analyze: a gap of error severity (above)"; exit 1; }
	@grep -E '^(FMEA of|Gaps:)' $(BUILD)/demo/analysis.txt
	@echo "FMEA, fault trees and safety case (safecass analyze; open in a browser, prints to PDF): $(BUILD)/demo/analysis.html (text: $(BUILD)/demo/analysis.txt, MEF: $(BUILD)/demo/fault-trees.xml)"

# ROBODOC on ROS 1 (examples/ros_robodoc): roscore, diagnostic_aggregator, the nodes, rosdiagnostic.
ros-demo: configure
	@cmake -S . -B $(BUILD) -DSAFECASS_WITH_ROS1=ON >/dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target ros_robodoc_control ros_robodoc_jr3
	@./scripts/ros-demo.sh $(BUILD)

# Every test; a test that fails is run once more alone and named in the summary as retried
# (scripts/run-tests), which ends with what ran: ctest's count and the fuzz smoke run's executions.
test: build fuzz-smoke
	@JOBS=$(TEST_JOBS) ./scripts/run-tests $(BUILD) --fuzz-log $(FUZZ)/spec_loader.log $(CTEST_ARGS)

# The tests that start processes (label `processes`), STRESS_RUNS times (default 5) beside two busy
# loops with ctest -j2 and no retry: every run must pass (scripts/stress-test).
STRESS_RUNS ?= 5
stress-test: build
	@./scripts/stress-test $(BUILD) $(STRESS_RUNS)

known-defects: build
	@ctest --test-dir $(BUILD) --output-on-failure -L known-defect

# The libFuzzer targets of tests/fuzz (clang, ASan + UBSan, line tables only, their own tree,
# unity sources as the presets' builds: docs/contributing.md, "Continuous integration"), one per
# input that crosses a boundary: the spec loader, the ROS inputs, the named reads' answers, scenarios, history
# lines, input recordings, CSV logs, ROS 1 and ROS 2 bags, the viewer's messages, the console's
# command lines and the bus's authenticated messages (docs/contributing.md, "Fuzzing").
# scripts/fuzz runs them with their seeds; `make test` runs a smoke of each.
FUZZ := $(BUILD)/fuzz
FUZZ_TARGETS := spec_loader ros_input read_answer scenario history input_log csv rosbag1 rosbag2 viewer_message \
  console_command wire_events wire_messages
FUZZ_SECONDS ?= 60
fuzz-tree: deps
	@test -f $(FUZZ)/build.ninja || cmake -S . -B $(FUZZ) -G Ninja -DCMAKE_CXX_COMPILER=clang++ \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
	  -DCMAKE_UNITY_BUILD=ON -DSAFECASS_BUILD_FUZZ=ON -DSAFECASS_BUILD_TESTS=OFF \
	  -DSAFECASS_BUILD_TOOLS=ON -DSAFECASS_BUILD_EXAMPLES=OFF -DSAFECASS_BUILD_BENCHMARKS=OFF >/dev/null

# Every target for FUZZ_SECONDS (default 60) each: executions, edges and findings per target.
fuzz: fuzz-tree
	@cmake --build $(FUZZ) -j $(JOBS) --target $(addsuffix _fuzz,$(FUZZ_TARGETS)) >/dev/null
	@./scripts/fuzz $(FUZZ) $(FUZZ_SECONDS) $(FUZZ_TARGETS)

# The source coverage of each parser that its target's kept corpus reaches (llvm-cov, its own tree).
fuzz-coverage: fuzz-tree
	@./scripts/fuzz-coverage $(FUZZ) $(BUILD)/fuzz-coverage $(FUZZ_TARGETS)

# A campaign's corpora, each merged to its smallest subset of the same coverage, into
# tests/fuzz/corpus/TARGET.tar.xz: every later run starts from them.
fuzz-keep: fuzz-tree
	@./scripts/fuzz-keep $(FUZZ) $(FUZZ_TARGETS)

# The short runs of `make test`: every target for 5 s, JOBS of them at once.
fuzz-smoke: fuzz-tree
	@cmake --build $(FUZZ) -j $(JOBS) --target $(addsuffix _fuzz,$(FUZZ_TARGETS)) >/dev/null
	@FUZZ_PARALLEL=$(JOBS) ./scripts/fuzz $(FUZZ) 5 $(FUZZ_TARGETS)

# Benchmarks are built in Release in their own tree; results land in build/bench.json (every
# repetition and the aggregates), run on one core (the last) when taskset is there.
PIN := $(shell command -v taskset >/dev/null 2>&1 && echo "taskset -c $$(($$(nproc) - 1))")
bench: deps
	@test -f $(BUILD)/release/build.ninja || cmake --preset release >/dev/null
	@cmake --build $(BUILD)/release -j $(JOBS)
	@$(PIN) ./$(BUILD)/release/bin/safecass_bench --benchmark_repetitions=5 \
	  --benchmark_display_aggregates_only=true \
	  --benchmark_out=$(BUILD)/bench.json --benchmark_out_format=json
	@./scripts/bench-middleware $(BUILD)/release/bin/bench_middleware $(BUILD)/bench-middleware.json
	@if [ -d $(BUILD)/release/python/safecass ]; then \
	  $(PIN) /usr/bin/python3 benchmarks/bench_python.py $(BUILD)/release/python $(BUILD)/bench-python.json; fi

# The hot paths against the committed baseline (benchmarks/baseline.json): each ratio, and a
# failure beyond its tolerance (docs/benchmarks.md, "bench-check"). Reads build/bench.json; not in CI.
bench-check:
	@./scripts/bench-check $(BUILD)/bench.json benchmarks/baseline.json

# ROBODOC on ROS 2 over DDS (examples/dds_robodoc): safecass_dds_node, a simulated JR3 driver and a
# /diagnostics reader, all plain Cyclone DDS participants.
ros2-demo: configure
	@cmake -S . -B $(BUILD) -DSAFECASS_WITH_DDS=ON >/dev/null
	@cmake --build $(BUILD) -j $(JOBS) --target safecass_dds_node dds_robodoc_jr3 dds_diagnostics_echo
	@./scripts/ros2-demo.sh $(BUILD)

# ROBODOC on three hosts (network namespaces, as root): robot, ui, IceStorm and the supervisor, mutual
# TLS; the force crosses its limit, then the robot's host is cut off and comes back. CLUSTER_ARGS=--watch
# leaves it running with the viewer on host c.
cluster-demo: build
	@./scripts/cluster-demo.sh $(BUILD) $(CLUSTER_ARGS)

# SAFECASS side by side with its peers (raw IceStorm, roscpp, ROS diagnostics, Boost.MSM and
# Boost.Statechart) in one run: its own Release tree with ROS 1 (build/peers), results in
# build/bench-peers.json and a table (docs/benchmarks.md). BENCH_PEERS_ARGS=--quick: a short run
# (about a minute) that checks the harness and that the JSON has every figure.
PEERS := $(BUILD)/peers
PEER_TARGETS := bench_peers_core peer_detection peer_icestorm_raw peer_supervisor_load peer_ros_visibility \
  peer_ros_watch peer_dds_visibility bench_middleware safecass_bench
CCACHE_LAUNCHER := $(if $(shell command -v ccache),-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
bench-peers: deps
	@./scripts/install-deps.sh --bench-peers
	@test -f $(PEERS)/build.ninja || cmake --preset peers $(CCACHE_LAUNCHER) >/dev/null
	@cmake --build $(PEERS) -j $(JOBS) --target $(PEER_TARGETS)
	@./scripts/bench-peers $(PEERS) $(BUILD)/bench-peers.json $(BENCH_PEERS_ARGS)

# How far one system scales: 1, 10, 25 and 50 coordinator processes of 20 components at 10 state
# changes a second each, through IceStorm replicated under IceGrid (docs/scaling.md); written to
# build/bench-scale-out.json. BENCH_SCALE_OUT_ARGS=--quick: 5 s per run.
bench-scale-out: build
	@./scripts/bench-scale-out $(BUILD) $(BUILD)/bench-scale-out.json $(BENCH_SCALE_OUT_ARGS)

# `safecass verify` on robodoc and on a generated 50-component tree with hazards, and
# `safecass verify --bus` on robodoc's deployment: wall-clock time (SPIN and the C compiler
# included) and memory, written to build/bench-verify.json.
bench-verify: build
	@./$(BUILD)/bin/bench_verify $(BUILD)/bench-verify.json

# The sanitizer runs. Without SANITIZER_SUBSET: the whole tree is built and every test runs
# (CTEST_ARGS). With SANITIZER_SUBSET=ci (what .ci/run uses): only the test folders named below
# are built (their `<folder>/all` targets: the test programs and the libraries they link) and run
# by one ctest; docs/contributing.md, "Continuous integration", says which and why. No test of
# these folders starts the `safecass` command; a folder whose tests do adds it to the targets.
ASAN_CI_DIRS := tests/unit/core tests/unit/filters tests/unit/json tests/unit/spec tests/unit/record tests/unit/replay \
  tests/unit/dds
TSAN_CI_DIRS := tests/unit/core
# The subsets register each test program as one ctest test (SAFECASS_TESTS_PER_PROGRAM, set by the
# sanitizer presets), so the cases left out are named to GoogleTest (GTEST_FILTER, which every
# program reads) rather than to ctest.
# Under UBSan's vptr check a process with no free descriptor reports its own valid objects as
# invalid (the check probes memory through a pipe), so the descriptor-exhaustion test is not run there.
# The random model's seeds 6-20 are left to `make test`: under ASan each seed takes about 2.7 s of
# one core (54 s for the twenty), and seeds 1-5 run its paths under ASan.
# The Ids tests compile a file and read the compiler's verdict: nothing of theirs runs under a
# sanitizer, and `make test` runs them.
ASAN_CI_ARGS := -LE known-defect -E '^(ViewerBacksOffWhenOutOfFileDescriptors|Ids\..*)$$'
space := $(subst ,, )
ASAN_CI_SEEDS := $(foreach n,6 7 8 9 1? 20,Seeds/RandomModelTest.*/Seed$(n))
# The filter bank's differential test runs 400 random systems under ASan (2,000 in `make test`):
# at -O0 with ASan the 2,000 took 66 s, most of the subset's test time, for no path the 400 miss.
ASAN_CI_ENV := SAFECASS_BANK_SEEDS=400 GTEST_FILTER='-$(subst $(space),:,$(ASAN_CI_SEEDS))'
# The random model runs one thread, where ThreadSanitizer has nothing to find (it reports races
# between threads); it is most of the TSan subset's time, and runs in `make test` and under ASan.
TSAN_CI_ARGS := -LE known-defect -E '^(middleware\.tls\..*|test_core_random|Ids\..*)$$'
TSAN_ENV = TSAN_OPTIONS="suppressions=$(CURDIR)/tests/tsan.supp $${TSAN_OPTIONS:-}"
# $(call sanitize,PRESET,CI_DIRS,CI_ARGS,ENV): with SANITIZER_SUBSET=ci the CI_DIRS' targets are
# built and their tests run by one ctest (a test file of the folders, ci-subset/, so that the
# folders' programs run side by side); without, the whole tree.
define sanitize
	@test -f $(BUILD)/$(1)/build.ninja || cmake --preset $(1) >/dev/null
	@if [ "$(SANITIZER_SUBSET)" = ci ]; then \
	  cmake --build $(BUILD)/$(1) -j $(JOBS) --target $(addsuffix /all,$(2)) || exit 1; \
	  mkdir -p $(BUILD)/$(1)/ci-subset && \
	  for d in $(2); do echo "subdirs(\"$(abspath $(BUILD)/$(1)/$$d)\")"; done >$(BUILD)/$(1)/ci-subset/CTestTestfile.cmake && \
	  echo "== $(1): $(2)" && \
	  $(4) ctest --test-dir $(BUILD)/$(1)/ci-subset --output-on-failure -j $(JOBS) $(3); \
	elif [ -n "$(SANITIZER_SUBSET)" ]; then echo "SANITIZER_SUBSET=$(SANITIZER_SUBSET): unknown subset (ci)"; exit 2; \
	else \
	  cmake --build $(BUILD)/$(1) -j $(JOBS) && $(4) ctest --test-dir $(BUILD)/$(1) --output-on-failure -j $(JOBS) $(CTEST_ARGS); \
	fi
endef

asan: deps
	$(call sanitize,asan,$(ASAN_CI_DIRS),$(ASAN_CI_ARGS),$(if $(filter ci,$(SANITIZER_SUBSET)),$(ASAN_CI_ENV)))

tsan: deps
	$(call sanitize,tsan,$(TSAN_CI_DIRS),$(TSAN_CI_ARGS),$(TSAN_ENV))

# Debian packages (CPack): libsafecass-dev (libraries, headers, CMake config, pkg-config) and
# safecass (the command and its man pages), in build/packages/ (docs/contributing.md, "Packages").
package: build
	@cd $(BUILD) && cpack
	@ls $(BUILD)/packages/*.deb

# clang-format (check only), the [[nodiscard]], names, function-length and namespace checks, and
# clang-tidy over the sources changed since the tidied baseline of .ci/tidy-baseline (scripts/lint).
# LINT_CHECK=format, =nodiscard, =names, =functions, =namespaces, =surface or =tidy runs one of them; LINT_CHECK=tidy-all runs clang-tidy over every source (docs/contributing.md, "Lint").
# (Not LINT: GNU make defines LINT = lint itself.)
LINT_CHECK ?= all
lint: build
	@./scripts/lint --$(LINT_CHECK) $(BUILD)

clean:
	rm -rf $(BUILD)
