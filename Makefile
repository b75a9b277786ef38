# libpolyc - see README.md. `make` builds the library and the tool,
# `make test` runs every test suite, `make bench DATA=../shared/data` measures.
CC      ?= cc
BUILD   ?= build
OPT     ?= -O2 -g
WARN    = -std=c99 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wdouble-promotion \
          -Wstrict-prototypes -Wmissing-prototypes -Wvla
CFLAGS  ?=
ALL_CFLAGS = $(WARN) $(OPT) $(CFLAGS) -Iinclude -fPIC -fvisibility=hidden -DPOLYC_BUILD_SHARED
LDLIBS  = -lm

LIB_SRC  = $(wildcard src/*.c)
LIB_OBJ  = $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o)
# tools/ modules shared by the CLI, the tests and the benchmark
TOOL_MOD = $(filter-out tools/polyc.c tools/bench.c,$(wildcard tools/*.c))
TOOL_OBJ = $(TOOL_MOD:tools/%.c=$(BUILD)/tobj/%.o)
TOOL_CFLAGS = $(WARN) $(OPT) $(CFLAGS) -Iinclude -Itools -D_POSIX_C_SOURCE=200809L

.PHONY: all lib test unit bench clean
all: $(BUILD)/libpolyc.a $(BUILD)/polyc

$(BUILD)/obj/%.o: src/%.c include/polyc.h $(wildcard src/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c $< -o $@
$(BUILD)/tobj/%.o: tools/%.c include/polyc.h $(wildcard tools/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(TOOL_CFLAGS) -c $< -o $@
$(BUILD)/libpolyc.a: $(LIB_OBJ)
	rm -f $@ && ar rcs $@ $^
$(BUILD)/polyc: tools/polyc.c $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(TOOL_CFLAGS) $^ -o $@ $(LDLIBS)

# Unit and end-to-end tests: one cmocka binary per tests/test_*.c
TEST_SRC = $(wildcard tests/test_*.c)
TEST_BIN = $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
$(BUILD)/tests/%: tests/%.c $(TOOL_OBJ) $(BUILD)/libpolyc.a $(wildcard tests/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(TOOL_CFLAGS) -Isrc -Itests $< $(TOOL_OBJ) $(BUILD)/libpolyc.a -o $@ -lcmocka $(LDLIBS)

unit: $(TEST_BIN) $(BUILD)/polyc
	@set -e; for t in $(TEST_BIN); do echo "== $$t"; $$t; done

test: unit

# Benchmark on the shared data (not in the repo): an optimised build in
# build-bench/, then one table. `make bench DATA=dir BENCH_ARGS='--only intel'`
DATA ?= ../shared/data
BENCH_ARGS ?=
bench:
	$(MAKE) BUILD=build-bench OPT='-O3 -march=native -DNDEBUG' build-bench/bench
	build-bench/bench $(BENCH_ARGS) $(DATA)
$(BUILD)/bench: tools/bench.c $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(TOOL_CFLAGS) $^ -o $@ $(LDLIBS)

# Regenerate the bundled example (examples/office.*) with the simulator
.PHONY: examples
examples: $(BUILD)/gen_example
	$(BUILD)/gen_example examples/office.log examples/office.gt.txt
$(BUILD)/gen_example: tests/gen_example.c $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(TOOL_CFLAGS) $^ -o $@ $(LDLIBS)

clean:
	rm -rf $(BUILD) build-*
