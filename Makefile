# tightknot: plain GNU make.
#
#   make            build build/libtightknot.a and build/tightknot
#   make test       install missing packages, build, run every test (also
#                   under address+undefined sanitizers)
#   make run        build and start the service
#   make bench      run the benchmarks (print figures, never fail on time)
#   make fuzz       run each fuzz target FUZZ_SECONDS (default 60) with libFuzzer
#   make deps       install missing Debian packages (quiet when all there)
#   V=1             show full commands; SANITIZE=1 builds into build/asan,
#                   SANITIZE=thread into build/tsan
#   CC=clang        any C11 compiler

CC ?= cc
BUILD ?= build
SHARED ?= ../shared
CATALOGUE ?= $(SHARED)/catalogue

ifeq ($(FUZZ),1)
# libFuzzer's coverage in every object; the targets link -fsanitize=fuzzer.
BUILD := build/libfuzzer
CC := clang
SAN_FLAGS := -fsanitize=fuzzer-no-link,address,undefined -fno-omit-frame-pointer \
	-fno-sanitize-recover=all
OPT := -O1
else ifeq ($(SANITIZE),thread)
# The service's threads (workers, request threads, the store) under
# ThreadSanitizer: `make test` runs the service's suite against it.
BUILD := build/tsan
SAN_FLAGS := -fsanitize=thread -fno-omit-frame-pointer
OPT := -O1
else ifeq ($(SANITIZE),1)
BUILD := build/asan
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
OPT := -O1
else
OPT := -O2
endif

CHECK_CFLAGS := $(shell pkg-config --cflags check 2>/dev/null)
CHECK_LIBS := $(shell pkg-config --libs check 2>/dev/null)

CPPFLAGS += -Iinclude -Icommon -Itests/support -I/usr/include/suitesparse -I/usr/include/postgresql -D_XOPEN_SOURCE=700
CFLAGS += -std=c11 $(OPT) -g -Wall -Wextra -Werror -Wshadow -Wstrict-prototypes \
	-Wmissing-prototypes -Wno-missing-field-initializers -MMD -MP $(SAN_FLAGS)
LDFLAGS += $(SAN_FLAGS)
LDLIBS += -lcholmod -lsuitesparseconfig -llapack -lblas -lm -lpthread

ifeq ($(V),1)
Q :=
else
Q := @
endif

