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
# running scripts/install-deps.sh first when one is missing. It is made again when OpenMPI
# came or went since (`make test` installs it after `make run` built without it).
NO_CONFIG_GOALS := clean format format-check deps
ifeq ($(filter $(NO_CONFIG_GOALS),$(MAKECMDGOALS)),)
-include build/config.mk
MPI_NOW := $(shell pkg-config --exists ompi-c 2>/dev/null && echo 1 || echo 0)
ifneq ($(MPI_FOUND),$(MPI_NOW))
build/config.mk: FORCE
endif
endif

# The host's folders (docs/architecture.md, "The host's layers"): each on the include path,
# so a header is named by its file name wherever it lives.
HOST_DIRS := host $(sort $(dir $(wildcard host/*/*.c host/*/*.h host/*/*.cpp)))
HOST_INC  := $(patsubst %,-I%,$(patsubst %/,%,$(HOST_DIRS)))
# MPI (docs/scaling.md): used when build/config.mk found OpenMPI; MPI=0 builds without it.
ifeq ($(MPI),0)
MPI_CFLAGS :=
MPI_LIBS   :=
endif
CPPFLAGS := $(HOST_INC) -Ikernels $(PKG_CFLAGS) $(MPI_CFLAGS) -MMD -MP
CFLAGS   := $(CSTD) $(OPT) $(WARN) $(SANFLAGS)
CXXFLAGS := -std=c++17 $(OPT) -Wall -Wextra -Wshadow $(SANFLAGS)
LDFLAGS  := $(SANFLAGS)
LDLIBS   := $(PKG_LIBS) $(OIIO_LIBS) $(MPI_LIBS) -lm -pthread
# vbcl itself does not link OpenImageIO: it loads it as a plugin (host/util/image_plugin.c).
VBCL_LDLIBS := $(PKG_LIBS) $(MPI_LIBS) -lm -pthread -ldl

HOST_C   := $(wildcard host/*.c host/*/*.c)
PLUGIN_LOADER := host/util/image_plugin.c
HOST_CXX := $(wildcard host/*.cpp host/*/*.cpp)
LIB_OBJ  := $(patsubst host/%.c,$(BUILD)/host/%.o,$(filter-out host/main.c $(PLUGIN_LOADER),$(HOST_C))) \
            $(patsubst host/%.cpp,$(BUILD)/host/%.o,$(HOST_CXX)) $(BUILD)/kernel_source.o
MAIN_OBJ := $(BUILD)/host/main.o
# The vbcl binary: the library without OpenImageIO's file, the plugin's loader, and the
# plugin (image_io.cpp and image_path.c as a shared object, which encodes and reads images;
# vbcl writes the files itself) embedded.
PLUGIN_SRC := host/util/image_io.cpp host/util/image_path.c
VBCL_OBJ := $(MAIN_OBJ) $(filter-out $(BUILD)/host/util/image_io.o,$(LIB_OBJ)) \
            $(BUILD)/host/util/image_plugin.o $(BUILD)/image_plugin_blob.o
TEST_OBJ := $(patsubst tests/%.c,$(BUILD)/tests/%.o,$(wildcard tests/*.c))
KERNELS  := $(wildcard kernels/*.cl kernels/*.h)

.PHONY: all run test deps test-deps format format-check clean bench bench-grid gallery stress oclgrind fuzz FORCE test-drivers
all: vbcl

build/config.mk: scripts/install-deps.sh Makefile
	@mkdir -p build
	$(Q)if ! pkg-config --exists OpenCL libcjson OpenImageIO 2>/dev/null || \
	      ! ls /etc/OpenCL/vendors/*.icd >/dev/null 2>&1; then \
	    echo "vbcl: dependencies missing: running scripts/install-deps.sh"; \
	    scripts/install-deps.sh; fi
	$(Q)pkg-config --exists OpenCL libcjson OpenImageIO || \
	    { echo "vbcl: pkg-config still cannot find OpenCL, libcjson, OpenImageIO" >&2; exit 1; }
	$(Q){ echo "PKG_CFLAGS := $$(pkg-config --cflags OpenCL libcjson OpenImageIO)"; \
	      echo "PKG_LIBS := $$(pkg-config --libs OpenCL libcjson)"; \
	      echo "OIIO_LIBS := $$(pkg-config --libs OpenImageIO)"; \
	      if pkg-config --exists ompi-c 2>/dev/null; then \
	        echo "MPI_FOUND := 1"; \
	        echo "MPI_CFLAGS := -DVBCL_MPI $$(pkg-config --cflags ompi-c)"; \
	        echo "MPI_LIBS := $$(pkg-config --libs ompi-c)"; \
	      else echo "# no MPI (libopenmpi-dev): vbcl runs as one process"; \
	        echo "MPI_FOUND := 0"; fi; } > $@

deps:
	scripts/install-deps.sh

# What the tests, the checks and the scripts need besides (install-deps.sh --test).
test-deps:
	$(Q)scripts/install-deps.sh --test

# ./vbcl is always the plain build; a sanitized one stays in build/san/vbcl.
ifeq ($(SANITIZE),)
vbcl: $(BUILD)/vbcl
	$(Q)cp $< $@
else
vbcl: $(BUILD)/vbcl
	@echo "sanitized binary: $(BUILD)/vbcl (./vbcl is left as the plain build)"
endif

$(BUILD)/vbcl: $(VBCL_OBJ)
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(VBCL_LDLIBS)

$(BUILD)/plugin/%.o: host/util/%.cpp build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CXX     $< (plugin)"
	$(Q)$(CXX) $(CPPFLAGS) $(CXXFLAGS) -fPIC -c -o $@ $<

$(BUILD)/plugin/%.o: host/util/%.c build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CC      $< (plugin)"
	$(Q)$(CC) $(CPPFLAGS) $(CFLAGS) -fPIC -c -o $@ $<

$(BUILD)/libvbcl_image.so: $(patsubst host/util/%,$(BUILD)/plugin/%.o,$(basename $(PLUGIN_SRC)))
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -shared -o $@ $^ $(OIIO_LIBS)

# The plugin's bytes in the binary, as vbcl_image_plugin .. vbcl_image_plugin_end.
$(BUILD)/image_plugin_blob.o: $(BUILD)/libvbcl_image.so
	@echo "  EMBED   $<"
	$(Q)printf '%s\n' '.section .rodata' '.balign 64' '.globl vbcl_image_plugin' \
	    'vbcl_image_plugin:' '.incbin "$<"' '.globl vbcl_image_plugin_end' \
	    'vbcl_image_plugin_end:' '.section .note.GNU-stack,"",@progbits' > $(BUILD)/image_plugin_blob.s
	$(Q)$(CC) -c -o $@ $(BUILD)/image_plugin_blob.s

$(BUILD)/vbcl-tests: $(TEST_OBJ) $(LIB_OBJ) $(BUILD)/probe_source.o
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

# The fault-injection library of test_faults.c (LD_PRELOAD; tests/fault/shim.c).
$(BUILD)/libvbcl_fault.so: tests/fault/shim.c
	@echo "  LINK    $@"
	$(Q)$(CC) $(CSTD) -O1 $(WARN) -shared -fPIC -o $@ $< -ldl

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

# The kernels are embedded in the binary: render.cl (the tracing program) and film.cl
# (anti-aliasing's film kernels), each with everything it includes; the test binaries also
# embed probe.cl, the tests' own program.
$(BUILD)/embed_kernels: scripts/embed_kernels.c
	@mkdir -p $(dir $@)
	$(Q)$(CC) $(CSTD) -O1 $(WARN) -o $@ $<

$(BUILD)/kernel_source.c: $(KERNELS) $(BUILD)/embed_kernels
	@echo "  EMBED   kernels/render.cl kernels/film.cl"
	$(Q)$(BUILD)/embed_kernels kernels $@ vbcl_kernel_source=render.cl vbcl_film_source=film.cl

$(BUILD)/kernel_source.o: $(BUILD)/kernel_source.c
	$(Q)$(CC) $(CSTD) -O0 -c -o $@ $<

$(BUILD)/probe_source.c: $(KERNELS) $(BUILD)/embed_kernels
	@echo "  EMBED   kernels/probe.cl"
	$(Q)$(BUILD)/embed_kernels kernels $@ vbcl_probe_source=probe.cl

$(BUILD)/probe_source.o: $(BUILD)/probe_source.c
	$(Q)$(CC) $(CSTD) -O0 -c -o $@ $<

# Renders the quickstart scene: what a new user runs first. The kernel programs are
# compiled first, on every core (vbcl --warm-cache: 2 – 2.5 minutes on 2 cores the first
# time, a second after), so that this render and a user's own scenes compile nothing. The
# host is built on every core too.
run:
	$(Q)$(MAKE) --no-print-directory -j$$(nproc) vbcl
	./vbcl --warm-cache
	./vbcl scenes/quickstart.json -o quickstart.png

# Runs every test (kernels on the default OpenCL device), after the binaries are built and
# vbcl --warm-cache has compiled the kernel programs, both on every core. Sanitizer builds run the tests
# against their own instrumented vbcl. intercept_tls_get_addr=0: the __tls_get_addr
# interceptor of GCC's sanitizer runtime (up to GCC 13) takes a dynamic TLS block that
# malloc happens to place 16 bytes past a 4 KiB boundary for a glibc 2.18 one and reads a
# bogus range from the two words before it; LeakSanitizer's tracer then dies at exit
# ("Tracer caught signal 11") on a run with no leak. Dynamic TLS blocks are malloc'd and
# reached from each thread's DTV, so the leak check does not need the interceptor.
SAN_ENV := $(if $(SANITIZE),LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0:intercept_tls_get_addr=0)
# Beside the tests, scripts/smoke.sh: the gallery script on two figures at 16x16, every
# benchmark part on tiny images (scripts/bench.py --quick) and scripts/bench_rays_compare.py
# on one, so that `make gallery`, `make bench` and the comparison script cannot rot; not in
# sanitizer builds, whose timings mean nothing. The tests run in TEST_JOBS worker processes
# (vbcl-tests -j), one a core up to 4 by default; --warm-cache compiles the kernels while
# the test binaries build.
TEST_JOBS ?= $(shell n=$$(nproc); echo $$((n < 4 ? n : 4)))
test: test-deps
	$(Q)$(MAKE) --no-print-directory -j$$(nproc) $(BUILD)/vbcl
	$(Q)$(SAN_ENV) $(BUILD)/vbcl --warm-cache & warm=$$!; \
	  $(MAKE) --no-print-directory -j$$(nproc) $(BUILD)/vbcl-tests $(BUILD)/vbcl-bench-rays \
	    $(BUILD)/libvbcl_fault.so; built=$$?; \
	  wait $$warm && [ $$built = 0 ]
ifeq ($(SANITIZE),)
	$(Q)scripts/smoke.sh $(BUILD) > $(BUILD)/smoke.log 2>&1 & smoke=$$!; \
	  $(BUILD)/vbcl-tests -j $(TEST_JOBS) --vbcl $(BUILD)/vbcl; tests=$$?; \
	  wait $$smoke; smoked=$$?; cat $(BUILD)/smoke.log; [ $$tests = 0 ] && [ $$smoked = 0 ]
else
	$(Q)$(SAN_ENV) $(BUILD)/vbcl-tests -j $(TEST_JOBS) --vbcl $(BUILD)/vbcl
endif

# The thesis's appendix figures A.1 ... A.8 at their own settings (400x400), one at a time:
# PNG files in docs/images/thesis/ and the README's gallery table with each render's measured
# time, samples per pixel and rays (scripts/gallery.py; about 4 minutes on 2 cores).
gallery: vbcl | test-deps
	scripts/gallery.py --vbcl ./vbcl --out docs/images/thesis --readme README.md

# The benchmarks (scripts/bench.py; docs/benchmarks.md): the thesis's section 4.1.5 table on
# figure A.4, throughput across grid sizes, run time against error for anti-aliasing and
# band counts, kernel build time, rays per second against Embree and per OpenCL device, and
# figure A.4 by acceleration structure (about 18 minutes on 2 cores). CSV,
# markdown and PNG in bench-out/. BENCH_FLAGS passes options, e.g. BENCH_FLAGS="--parts grid".
BENCH_FLAGS ?=
# Embree, for the part "embree", is installed here (install-deps.sh --bench); where it cannot
# be, that part measures vbcl alone.
bench: vbcl
	$(Q)scripts/install-deps.sh --bench || echo "bench: Embree not installed: part embree measures vbcl alone"
	$(Q)$(MAKE) --no-print-directory $(BUILD)/vbcl-bench-rays
	scripts/bench.py $(BENCH_FLAGS)

# The ray-throughput bench against Embree (bench.py part "embree"; docs/benchmarks.md): the
# probe kernels and Embree 3's single-ray API on the same rays. It links Embree when
# embree3/rtcore.h is found (scripts/install-deps.sh --bench installs Debian's libembree-dev),
# else it measures vbcl alone and says Embree was skipped. The renderer never links Embree.
EMBREE = $(shell $(CC) -E -x c -include embree3/rtcore.h /dev/null >/dev/null 2>&1 && echo 1)
BENCH_EMBREE_OBJ = $(BUILD)/tests/bench/bench_embree$(if $(EMBREE),-embree).o
$(BUILD)/tests/bench/bench_embree-embree.o: tests/bench/bench_embree.c build/config.mk
	@mkdir -p $(dir $@)
	@echo "  CC      $< (with Embree)"
	$(Q)$(CC) $(CPPFLAGS) -DVBCL_HAVE_EMBREE $(CFLAGS) -c -o $@ $<

# embree.cfg changes when Embree appears or goes, so that the bench is linked again.
$(BUILD)/tests/bench/embree.cfg: FORCE
	@mkdir -p $(dir $@)
	$(Q)echo "embree=$(EMBREE)" | cmp -s - $@ || echo "embree=$(EMBREE)" > $@

$(BUILD)/vbcl-bench-rays: $(BUILD)/tests/bench/bench_rays.o $(BENCH_EMBREE_OBJ) $(LIB_OBJ) \
                          $(BUILD)/probe_source.o $(BUILD)/tests/bench/embree.cfg
	@echo "  LINK    $@$(if $(EMBREE),, (without Embree: not installed))"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $(filter %.o,$^) $(LDLIBS) $(if $(EMBREE),-lembree3) -lpthread

FORCE:

# Render time against the auto-grid density (docs/architecture.md, "Measurements").
bench-grid: vbcl
	scripts/bench_grid.sh

# Stress run (docs/testing.md): 10^7 rays at the edges and vertices of closed meshes at
# three scales, and an 8192x8192 render. Too long for `make test`, which runs a 10^5 version.
$(BUILD)/vbcl-stress: $(BUILD)/tests/stress/stress_main.o $(BUILD)/tests/watertight.o $(LIB_OBJ) \
                      $(BUILD)/probe_source.o
	@echo "  LINK    $@"
	$(Q)$(CXX) $(LDFLAGS) -o $@ $^ $(LDLIBS)

stress: $(BUILD)/vbcl-stress $(BUILD)/vbcl
	$(Q)$(SAN_ENV) $(BUILD)/vbcl-stress --vbcl $(BUILD)/vbcl

# The kernels under oclgrind on the smallest scene (fails on any error it reports), and the
# same image on PoCL and on oclgrind, a second OpenCL implementation (docs/testing.md).
OCLGRIND_FLAGS ?= --check-api --data-races
oclgrind: $(BUILD)/vbcl | test-deps
	$(Q)scripts/oclgrind_check.sh $(BUILD)/vbcl tests/scenes/tiny.json "$(OCLGRIND_FLAGS)"
	$(Q)scripts/oclgrind_check.sh $(BUILD)/vbcl tests/scenes/tiny_glass.json "$(OCLGRIND_FLAGS)" 1e-3
	$(Q)scripts/oclgrind_check.sh $(BUILD)/vbcl tests/scenes/tiny_aa.json "$(OCLGRIND_FLAGS)"
	$(Q)scripts/oclgrind_check.sh $(BUILD)/vbcl tests/scenes/tiny_dispersion.json "$(OCLGRIND_FLAGS)" 1e-3

# A second OpenCL driver (docs/testing.md, "Two OpenCL drivers"): Intel's CPU runtime from
# PyPI, installed once into ~/.cache/vbcl/intel-ocl (scripts/intel-ocl.sh), beside PoCL; the
# same small scenes rendered on both and compared with stated tolerances.
test-drivers: $(BUILD)/vbcl
	$(Q)env=$$(scripts/intel-ocl.sh) && . "$$env" && \
	    scripts/drivers_check.py --vbcl $(BUILD)/vbcl --a Portable --b Intel

# libFuzzer harnesses for the scene and mesh parsers, built with clang into build/fuzz/ and
# run from the seed corpus in tests/fuzz/corpus/ (docs/testing.md): FUZZ_RUNS executions
# per parser when given (failing if FUZZ_SECONDS runs out first), else FUZZ_SECONDS each.
# Prints each parser's executions, time and rate. CI: FUZZ_RUNS=1000000 FUZZ_SECONDS=900.
FUZZ_SECONDS ?= 60
FUZZ_RUNS    ?=
FUZZ_CC      ?= clang
FUZZ_TARGETS := scene mesh_obj mesh_ply
FUZZ_SRC     := $(wildcard host/scene/*.c) host/util/diag.c host/geom/mesh.c host/geom/mesh_meet.c \
                host/geom/mesh_io.c host/geom/shapes.c host/accel/grid.c host/util/cache.c \
                host/texgen/texgen_args.c host/texgen/texgen_bomb.c host/texgen/texgen_deform.c \
                host/texgen/texgen_set.c host/util/fileio.c tests/fuzz/no_images.c
build/fuzz/fuzz_%: tests/fuzz/fuzz_%.c tests/fuzz/fuzz_input.h $(FUZZ_SRC) build/config.mk | test-deps
	@mkdir -p $(dir $@)
	@echo "  FUZZ    $@"
	$(Q)$(FUZZ_CC) $(CSTD) -g -O1 $(WARN) -Wno-unknown-warning-option \
	    -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all $(HOST_INC) -Ikernels \
	    $$(pkg-config --cflags libcjson) -o $@ $< $(FUZZ_SRC) $$(pkg-config --libs libcjson) -lm

fuzz: $(patsubst %,build/fuzz/fuzz_%,$(FUZZ_TARGETS))
	$(Q)for t in $(FUZZ_TARGETS); do \
	    corpus=$$(echo $$t | sed 's/^mesh_//'); mkdir -p build/fuzz/work-$$t; \
	    echo "fuzz: $$t: $(if $(FUZZ_RUNS),$(FUZZ_RUNS) executions (at most $(FUZZ_SECONDS) s),$(FUZZ_SECONDS) s) (seeds: tests/fuzz/corpus/$$corpus)"; \
	    t0=$$(date +%s); \
	    build/fuzz/fuzz_$$t build/fuzz/work-$$t tests/fuzz/corpus/$$corpus \
	        -max_total_time=$(FUZZ_SECONDS) $(if $(FUZZ_RUNS),-runs=$(FUZZ_RUNS)) -timeout=10 \
	        -rss_limit_mb=2048 -max_len=16384 \
	        -print_final_stats=1 -artifact_prefix=build/fuzz/crash-$$t- \
	        > build/fuzz/$$t.log 2>&1 || { tail -40 build/fuzz/$$t.log; \
	        echo "fuzz: $$t FAILED: the input is in build/fuzz/crash-$$t-*"; exit 1; }; \
	    secs=$$(( $$(date +%s) - t0 )); \
	    execs=$$(sed -n 's/^stat::number_of_executed_units: *//p' build/fuzz/$$t.log); \
	    new=$$(sed -n 's/^stat::new_units_added: *//p' build/fuzz/$$t.log); \
	    echo "fuzz: $$t: $$execs executions in $$secs s ($$(( execs / (secs > 0 ? secs : 1) ))/s), $$new new inputs"; \
	    if [ -n "$(FUZZ_RUNS)" ] && [ "$$execs" -lt "$(FUZZ_RUNS)" ]; then \
	        echo "fuzz: $$t reached only $$execs of $(FUZZ_RUNS) executions in $(FUZZ_SECONDS) s"; exit 1; fi; \
	done

FORMAT_FILES := $(wildcard host/*.c host/*.h host/*/*.c host/*/*.h host/*/*.cpp kernels/*.cl kernels/*.h tests/*.c tests/*.h \
                tests/stress/*.c tests/bench/*.c tests/bench/*.h tests/fuzz/*.c tests/fuzz/*.h tests/fault/*.c \
                scripts/*.c)
format:
	clang-format -i $(FORMAT_FILES)

format-check:
	clang-format --dry-run --Werror $(FORMAT_FILES)

clean:
	rm -rf build vbcl

-include $(shell find build $(BUILD) -name '*.d' 2>/dev/null | sort -u)
