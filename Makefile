# tightknot: plain GNU make.
#
#   make            build build/libtightknot.a and build/tightknot
#   make test       install missing packages, build, run every test (also
#                   under address+undefined sanitizers)
#   make run        build and start the service
#   make bench      run the benchmarks (print figures, never fail on time)
#   make deps       install missing Debian packages (quiet when all there)
#   V=1             show full commands; SANITIZE=1 builds into build/asan
#   CC=clang        any C11 compiler

CC ?= cc
BUILD ?= build
SHARED ?= ../shared
CATALOGUE ?= $(SHARED)/catalogue

ifeq ($(SANITIZE),1)
BUILD := build/asan
SAN_FLAGS := -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=all
OPT := -O1
else
OPT := -O2
endif

CHECK_CFLAGS := $(shell pkg-config --cflags check 2>/dev/null)
CHECK_LIBS := $(shell pkg-config --libs check 2>/dev/null)

CPPFLAGS += -Iinclude -Itests/support -I/usr/include/suitesparse -D_XOPEN_SOURCE=700
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

SERVER_SRC := $(filter-out server/tightknotd.c,$(wildcard server/*.c))
SERVER_OBJ := $(SERVER_SRC:%.c=$(BUILD)/%.o)
SERVER_LIB := $(BUILD)/libtkserver.a
SERVER_LIBS := -lmicrohttpd -ljansson -lsqlite3
DAEMON := $(BUILD)/tightknotd

CLI_SRC := $(wildcard tools/tightknot*.c)
CLI_OBJ := $(CLI_SRC:%.c=$(BUILD)/%.o)
CLI := $(BUILD)/tightknot

TEST_SRC := $(wildcard tests/test_*.c)
TEST_BIN := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
TEST_SUPPORT_SRC := $(wildcard tests/support/*.c)
TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(BUILD)/%.o)

BENCH_SRC := $(wildcard bench/*.c)
BENCH_BIN := $(BENCH_SRC:bench/%.c=$(BUILD)/bench/%)

.SECONDARY:

.PHONY: all deps test test-unit test-asan test-cli run bench bench-struts bench-tighten bench-service \
	lint headers clean

WEB_OUT := $(BUILD)/web
WEB_SRC := $(wildcard web/*)

all: $(LIB) $(CLI) $(DAEMON) $(WEB_OUT)/index.html

deps:
	$(Q)./tools/install-deps.sh
	$(Q)./tools/install-node-deps.sh

$(BUILD)/%.o: %.c
	@mkdir -p $(dir $@)
	@$(if $(Q),echo "  CC      $<")
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) $(CHECK_CFLAGS) -c -o $@ $<

$(LIB): $(ENGINE_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

# The page: web/ and the three.js modules from node_modules (make deps).
$(WEB_OUT)/index.html: $(WEB_SRC) tools/build-web.sh package-lock.json
	@$(if $(Q),echo "  WEB     $(WEB_OUT)")
	$(Q)./tools/build-web.sh $(WEB_OUT) >/dev/null

$(SERVER_LIB): $(SERVER_OBJ)
	@$(if $(Q),echo "  AR      $@")
	$(Q)rm -f $@ && ar rcs $@ $^

$(CLI): $(CLI_OBJ) $(SERVER_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $(CLI_OBJ) $(SERVER_LIB) $(LIB) $(SERVER_LIBS) -lcurl $(LDLIBS)

$(DAEMON): $(BUILD)/server/tightknotd.o $(SERVER_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(SERVER_LIB) $(LIB) $(SERVER_LIBS) $(LDLIBS)

$(BUILD)/tests/%: $(BUILD)/tests/%.o $(TEST_SUPPORT_OBJ) $(SERVER_LIB) $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(TEST_SUPPORT_OBJ) $(SERVER_LIB) $(LIB) $(CHECK_LIBS) \
		$(SERVER_LIBS) $(LDLIBS)

$(BUILD)/bench/%: $(BUILD)/bench/%.o $(LIB)
	@$(if $(Q),echo "  LD      $@")
	$(Q)$(CC) $(LDFLAGS) -o $@ $< $(LIB) $(LDLIBS)

# Every test: unit tests in the normal and sanitizer builds, then the
# command-line tests; one closing line with the totals.
test: deps
	$(Q)$(MAKE) --no-print-directory all $(TEST_BIN)
	$(Q)$(MAKE) --no-print-directory SANITIZE=1 all tests-bin
	$(Q)./tests/run-all.sh $(BUILD) build/asan $(CATALOGUE)

tests-bin: $(TEST_BIN)

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

bench: bench-struts bench-tighten bench-service

bench-struts: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/struts $(CATALOGUE)

bench-tighten: deps all $(BENCH_BIN)
	$(Q)$(BUILD)/bench/tighten $(CATALOGUE)

bench-service: deps all
	$(Q)./bench/service.sh $(BUILD) $(CATALOGUE)

# Banned unsafe calls (curl's list).
lint:
	$(Q)! grep -nE '\b(sprintf|strcpy|strcat|atoi|atof|gets)\s*\(' \
		engine/*.c server/*.c tools/*.c tests/*.c bench/*.c 2>/dev/null || \
		(echo "lint: banned call found" && false)

# Each public header compiles on its own.
headers:
	$(Q)for h in include/tk/*.h; do \
		echo "#include \"$${h#include/}\"" | $(CC) $(CPPFLAGS) -std=c11 -Wall -Wextra -Werror \
			-fsyntax-only -x c - || exit 1; done

clean:
	rm -rf build

-include $(ENGINE_OBJ:.o=.d) $(SERVER_OBJ:.o=.d) $(BUILD)/server/tightknotd.d $(CLI_OBJ:.o=.d) $(TEST_BIN:%=%.d) $(TEST_SUPPORT_OBJ:.o=.d) \
	$(BENCH_BIN:%=%.d)