ENGINE_SRC := $(wildcard engine/*.c)
ENGINE_OBJ := $(ENGINE_SRC:%.c=$(BUILD)/%.o)
LIB := $(BUILD)/libtightknot.a

# What the command line and the service share: the records' JSON.
COMMON_SRC := $(wildcard common/*.c)
COMMON_OBJ := $(COMMON_SRC:%.c=$(BUILD)/%.o)
COMMON_LIB := $(BUILD)/libtkcommon.a

SERVER_SRC := $(filter-out server/tightknotd.c,$(wildcard server/*.c))
SERVER_OBJ := $(SERVER_SRC:%.c=$(BUILD)/%.o)
SERVER_LIB := $(BUILD)/libtkserver.a
SERVER_LIBS := -lmicrohttpd -ljansson -lsqlite3 -lpq -lgnutls
DAEMON := $(BUILD)/tightknotd

CLI_SRC := $(wildcard tools/tightknot*.c)
CLI_OBJ := $(CLI_SRC:%.c=$(BUILD)/%.o)
CLI := $(BUILD)/tightknot

TEST_SRC := $(wildcard tests/test_*.c)
TEST_BIN := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
TEST_SUPPORT_SRC := $(wildcard tests/support/*.c)
TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(BUILD)/%.o)

# Fuzz targets (tests/fuzz/fuzz_NAME.c): libFuzzer binaries with `make fuzz`,
# and replay drivers that run their corpora in every `make test`.
FUZZ_TARGETS := $(patsubst tests/fuzz/fuzz_%.c,%,$(wildcard tests/fuzz/fuzz_*.c))
REPLAY_BIN := $(FUZZ_TARGETS:%=$(BUILD)/fuzz/replay_%)
FUZZ_BIN := $(FUZZ_TARGETS:%=$(BUILD)/fuzz/fuzz_%)
FUZZ_SECONDS ?= 60

BENCH_SRC := $(wildcard bench/*.c)
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)

.SECONDARY:

.PHONY: all deps test test-unit test-asan test-cli run bench bench-struts bench-tighten bench-steps bench-starts bench-service bench-cluster bench-work bench-catalogue bench-jones bench-extrapolate \
	lint headers clean fuzz fuzz-bin

WEB_OUT := $(BUILD)/web
WEB_SRC := $(wildcard web/*)

all: $(LIB) $(CLI) $(DAEMON) $(WEB_OUT)/index.html

deps:
	$(Q)./tools/install-deps.sh
	$(Q)./tools/install-node-deps.sh
	@mkdir -p build && touch $(DEPS_STAMP)

# Plain `make` on a fresh clone installs what the build needs first (once;
# `make deps` checks again).
DEPS_STAMP := build/.deps-installed
$(DEPS_STAMP): tools/install-deps.sh tools/install-node-deps.sh package-lock.json
	$(Q)./tools/install-deps.sh
	$(Q)./tools/install-node-deps.sh
	@mkdir -p build && touch $@

$(BUILD)/%.o: %.c | $(DEPS_STAMP)
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(CHECK_CFLAGS) -c -o $@ $<

$(LIB): $(ENGINE_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

# The page: web/ and the three.js modules from node_modules (make deps).
$(WEB_OUT)/index.html: $(WEB_SRC) tools/build-web.sh package-lock.json | $(DEPS_STAMP)
	@$(if $(Q),echo "  WEB     $(WEB_OUT)")
	$(Q)./tools/build-web.sh $(WEB_OUT) >/dev/null

$(SERVER_LIB): $(SERVER_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(COMMON_LIB): $(COMMON_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

# The command line shares only the records' JSON with the service: neither
# libmicrohttpd nor SQLite on its link line.
$(CLI): $(CLI_OBJ) $(COMMON_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $(CLI_OBJ) $(COMMON_LIB) $(LIB) -ljansson -lcurl $(LDLIBS)

$(DAEMON): $(BUILD)/server/tightknotd.o $(SERVER_LIB) $(COMMON_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(SERVER_LIB) $(COMMON_LIB) $(LIB) $(SERVER_LIBS) $(LDLIBS)

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(TEST_SUPPORT_OBJ) $(SERVER_LIB) $(COMMON_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(SERVER_LIB) $(COMMON_LIB) $(LIB) $(CHECK_LIBS) \
		$(SERVER_LIBS) $(LDLIBS)

# The service's headers live with it; its tests and fuzz targets see them.
$(BUILD)/server/%.o $(BUILD)/tests/%.o: CPPFLAGS += -Iserver

$(BUILD)/fuzz/replay_%: $(BUILD)/tests/fuzz/fuzz_%.o $(BUILD)/tests/fuzz/replay.o $(SERVER_LIB) $(COMMON_LIB) $(LIB)
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(BUILD)/tests/fuzz/replay.o $(SERVER_LIB) $(COMMON_LIB) $(LIB) \
		$(SERVER_LIBS) $(LDLIBS)

$(BUILD)/fuzz/fuzz_%: $(BUILD)/tests/fuzz/fuzz_%.o $(SERVER_LIB) $(COMMON_LIB) $(LIB)
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -fsanitize=fuzzer -o $@ $< $(SERVER_LIB) $(COMMON_LIB) $(LIB) $(SERVER_LIBS) $(LDLIBS)

$(BUILD)/bench/%: $(BUILD)/bench/%.o $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(LIB) $(LDLIBS)

# Every test: unit tests in the normal and sanitizer builds, then the
# command-line tests; one closing line with the totals.  The builds use
# every core unless make was given -j.
TEST_JOBS := $(if $(filter -j%,$(MAKEFLAGS)),,-j$(shell nproc 2>/dev/null || echo 1))
test: deps
	$(Q)$(MAKE) --no-print-directory $(TEST_JOBS) all tests-bin $(BENCH_BIN) lint headers
	$(Q)$(MAKE) --no-print-directory $(TEST_JOBS) SANITIZE=1 all tests-bin
	$(Q)$(MAKE) --no-print-directory $(TEST_JOBS) SANITIZE=thread build/tsan/tightknotd build/tsan/tightknot
	$(Q)$(MAKE) --no-print-directory $(TEST_JOBS) FUZZ=1 fuzz-bin
	$(Q)./tests/run-all.sh $(BUILD) build/asan $(CATALOGUE)

tests-bin: $(TEST_BIN) $(REPLAY_BIN)

# Each fuzz target for FUZZ_SECONDS (default 60) with clang's libFuzzer,
# from its seed corpus tests/fuzz/corpus/NAME; what it finds is kept in
# build/libfuzzer/corpus/NAME, crashes in build/libfuzzer/artifacts.
fuzz: deps
	$(Q)$(MAKE) --no-print-directory FUZZ=1 fuzz-bin
	$(Q)./tests/fuzz/fuzz.sh build/libfuzzer $(FUZZ_SECONDS) $(FUZZ_TARGETS)

fuzz-bin: $(FUZZ_BIN)

test-unit: all $(TEST_BIN)
	$(Q)./tests/run-all.sh --unit-only $(BUILD) "" $(CATALOGUE)

# The service on its defaults: 127.0.0.1:8080, jobs in var/tightknot.db,
# the catalogue when ../shared/catalogue is there, the page from web/.
PORT ?= 8080
RUN_ARGS = --port $(PORT) --db var/tightknot.db $(if $(wildcard $(CATALOGUE)/*.vect),--catalogue $(CATALOGUE)) --web $(WEB_OUT)

run: deps all
	@mkdir -p var
	@echo "tightknot: starting the service on http://127.0.0.1:$(PORT)/ (Ctrl-C stops it)"
	$(Q)exec $(DAEMON) $(RUN_ARGS)

bench: bench-struts bench-tighten bench-steps bench-starts bench-service bench-cluster bench-work

bench-struts: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/struts $(CATALOGUE)

bench-tighten: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/tighten $(CATALOGUE)

bench-steps: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/steps $(CATALOGUE)

bench-starts: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/starts $(CATALOGUE)

bench-service: deps all
	$(Q)./bench/service.sh $(BUILD) $(CATALOGUE)

bench-cluster: deps all
	$(Q)node bench/cluster.mjs $(BUILD) $(CATALOGUE)

# A budget of work against the processor time it takes here, and the same
# run again beside a copy of itself.
bench-work: deps all
	$(Q)./bench/work.sh 20 $(BUILD) $(CATALOGUE)

# The whole catalogue through the service (hours: see README, --slice).
bench-catalogue: deps all
	$(Q)node bench/catalogue.mjs --build $(BUILD) $(CATALOGUE)

# The types the catalogue bench ended at, against its files' by the Jones
# polynomial (Regina's, from Debian's regina-normal): after a table run.
bench-jones: deps
	$(Q)./tools/install-deps.sh regina-normal
	$(Q)./bench/jones.py --db $(BUILD)/catalogue/jobs.db --catalogue $(CATALOGUE) \
		--starts $(BUILD)/catalogue/starts

# The smooth limit of the trefoil's ropelength from its tight polygons at
# 1200 to 9600 vertices (75 minutes: see README).
bench-extrapolate: deps all
	$(Q)node bench/extrapolate.mjs --build $(BUILD) --catalogue $(CATALOGUE) --reference 32.742934

# Banned unsafe calls (curl's list); and each engine file calls only those
# below it (engine/run.h's order), read from the objects' symbols.
lint: $(ENGINE_OBJ)
	$(Q)! grep -nE '\b(sprintf|strcpy|strcat|atoi|atof|gets)\s*\(' \
		engine/*.c common/*.c server/*.c tools/*.c tests/*.c bench/*.c 2>/dev/null || \
		(echo "lint: banned call found" && false)
	$(Q)./tools/engine-calls.sh $(BUILD) >/dev/null

# Each public header compiles on its own.
headers:
	$(Q)for h in include/tk/*.h common/*.h; do \
		echo "#include \"$${h#include/}\"" | $(CC) $(CPPFLAGS) -Iserver -std=c11 -Wall -Wextra -Werror \
			-fsyntax-only -x c - || exit 1; done

clean:
	rm -rf build

-include $(ENGINE_OBJ:.o=.d) $(COMMON_OBJ:.o=.d) $(SERVER_OBJ:.o=.d) $(BUILD)/server/tightknotd.d $(CLI_OBJ:.o=.d) $(TEST_BIN:%=%.d) $(TEST_SUPPORT_OBJ:.o=.d) \
	$(BENCH_BIN:%=%.d) $(FUZZ_TARGETS:%=$(BUILD)/tests/fuzz/fuzz_%.d) $(BUILD)/tests/fuzz/replay.d
