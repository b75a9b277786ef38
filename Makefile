# libpolyc - see README.md. `make` builds the library and the tool,
# `make test` runs every test suite, `make bench DATA=../shared/data` measures,
# `make sweep` maps and scores simulated scenes of every kind over seeds 1-6.
CC      ?= cc
BUILD   ?= build
OPT     ?= -O2 -g
WARN    = -std=c99 -Wall -Wextra -Wpedantic -Wshadow -Wconversion -Wdouble-promotion \
          -Wstrict-prototypes -Wmissing-prototypes -Wvla
CFLAGS  ?=
ALL_CFLAGS = $(WARN) $(OPT) $(CFLAGS) -Iinclude -fPIC -fvisibility=hidden -fno-math-errno -DPOLYC_BUILD_SHARED
LDLIBS  = -lm

LIB_SRC  = $(wildcard src/*.c src/*/*.c)
LIB_OBJ  = $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o)
# tools/: the shipped tool (POLYC_SRC: main, command line, input, run,
# the online replay, messages) and its modules (log reader, map files, SVG/JSON/TXT output,
# the library's block), which the tests, the bench and the binding use too.
# tools/eval/: the evaluation harness (bench, sweep, simulator, ground-truth
# and topology scores), which the tests and the benchmark use and the tool
# does not.
POLYC_SRC = tools/polyc.c tools/cli.c tools/options.c tools/load.c tools/run.c tools/online.c
POLYC_OBJ = $(POLYC_SRC:tools/%.c=$(BUILD)/tobj/%.o)
TOOL_MOD = $(filter-out $(POLYC_SRC),$(wildcard tools/*.c))
TOOL_OBJ = $(TOOL_MOD:tools/%.c=$(BUILD)/tobj/%.o)
BENCH_SRC = $(wildcard tools/eval/bench*.c)
EVAL_MOD = $(filter-out $(BENCH_SRC) tools/eval/sweep.c tools/eval/mapscore.c,$(wildcard tools/eval/*.c))
EVAL_OBJ = $(EVAL_MOD:tools/eval/%.c=$(BUILD)/eobj/%.o)
TOOL_CFLAGS = $(WARN) $(OPT) $(CFLAGS) -Iinclude -Itools -D_POSIX_C_SOURCE=200809L
EVAL_CFLAGS = $(TOOL_CFLAGS) -Itools/eval

.PHONY: all lib test unit bench sweep clean install cross deps check test-cxx test-install test-python test-embedded
.PHONY: test-cli test-fuzz-replay test-asan test-valgrind fuzz fuzz-merge
all: $(BUILD)/libpolyc.a $(BUILD)/libpolyc.so $(BUILD)/polyc

# comparisons that may not trap: the only way gcc vectorises this loop (the
# values are the same)
$(BUILD)/obj/search/trial_costs.o: ALL_CFLAGS += -fno-trapping-math
$(BUILD)/obj/%.o: src/%.c include/polyc.h $(wildcard src/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(ALL_CFLAGS) -c $< -o $@
$(BUILD)/tobj/%.o: tools/%.c include/polyc.h $(wildcard tools/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(TOOL_CFLAGS) -c $< -o $@
# (src/*.h too: fairbic.c reaches into the library's internals)
$(BUILD)/eobj/%.o: tools/eval/%.c include/polyc.h $(wildcard tools/*.h tools/eval/*.h src/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(EVAL_CFLAGS) -c $< -o $@
$(BUILD)/libpolyc.a: $(LIB_OBJ)
	rm -f $@ && ar rcs $@ $^
$(BUILD)/polyc: $(POLYC_OBJ) $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(TOOL_CFLAGS) $^ -o $@ $(LDLIBS)

# Shared library: exports only the POLYC_API functions (-fvisibility=hidden)
VERSION := $(shell awk '/define POLYC_VERSION_(MAJOR|MINOR|PATCH) /{v = v s $$3; s = "."} END {print v}' include/polyc.h)
SONAME   = libpolyc.so.$(firstword $(subst ., ,$(VERSION)))
$(BUILD)/libpolyc.so: $(LIB_OBJ)
	$(CC) -shared -Wl,-soname,$(SONAME) $(LDFLAGS) $^ -o $@ $(LDLIBS)

# `make install PREFIX=/usr/local DESTDIR=`: header, libpolyc.a, libpolyc.so.X.Y.Z
# with its soname and dev links, the tool, and polyc.pc for pkg-config
PREFIX ?= /usr/local
LIBDIR ?= $(PREFIX)/lib
install: all
	install -d $(DESTDIR)$(PREFIX)/include $(DESTDIR)$(PREFIX)/bin $(DESTDIR)$(LIBDIR)/pkgconfig
	install -m 644 include/polyc.h $(DESTDIR)$(PREFIX)/include/
	install -m 644 $(BUILD)/libpolyc.a $(DESTDIR)$(LIBDIR)/
	install -m 755 $(BUILD)/libpolyc.so $(DESTDIR)$(LIBDIR)/libpolyc.so.$(VERSION)
	ln -sf libpolyc.so.$(VERSION) $(DESTDIR)$(LIBDIR)/$(SONAME)
	ln -sf $(SONAME) $(DESTDIR)$(LIBDIR)/libpolyc.so
	install -m 755 $(BUILD)/polyc $(DESTDIR)$(PREFIX)/bin/
	sed -e 's|@PREFIX@|$(PREFIX)|' -e 's|@LIBDIR@|$(LIBDIR)|' -e 's|@VERSION@|$(VERSION)|' \
	    polyc.pc.in > $(DESTDIR)$(LIBDIR)/pkgconfig/polyc.pc

# Unit and end-to-end tests: one cmocka binary per tests/test_*.c
TEST_SRC = $(wildcard tests/test_*.c)
TEST_BIN = $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
$(BUILD)/tests/%: tests/%.c $(TOOL_OBJ) $(EVAL_OBJ) $(BUILD)/libpolyc.a $(wildcard tests/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(EVAL_CFLAGS) -Isrc -Itests $< $(TOOL_OBJ) $(EVAL_OBJ) $(BUILD)/libpolyc.a -o $@ -lcmocka $(LDLIBS)

# the optimiser's suites share their harness (tests/opt_harness.c), whose
# oracles are the library's invariant checkers (src/search/checks.c): compiled in
# here when the library was built without them
OPT_CHECKS = $(if $(findstring -DPOLYC_CHECKS,$(CFLAGS)),,-DPOLYC_CHECKS src/search/checks.c)
$(BUILD)/tests/test_opt_%: tests/test_opt_%.c tests/opt_harness.c src/search/checks.c $(TOOL_OBJ) $(EVAL_OBJ) $(BUILD)/libpolyc.a $(wildcard tests/*.h src/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(EVAL_CFLAGS) -Isrc -Itests $< tests/opt_harness.c $(OPT_CHECKS) $(TOOL_OBJ) $(EVAL_OBJ) $(BUILD)/libpolyc.a -o $@ -lcmocka $(LDLIBS)

# every suite runs even when an earlier one fails; the target fails at the end
unit: $(TEST_BIN) $(BUILD)/polyc
	@fail=0; for t in $(TEST_BIN); do echo "== $$t"; $$t || fail=1; done; exit $$fail

# What a newcomer and CI run (README.md): dependencies, then every step of
# CHECK_STEPS, each into build-check/STEP.log: one line per step (the log's
# tail if it failed), and last a line `N passed, N failed` alone (CI reads it).
CHECK_STEPS = unit test-checks test-cli test-fuzz-replay test-asan test-cxx test-install \
              test-python test-embedded test-batch-alone test-opt-O3 test-opt-Os test-golden \
              test-valgrind cross target docs-figures
check: deps
	@mkdir -p build-check; pass=0; fail=0; \
	for s in $(CHECK_STEPS); do \
	  if $(MAKE) --no-print-directory $$s > build-check/$$s.log 2>&1; then \
	    pass=$$((pass + 1)); echo "ok    $$s"; \
	  else \
	    fail=$$((fail + 1)); echo "FAIL  $$s: the end of build-check/$$s.log:"; \
	    tail -n 40 build-check/$$s.log | sed 's/^/      /'; \
	  fi; \
	done; \
	echo "$$pass passed, $$fail failed"; test $$fail -eq 0

# The figures README.md and docs/ quote, against the commands that print them
# (tools/docs_figures.py: each figure, its document, its command; --list).
# docs-figures: those of the repository's own data (office.log and its grid,
# the sweep's scenes, footprint, the embedded examples, cross, target);
# sizes and counts exact, times not compared. docs-figures-data: those of the
# real logs, the simulated logs and the TurtleBot3 map in DATA, from a run of
# `make bench DATA=...` (or its saved output: BENCH_OUT=file) and build/polyc;
# times within 2 x. Each failure names the document, the quoted and the
# measured value, and the command.
.PHONY: docs-figures docs-figures-data
docs-figures: $(BUILD)/polyc
	python3 tools/docs_figures.py --make "$(MAKE)" --build $(BUILD)
docs-figures-data: $(BUILD)/polyc
	@if [ -d "$(DATA)" ]; then \
	  python3 tools/docs_figures.py --make "$(MAKE)" --build $(BUILD) --data "$(DATA)" \
	    $(if $(BENCH_OUT),--bench-out "$(BENCH_OUT)"); \
	else \
	  echo "docs-figures-data: no data folder '$(DATA)' (the real logs are not in the repository;"; \
	  echo "  build-bench/bench --help says what it holds): give DATA=path. Nothing compared."; \
	fi

# The unit suites on a library with its invariant checkers built in
# (src/search/checks.c): the optimiser asserts its store, hash and arena after
# every iteration, and its unit tests check the books from scratch.
.PHONY: test-checks
test-checks:
	$(MAKE) BUILD=build-checks CFLAGS=-DPOLYC_CHECKS unit

# The unit suites again under other optimisation settings (-O3, -Os -flto).
.PHONY: test-opt test-opt-O3 test-opt-Os
test-opt: test-opt-O3 test-opt-Os
test-opt-O3:
	$(MAKE) BUILD=build-O3 OPT='-O3 -g' unit
test-opt-Os:
	$(MAKE) BUILD=build-Os OPT='-Os -flto' unit
deps:
	sh tools/install-deps.sh


# Also: the header as C++, an installed copy used through pkg-config, the
# Python binding against build/libpolyc.so, the 128 KiB example on the host,
# the unit suites with the invariant checkers built in (test-checks), and the
# tool's bytes across optimisation levels (test-golden)
test: unit test-checks test-cli test-fuzz-replay test-asan test-cxx test-install test-python \
      test-embedded test-batch-alone test-golden
# tests/golden.sh: the tool built at -O0, -O2, -O3 and -Os -flto (in
# build-golden-*/) writes the same bytes on simulated scenes, examples/office.log
# and its grid as a ROS map
.PHONY: test-golden
test-golden: $(BUILD)/gen_example
	tests/golden.sh "$(MAKE)" $(BUILD)/gen_example
test-cxx: $(BUILD)/tests/cxx_header
	$(BUILD)/tests/cxx_header
$(BUILD)/tests/cxx_header: tests/cxx_header.cpp include/polyc.h $(BUILD)/libpolyc.a
	@mkdir -p $(dir $@)
	$(CXX) -std=c++11 -Wall -Wextra -Werror -pedantic -Iinclude $< $(BUILD)/libpolyc.a -o $@ $(LDLIBS)
test-install: all
	tests/install_test.sh "$(MAKE)" "$(BUILD)"
# The Python package's library: libpolyc with the tool's readers
# (scanlog, mapfile and its image readers, gridimage) and the binding's glue
# (polyc_io.c), as `pip install ./bindings/python` builds it
# (bindings/python/setup.py).
PY_MOD = tools/scanlog.c tools/scanlog_noreturn.c tools/mapfile.c tools/mapfile_pgm.c \
         tools/mapfile_png.c tools/mapfile_image.c tools/inflate.c \
         tools/gridimage.c tools/readfile.c tools/textesc.c bindings/python/polyc_io.c
PY_OBJ = $(PY_MOD:%.c=$(BUILD)/pyobj/%.o)
$(BUILD)/pyobj/%.o: %.c include/polyc.h $(wildcard tools/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(TOOL_CFLAGS) -fPIC -fvisibility=hidden -c $< -o $@
$(BUILD)/py/libpolyc.so: $(LIB_OBJ) $(PY_OBJ)
	@mkdir -p $(dir $@)
	$(CC) -shared $(LDFLAGS) $^ -o $@ $(LDLIBS)
# The tests run in a venv of their own ($(BUILD)/pyvenv) with numpy if pip
# can install it (its tests skip otherwise) and the build backend's wheels
# (setuptools, wheel) in $(BUILD)/pywheels for the test that pip-installs
# the package into a fresh venv without going online.
PYVENV = $(BUILD)/pyvenv
$(PYVENV)/ready:
	rm -rf $(PYVENV) && python3 -m venv $(PYVENV)
	$(PYVENV)/bin/python -m pip install -q numpy || echo "test-python: numpy could not be installed: the numpy tests skip"
	$(PYVENV)/bin/python -m pip download -q -d $(BUILD)/pywheels setuptools wheel || \
	    echo "test-python: no setuptools wheel: the pip install test goes online or skips"
	touch $@
test-python: all $(BUILD)/py/libpolyc.so $(PYVENV)/ready
	POLYC_LIB=$(abspath $(BUILD)/py/libpolyc.so) POLYC_TOOL=$(abspath $(BUILD)/polyc) \
	    POLYC_WHEELS=$(abspath $(BUILD)/pywheels) \
	    $(PYVENV)/bin/python -m unittest discover -v -s bindings/python -p 'test_*.py'
# the library as for the target (8-bit grid counters), and the embedded examples on it (one
# scan; an online map scan by scan): tests/embedded_test.sh checks their maps
EMB_OBJ = $(LIB_SRC:src/%.c=$(BUILD)/emb/%.o)
$(BUILD)/emb/%.o: src/%.c include/polyc.h $(wildcard src/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(WARN) $(OPT) $(CFLAGS) -DPOLYC_COUNTER_BITS=8 -Iinclude -c $< -o $@
EMB_EXAMPLES = embedded_scan embedded_online
$(EMB_EXAMPLES:%=$(BUILD)/%): $(BUILD)/%: examples/%.c examples/embedded_room.h $(EMB_OBJ)
	$(CC) $(WARN) $(OPT) $(CFLAGS) -Iinclude $(filter %.c %.o,$^) -o $@ $(LDLIBS)
test-embedded: $(EMB_EXAMPLES:%=$(BUILD)/%) footprint
	tests/embedded_test.sh $(EMB_EXAMPLES:%=$(BUILD)/%)
# bytes per scan, beam, vertex and grid tile (README "Footprint"): 16-, then 8-bit counters
.PHONY: footprint
footprint: $(BUILD)/footprint $(BUILD)/footprint8
	$(BUILD)/footprint 0.025 && $(BUILD)/footprint8 0.025
$(BUILD)/footprint: examples/footprint.c $(BUILD)/libpolyc.a
	$(CC) $(WARN) $(OPT) $(CFLAGS) -Iinclude $^ -o $@ $(LDLIBS)
$(BUILD)/footprint8: examples/footprint.c $(EMB_OBJ)
	$(CC) $(WARN) $(OPT) $(CFLAGS) -Iinclude $^ -o $@ $(LDLIBS)

# The online mode is a layer above the batch library (src/online/): the
# batch objects build and link without it (the one-scan example, linked
# against every object of src/online/ left out, maps its room), and no batch file
# includes an online header.
BATCH_OBJ = $(filter-out $(BUILD)/obj/online/%.o,$(LIB_OBJ))
.PHONY: test-batch-alone
test-batch-alone: $(BATCH_OBJ)
	$(CC) $(WARN) $(OPT) $(CFLAGS) -Iinclude examples/embedded_scan.c $(BATCH_OBJ) \
	    -o $(BUILD)/embedded_scan_batch $(LDLIBS)
	$(BUILD)/embedded_scan_batch | grep -q '^status ok'
	@bad=$$(grep -lE '#include "(\.\./)?online' $(filter-out src/online/%,$(wildcard src/*.c src/*.h src/*/*.c))); \
	if [ -n "$$bad" ]; then echo "batch files that include an online header: $$bad"; exit 1; fi
	@echo "test-batch-alone: the batch library links without src/online/"

# Robustness (docs/security.md). test-cli: every bad input of the tool
# (tests/cli_bad_input.sh), where it writes (tests/cli_output.sh: as root,
# also as an ordinary user), --online (tests/cli_online.sh), circles in the
# outputs (tests/cli_curves.sh) and the README's
# C example compiled as written (tests/cli_readme.sh).
# test-fuzz-replay: the committed fuzz corpus through the fuzz targets, built
# with $(CC). test-asan: unit tests, corpus replay and
# the quick bad-input tests again in build-asan/ under ASan and UBSan.
# test-valgrind: the tool over a sample log (batch and --online), its grid as
# a ROS map and a bad log, no error or leak.
FUZZ_TARGETS = scanlog library mapyaml pgm png
FUZZ_REPLAY  = $(FUZZ_TARGETS:%=$(BUILD)/tests/fuzz_replay_%)
$(BUILD)/tests/fuzz_replay_%: tests/fuzz_%.c tests/fuzz_replay.c $(TOOL_OBJ) $(BUILD)/libpolyc.a
	@mkdir -p $(dir $@)
	$(CC) $(TOOL_CFLAGS) $^ -o $@ $(LDLIBS)
test-fuzz-replay: $(FUZZ_REPLAY)
	@set -e; for t in $(FUZZ_TARGETS); do $(BUILD)/tests/fuzz_replay_$$t tests/corpus/$$t; done
CLI_TEST_ARGS ?=
test-cli: $(BUILD)/polyc $(BUILD)/gen_example
	tests/cli_bad_input.sh $(CLI_TEST_ARGS) $(BUILD)/polyc
	tests/cli_output.sh $(BUILD)/polyc
	tests/cli_online.sh $(BUILD)/polyc
	tests/cli_curves.sh $(BUILD)/polyc $(BUILD)/gen_example
	tests/cli_readme.sh "$(CC) $(OPT) $(CFLAGS)" $(BUILD)/polyc
SAN_LIST  = address,undefined,float-cast-overflow
SAN_FLAGS = -fsanitize=$(SAN_LIST) -fno-sanitize-recover=all
test-asan:
	ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
	$(MAKE) BUILD=build-asan OPT='-O1 -g $(SAN_FLAGS)' CLI_TEST_ARGS=--quick \
	    unit test-fuzz-replay test-cli
# (the bad log must exit 1 from polyc itself, so valgrind's own code is 99 there)
VALGRIND = valgrind -q --leak-check=full --errors-for-leak-kinds=definite,indirect,possible
test-valgrind: $(BUILD)/polyc
	$(VALGRIND) --error-exitcode=1 $(BUILD)/polyc --stats --iterations 20 \
	    -o $(BUILD)/valgrind.svg examples/office.log
	$(VALGRIND) --error-exitcode=1 $(BUILD)/polyc convert -o $(BUILD)/valgrind.txt examples/office.log
	$(VALGRIND) --error-exitcode=1 $(BUILD)/polyc --online --stats --iterations 5 \
	    --frames $(BUILD)/valgrind_frames --every 100 -o $(BUILD)/valgrind.svg examples/office.log
	$(VALGRIND) --error-exitcode=1 $(BUILD)/polyc grid -o $(BUILD)/valgrind_grid examples/office.log
	$(VALGRIND) --error-exitcode=1 $(BUILD)/polyc --stats --iterations 5 -o $(BUILD)/valgrind.svg \
	    $(BUILD)/valgrind_grid.yaml
	printf 'SCAN 0 0 0 0 0.1 0.05 4 3 1 1 1\nSCAN 0 0 0 0 0.1 0.05 4 3 1 x 1\n' > $(BUILD)/valgrind_bad.log
	@echo "test-valgrind: a bad log; the error line that follows is expected (exit 1)"
	$(VALGRIND) --error-exitcode=99 $(BUILD)/polyc -o $(BUILD)/valgrind.svg $(BUILD)/valgrind_bad.log; \
	    test $$? = 1
	rm -f $(BUILD)/valgrind.svg $(BUILD)/valgrind.txt $(BUILD)/valgrind_bad.log $(BUILD)/valgrind_grid.*
	rm -rf $(BUILD)/valgrind_frames

# libFuzzer (`make fuzz FUZZ_TIME=600`; needs clang): every target in
# build-fuzz/, run one after the other on a scratch corpus seeded from
# tests/corpus/; `make fuzz-merge` adds to tests/corpus/ the inputs that reach
# new edges (hit counts ignored, which keeps the committed corpus small).
FUZZ_CC   ?= clang
FUZZ_TIME ?= 60
FUZZ_BIN   = $(FUZZ_TARGETS:%=build-fuzz/fuzz_%)
FUZZ_CFLAGS = $(WARN) -g -O2 -fno-omit-frame-pointer -fsanitize=fuzzer,$(SAN_LIST) -fno-sanitize-recover=all \
              -Iinclude -Itools -D_POSIX_C_SOURCE=200809L
build-fuzz/fuzz_scanlog: tests/fuzz_scanlog.c tools/scanlog.c tools/scanlog_noreturn.c tools/textesc.c \
                         $(LIB_SRC)
build-fuzz/fuzz_library: tests/fuzz_library.c $(LIB_SRC)
build-fuzz/fuzz_mapyaml: tests/fuzz_mapyaml.c tools/mapfile.c tools/mapfile_pgm.c tools/textesc.c
build-fuzz/fuzz_pgm: tests/fuzz_pgm.c tools/mapfile.c tools/mapfile_pgm.c tools/textesc.c
build-fuzz/fuzz_png: tests/fuzz_png.c tools/mapfile.c tools/mapfile_pgm.c tools/mapfile_png.c \
    tools/inflate.c tools/textesc.c
# the optimiser's float compares drown the run in comparison tracing: off
build-fuzz/fuzz_library: FUZZ_CFLAGS += -fno-sanitize-coverage=trace-cmp
$(FUZZ_BIN): include/polyc.h $(wildcard src/*.h) tools/scanlog.h tools/scanlog_noreturn.h \
             tools/mapfile.h tools/textesc.h tools/inflate.h
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(filter %.c,$^) -o $@ -lm
fuzz: $(FUZZ_BIN)
	@set -e; for t in $(FUZZ_TARGETS); do mkdir -p build-fuzz/corpus/$$t build-fuzz/findings/$$t; \
	  nice build-fuzz/fuzz_$$t -max_total_time=$(FUZZ_TIME) -print_final_stats=1 \
	    -artifact_prefix=build-fuzz/findings/$$t/ build-fuzz/corpus/$$t tests/corpus/$$t; done
fuzz-merge: $(FUZZ_BIN)
	@set -e; for t in $(FUZZ_TARGETS); do \
	  build-fuzz/fuzz_$$t -merge=1 -use_counters=0 tests/corpus/$$t build-fuzz/corpus/$$t; done

# Cortex-M4 (`make cross`; needs gcc-arm-none-eabi, libnewlib-arm-none-eabi): the
# library at -Os -Werror and its sizes; FAILS if it references an allocator or
# stdio (nm -u), or if a linked example (newlib-nano, nosys.specs) contains one; then each
# example's stack from -fstack-usage. A failed POLYC_ASSERT traps (udf): newlib's
# assert() calls __assert_func, which pulls in fiprintf and all of stdio.
CROSS  ?= arm-none-eabi-
XBUILD ?= build-cross
XFLAGS  = $(WARN) -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -Os -Werror -fno-math-errno \
          -ffunction-sections -fdata-sections -fstack-usage -fcallgraph-info=su \
          -DPOLYC_COUNTER_BITS=8 '-DPOLYC_ASSERT(x)=((x) ? (void)0 : __builtin_trap())' -Iinclude
XOBJ    = $(LIB_SRC:src/%.c=$(XBUILD)/%.o)
sp     := $(subst ,, )
X_ALLOC = _*(malloc|calloc|realloc|reallocf|free|memalign|aligned_alloc|posix_memalign|sbrk)(_r)?
X_STDIO = $(subst $(sp),|,.*printf.* .*scanf.* f?open fdopen freopen fclose fread fwrite fputs \
          fputc putc puts putchar fgets gets fgetc getc getchar ungetc fflush fseek ftell rewind \
          perror setvbuf setbuf tmpfile stdin stdout stderr __assert_func setlocale localeconv \
          strto(d|f|ld) atof)
# Single precision by design (docs/architecture.md): the M4F's FPU has no
# double, so a double operation is a library call of 30-100 instructions.
# No object of the library may call software double routines, double libm,
# newlib's float libm that computes in double (sinf, cosf, atan2f, logf,
# expf, powf: src/fmath.c has the library's own), or libgcc's 64-bit float
# conversions, which go through double. The API's doubles (poses, origins,
# figures) are handled on their bits: src/boundary.c's checks and
# comparisons, src/binary64.c's sums and conversions.
X_DOUBLE = __aeabi_d[a-z0-9]+|__aeabi_[fiul]+2d|__aeabi_d2[a-z]+|__[a-z]+df[23]|__extendsfdf2|\
           __truncdfsf2|__fix(uns)?sfdi|__fix(uns)?dfsi|__float(un)?sidf|__float(un)?didf|__ieee754_[a-z0-9]+|\
           sin|cos|tan|asin|acos|atan|atan2|sinh|cosh|tanh|exp|exp2|log|log2|log10|pow|sqrt|cbrt|\
           hypot|floor|ceil|round|lround|trunc|rint|lrint|nearbyint|fmod|remainder|fmin|fmax|fabs|\
           copysign|frexp|ldexp|modf|sinf|cosf|tanf|atan2f|atanf|expf|logf|powf
XELF    = $(EMB_EXAMPLES:%=$(XBUILD)/%.elf)
cross: $(XBUILD)/libpolyc.a $(XELF)
	$(CROSS)size -t $(XOBJ)
	$(CROSS)size $(XELF)
	@bad=$$($(CROSS)nm -u $(XOBJ) | awk '{print $$2}' | grep -Ex '$(X_ALLOC)|$(X_STDIO)|_impure_ptr' | sort -u); \
	if [ -n "$$bad" ]; then echo "cross: FAIL: the library references" $$bad; exit 1; fi
	@for e in $(XELF); do \
	  bad=$$($(CROSS)nm $$e | awk '{print $$3}' | grep -Ex '$(X_ALLOC)|$(X_STDIO)' | sort -u); \
	  if [ -n "$$bad" ]; then echo "cross: FAIL: the linked $$e contains" $$bad; exit 1; fi; \
	done
	@echo "cross: no allocator and no stdio in the library or the linked examples"
	@bad=0; for o in $(XOBJ); do \
	  d=$$($(CROSS)nm -u $$o | awk '{print $$2}' | grep -Ex '$(subst $(sp),,$(X_DOUBLE))' | sort -u | tr '\n' ' '); \
	  if [ -n "$$d" ]; then echo "cross: FAIL: $$o calls double arithmetic: $$d"; bad=1; fi; \
	done; test $$bad = 0
	@echo "cross: no double arithmetic in the library"
	@set -e; for x in $(EMB_EXAMPLES); do \
	  python3 tools/eval/stack_usage.py --cross $(CROSS) --elf $(XBUILD)/$$x.elf \
	    $(XOBJ:.o=.ci) $(XBUILD)/$$x.ci; done
$(XBUILD)/%.o: src/%.c include/polyc.h $(wildcard src/*.h)
	@mkdir -p $(dir $@)
	$(CROSS)gcc $(XFLAGS) -c $< -o $@
$(XBUILD)/libpolyc.a: $(XOBJ)
	rm -f $@ && $(CROSS)ar rcs $@ $^
# (each example with its target macro: no stdio)
$(XBUILD)/embedded_scan.o: XTARGET = EMBEDDED_SCAN_TARGET
$(XBUILD)/embedded_online.o: XTARGET = EMBEDDED_ONLINE_TARGET
$(EMB_EXAMPLES:%=$(XBUILD)/%.o): $(XBUILD)/%.o: examples/%.c examples/embedded_room.h include/polyc.h
	@mkdir -p $(dir $@)
	$(CROSS)gcc $(XFLAGS) -D$(XTARGET) -c $< -o $@
$(XELF): %.elf: %.o $(XBUILD)/libpolyc.a
	$(CROSS)gcc $(XFLAGS) -specs=nano.specs -specs=nosys.specs -Wl,--gc-sections $^ -lm -o $@

# The embedded examples on an emulated Cortex-M4F (`make target`; needs
# qemu-system-arm and newlib's rdimon, which make deps installs): each example
# with the harness of tools/target/ (its own vector table, start-up and linker
# script, an instruction counter, stdio over semihosting) against
# $(XBUILD)/libpolyc.a, run on qemu's mps2-an386 (-icount shift=0: one
# instruction a nanosecond); tools/target/check.py checks each map against
# the room's walls and the host's map and prints the instructions of each
# library call. `make target-profile`: the same runs with a PC sample every
# 4,000 instructions, the top functions and the share of software double.
TBUILD ?= build-target
QEMU   ?= qemu-system-arm
QEMU_RUN = timeout 600 $(QEMU) -M mps2-an386 -nographic -monitor none -serial none \
           -icount shift=0 -semihosting-config enable=on,target=native -kernel
T_LINK = -nostartfiles -T tools/target/mps2_an386.ld -specs=rdimon.specs -Wl,--gc-sections
T_CFLAGS = $(filter-out -Werror -fcallgraph-info=su -fstack-usage,$(XFLAGS)) -DTARGET_STDIO \
           -include tools/target/target.h
.PHONY: target target-profile
$(TBUILD)/startup.o: tools/target/startup.c tools/target/target.h
	@mkdir -p $(dir $@)
	$(CROSS)gcc $(T_CFLAGS) -Werror -c $< -o $@
$(TBUILD)/startup_profile.o: tools/target/startup.c tools/target/target.h
	@mkdir -p $(dir $@)
	$(CROSS)gcc $(T_CFLAGS) -Werror -DTARGET_PROFILE -c $< -o $@
$(EMB_EXAMPLES:%=$(TBUILD)/%.o): $(TBUILD)/%.o: examples/%.c examples/embedded_room.h include/polyc.h \
                                  tools/target/target.h
	@mkdir -p $(dir $@)
	$(CROSS)gcc $(T_CFLAGS) -c $< -o $@
$(TBUILD)/%.elf: $(TBUILD)/startup.o $(TBUILD)/%.o $(XBUILD)/libpolyc.a tools/target/mps2_an386.ld
	$(CROSS)gcc $(T_CFLAGS) $(T_LINK) $(filter %.o %.a,$^) -lm -o $@
$(TBUILD)/%.profile.elf: $(TBUILD)/startup_profile.o $(TBUILD)/%.o $(XBUILD)/libpolyc.a \
                         tools/target/mps2_an386.ld
	$(CROSS)gcc $(T_CFLAGS) $(T_LINK) $(filter %.o %.a,$^) -lm -o $@
target: $(EMB_EXAMPLES:%=$(TBUILD)/%.elf) $(EMB_EXAMPLES:%=$(BUILD)/%)
	@set -e; for x in $(EMB_EXAMPLES); do \
	  $(QEMU_RUN) $(TBUILD)/$$x.elf > $(TBUILD)/$$x.out 2>&1; \
	  $(BUILD)/$$x > $(TBUILD)/$$x.host; \
	  python3 tools/target/check.py --room examples/embedded_room.h --name $$x \
	    $(TBUILD)/$$x.out $(TBUILD)/$$x.host; done
PROFILE_ARGS ?=
target-profile: $(EMB_EXAMPLES:%=$(TBUILD)/%.profile.elf)
	@set -e; for x in $(EMB_EXAMPLES); do \
	  (cd $(TBUILD) && $(QEMU_RUN) $$x.profile.elf > $$x.profile.out 2>&1 && mv target-pcs.bin $$x.pcs); \
	  python3 tools/target/profile.py --nm $(CROSS)nm --elf $(TBUILD)/$$x.profile.elf \
	    --name $$x $(PROFILE_ARGS) $(TBUILD)/$$x.pcs; done

# Benchmark on the shared data (not in the repo): an optimised build in
# build-bench/, then one table. `make bench DATA=dir BENCH_ARGS='--only intel'`
# (also builds build-bench/mapscore: one map's topology and bands against one log)
DATA ?= ../shared/data
BENCH_ARGS ?=
bench:
	$(MAKE) BUILD=build-bench OPT='-O3 -march=native -DNDEBUG' build-bench/bench build-bench/mapscore
	build-bench/bench $(BENCH_ARGS) $(DATA)
$(BUILD)/bench: $(BENCH_SRC) tools/eval/bench.h $(EVAL_OBJ) $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(EVAL_CFLAGS) $(filter-out %.h,$^) -o $@ $(LDLIBS)
$(BUILD)/mapscore: tools/eval/mapscore.c $(EVAL_OBJ) $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(EVAL_CFLAGS) $^ -o $@ $(LDLIBS)

# Simulated scenes of every kind over several seeds, each scored against its
# own ground truth (docs/evaluation.md). `make sweep SWEEP_ARGS='--seeds 1-20
# --kinds hall,flat --svg /tmp/svg'`; needs no data directory.
SWEEP_ARGS ?=
sweep:
	$(MAKE) BUILD=build-bench OPT='-O3 -march=native -DNDEBUG' build-bench/sweep
	build-bench/sweep $(SWEEP_ARGS)
$(BUILD)/sweep: tools/eval/sweep.c $(EVAL_OBJ) $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(EVAL_CFLAGS) $^ -o $@ $(LDLIBS)

# The README's pictures (docs/img/*.png but corridor.png, which is `make
# sweep`'s): the tool's SVGs, from the bench build, rendered 700 px wide by
# rsvg-convert (librsvg2-bin). intel.log is read from DATA. online-strip.png:
# intel replayed with --online, its frames after 200, 400, 600 and 910 scans
# side by side (tools/eval/svgstrip.sh: one SVG of the four, rendered once).
# `make images DATA=../shared/data`
IMG_DIR = build-bench/img
.PHONY: images
images: images-online
	$(MAKE) BUILD=build-bench OPT='-O3 -march=native -DNDEBUG' build-bench/polyc
	@mkdir -p $(IMG_DIR)
	build-bench/polyc -o $(IMG_DIR)/office.svg examples/office.log
	build-bench/polyc grid --cell 0.05 -o $(IMG_DIR)/office examples/office.log
	build-bench/polyc --grid -o $(IMG_DIR)/office-map.svg $(IMG_DIR)/office.yaml
	build-bench/polyc --no-optimize -o $(IMG_DIR)/intel-initial.svg $(DATA)/carmen/intel.log
	build-bench/polyc -o $(IMG_DIR)/intel-optimised.svg $(DATA)/carmen/intel.log
	for f in office office-map intel-initial intel-optimised; do \
	    rsvg-convert -w 700 -o docs/img/$$f.png $(IMG_DIR)/$$f.svg || exit 1; done
	build-bench/polyc --points -o $(IMG_DIR)/fhw.svg $(DATA)/carmen/fhw.log
	sh tools/eval/svgcrop.sh $(IMG_DIR)/fhw.svg docs/img/fhw-band.png 6 9 12 15 450

# `make images-online DATA=../shared/data`: the strip alone
.PHONY: images-online
images-online:
	$(MAKE) BUILD=build-bench OPT='-O3 -march=native -DNDEBUG' build-bench/polyc
	@mkdir -p $(IMG_DIR)
	rm -rf $(IMG_DIR)/online
	build-bench/polyc --online --frames $(IMG_DIR)/online --every 10 \
	    -o $(IMG_DIR)/intel-online.svg $(DATA)/carmen/intel.log
	sh tools/eval/svgstrip.sh docs/img/online-strip.png 1400 \
	    $(foreach n,00200 00400 00600 00910,$(IMG_DIR)/online/frame-$(n).svg)

# Regenerate the bundled example (examples/office.*) with the simulator
.PHONY: examples
examples: $(BUILD)/gen_example
	$(BUILD)/gen_example examples/office.log examples/office.gt.txt
$(BUILD)/gen_example: tests/gen_example.c $(EVAL_OBJ) $(TOOL_OBJ) $(BUILD)/libpolyc.a
	$(CC) $(EVAL_CFLAGS) $^ -o $@ $(LDLIBS)

clean:
	rm -rf $(BUILD) build-* *.egg-info bindings/python/build bindings/python/*.egg-info
