# vbcl — top-level Makefile. `make run` installs what is missing, builds and renders the
# quickstart scene; `make test` runs the tests. Quiet unless V=1; SANITIZE=address,undefined
# builds instrumented binaries under build/san/.

CC      ?= cc
CXX     ?= c++
SANITIZE ?=

BUILD := build$(if $(SANITIZE),/san)
Q := $(if $(V),,@)

WARN    := -Wall -Wextra -Wshadow -Wstrict-prototypes -Wmissing-prototypes -Wvla -Wformat-security -Wno-format-truncation
CSTD    := -std=c11 -D_GNU_SOURCE
OPT     ?= -O2 -g
SANFLAGS := $(if $(SANITIZE),-fsanitize=$(SANITIZE) -fno-omit-frame-pointer -fno-sanitize-recover=all)

# Dependencies come from pkg-config; build/config.mk records them once they are found,
# running scripts/install-deps.sh first when one is missing.
NO_CONFIG_GOALS := clean format format-check deps
ifeq ($(filter $(NO_CONFIG_GOALS),$(MAKECMDGOALS)),)
-include build/config.mk
endif

CPPFLAGS := -Ihost -Ikernels $(PKG_CFLAGS) -MMD -MP
CFLAGS   := $(CSTD) $(OPT) $(WARN) $(SANFLAGS)
CXXFLAGS := -std=c++17 $(OPT) -Wall -Wextra -Wshadow $(SANFLAGS)
LDFLAGS  := $(SANFLAGS)
LDLIBS   := $(PKG_LIBS) -lm

HOST_C   := $(wildcard host/*.c)
HOST_CXX := $(wildcard host/*.cpp)
LIB_OBJ  := $(patsubst host/%.c,$(BUILD)/host/%.o,$(filter-out host/main.c,$(HOST_C))) \
            $(patsubst host/%.cpp,$(BUILD)/host/%.o,$(HOST_CXX)) $(BUILD)/kernel_source.o
MAIN_OBJ := $(BUILD)/host/main.o
TEST_OBJ := $(patsubst tests/%.c,$(BUILD)/tests/%.o,$(wildcard tests/*.c))
KERNELS  := $(wildcard kernels/*.cl kernels/*.h)

.PHONY: all run test deps format format-check clean bench-grid
all: vbcl

build/config.mk: scripts/install-deps.sh
	@mkdir -p build
	$(Q)if ! pkg-config --exists OpenCL libcjson OpenImageIO 2>/dev/null || \
	      ! ls /etc/OpenCL/vendors/*.icd >/dev/null 2>&1; then \
	    echo "vbcl: dependencies missing: running scripts/install-deps.sh"; \
	    scripts/install-deps.sh; fi
	$(Q)pkg-config --exists OpenCL libcjson OpenImageIO || \
	    { echo "vbcl: pkg-config still cannot find OpenCL, libcjson, OpenImageIO" >&2; exit 1; }
	$(Q){ echo "PKG_CFLAGS := $$(pkg-config --cflags OpenCL libcjson OpenImageIO)"; \
	      echo "PKG_LIBS := $$(pkg-config --libs OpenCL libcjson OpenImageIO)"; } > $@

deps:
	scripts/install-deps.sh

# ./vbcl is always the plain build; a sanitized one stays in build/san/vbcl.
ifeq ($(SANITIZE),)
vbcl: $(BUILD)/vbcl
	$(Q)cp $< $@
else
vbcl: $(BUILD)/vbcl
	@echo "sanitized binary: $(BUILD)/vbcl (./vbcl is left as the plain build)"
endif

$(BUILD)/vbcl: $(MAIN_OBJ) $(LIB_OBJ)
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/vbcl-tests: $(TEST_OBJ) $(LIB_OBJ)
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

$(BUILD)/host/%.o: host/%.c build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CC      $<"
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) -c -o $@ $<

$(BUILD)/host/%.o: host/%.cpp build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CXX     $<"
	$(Q)$(CXX) $(CPPFLAGS) $(CXXFLAGS) -c -o $@ $<

$(BUILD)/tests/%.o: tests/%.c build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CC      $<"
	$(Q)$(CC) $(CPPFLAGS) -Itests $(CFLAGS) -c -o $@ $<

# The kernels are embedded in the binary: render.cl and everything it includes.
$(BUILD)/embed_kernels: scripts/embed_kernels.c
	@mkdir -p $(dir $@)
	$(Q)$(CC) $(CSTD) -O1 $(WARN) -o $@ $<

$(BUILD)/kernel_source.c: $(KERNELS) $(BUILD)/embed_kernels
	@echo "  EMBED   kernels/render.cl"
	$(Q)$(BUILD)/embed_kernels kernels render.cl $@

$(BUILD)/kernel_source.o: $(BUILD)/kernel_source.c
	$(Q)$(CC) $(CSTD) -O0 -c -o $@ $<

# Renders the quickstart scene: what a new user runs first.
run: vbcl
	./vbcl scenes/quickstart.json -o quickstart.png

# Runs every test (kernels on the default OpenCL device). Sanitizer builds run the tests
# against their own instrumented vbcl.
SAN_ENV := $(if $(SANITIZE),LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0)
test: $(BUILD)/vbcl-tests $(BUILD)/vbcl
	$(Q)$(SAN_ENV) $(BUILD)/vbcl-tests --vbcl $(BUILD)/vbcl

# Render time against the auto-grid density (docs/architecture.md, "Measurements").
bench-grid: vbcl
	scripts/bench_grid.sh

FORMAT_FILES := $(wildcard host/*.c host/*.h host/*.cpp kernels/*.cl kernels/*.h tests/*.c tests/*.h scripts/*.c)
format:
	clang-format -i $(FORMAT_FILES)

format-check:
	clang-format --dry-run --Werror $(FORMAT_FILES)

clean:
	rm -rf build vbcl

-include $(shell find build -name '*.d' 2>/dev/null)
