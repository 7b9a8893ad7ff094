# SAFECASS — the two commands a newcomer needs: `make demo` and `make test`.
# Each does its own set-up (system packages, configure, build).

JOBS ?= $(shell nproc)
BUILD := build
CTEST_ARGS ?=

.PHONY: all deps configure build demo test bench asan tsan clean

all: build

deps:
	@./scripts/install-deps.sh

configure: deps
	@test -f $(BUILD)/build.ninja || cmake --preset dev >/dev/null

build: configure
	@cmake --build $(BUILD) -j $(JOBS)

# The case study of the paper (examples/robodoc) in simulated time; the history lands in build/demo/.
demo: build
	@mkdir -p $(BUILD)/demo
	@./$(BUILD)/bin/robodoc_demo examples/robodoc/story.json $(BUILD)/demo/robodoc-history.jsonl
	@./$(BUILD)/bin/safecass timeline $(BUILD)/demo/robodoc-history.jsonl --html $(BUILD)/demo/timeline.html
	@echo "Timeline of the run (open in a browser): $(BUILD)/demo/timeline.html"

test: build
	@ctest --test-dir $(BUILD) --output-on-failure -j $(JOBS) $(CTEST_ARGS)

# Benchmarks are built in Release in their own tree; results land in build/bench.json.
bench: deps
	@test -f $(BUILD)/release/build.ninja || cmake --preset release >/dev/null
	@cmake --build $(BUILD)/release -j $(JOBS)
	@./$(BUILD)/release/bin/safecass_bench --benchmark_repetitions=5 \
	  --benchmark_report_aggregates_only=true \
	  --benchmark_out=$(BUILD)/bench.json --benchmark_out_format=json

asan: deps
	@test -f $(BUILD)/asan/build.ninja || cmake --preset asan >/dev/null
	@cmake --build $(BUILD)/asan -j $(JOBS)
	@ctest --test-dir $(BUILD)/asan --output-on-failure -j $(JOBS) $(CTEST_ARGS)

tsan: deps
	@test -f $(BUILD)/tsan/build.ninja || cmake --preset tsan >/dev/null
	@cmake --build $(BUILD)/tsan -j $(JOBS)
	@ctest --test-dir $(BUILD)/tsan --output-on-failure -j $(JOBS) $(CTEST_ARGS)

clean:
	rm -rf $(BUILD)
