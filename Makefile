# rt - a data-oriented CPU renderer.
#
#   make              build ./rt (installs missing Debian packages first)
#   make test         build and run the test suite
#   make asan         the test suite under AddressSanitizer + UBSan
#   make tsan         the threaded tests under ThreadSanitizer
#   make profile      ./rt-profile: optimised, with symbols and frame pointers (for perf)
#   make scenes       render every scene in scenes/ into docs/images/
#   make denoiser     Intel Open Image Denoise for --denoise: the pyoidn wheel in build/oidn-venv
#   make reference    the path tracer against the shared Mitsuba reference, through rt compare (SPP=64)
#   make bench-packets rt's packets and Embree's on the same pixel tiles (also run by bench-compare)
#   make bench-instances rt instanced vs flattened vs Embree 3 instances on the same rays
#   make bench-render rt's path tracer against Mitsuba 3 (sets it up in build/mitsuba-venv)
#   make bench-denoise --denoise at 4/16/64 spp against raw 256 and 1024 spp
#   make bench-helmet  path tracer rays/s on DamagedHelmet under a sky and a sun (RT_BINS: several builds)
#   make bench-load   load-time goals (a 30000-material OBJ under 2 s), timed outside the unit tests
#   make install      rt, the library and its headers, and a pkg-config file
#                     (PREFIX=/usr/local, DESTDIR for staging); make test-install checks it
#   make test-slurm   the Slurm launcher (examples/slurm) on a real Slurm started here (root)
#   make test-kubernetes / test-parallel   the Kubernetes and GNU parallel launchers, run locally
#   make clean
#
# Variables: WERROR=1 turns warnings into errors (CI sets it); PORTABLE=1
# builds for any x86-64 instead of this machine's CPU; SHARED=dir
# points the tests at the shared assets (default ../shared).

CC      ?= cc
# -march=native: the compiler's vector code for this machine. A binary for
# other machines of a farm: PORTABLE=1 (x86-64 baseline; the kd-tree's AVX2
# kernels are compiled in either way and used when the CPU has AVX2 and FMA,
# else its portable step: same images). -ffp-contract=off: no multiply-adds
# fused by the compiler (GCC's -std=c11 default; clang's is on), so code
# compiled with FMA available (native, the AVX2 kernels) rounds as baseline.
ifeq ($(PORTABLE),1)
OPT     ?= -O2
BUILD   ?= build-portable
RT      ?= rt-portable
else
OPT     ?= -O2 -march=native
endif
WARN    := -Wall -Wextra -Wpedantic -Wshadow
ifeq ($(WERROR),1)
WARN    += -Werror
endif
CFLAGS  ?=
CFLAGS  += -std=c11 -ffp-contract=off $(WARN) $(OPT) -Iinclude -D_POSIX_C_SOURCE=200809L -MMD -MP
# C++ only for src/io/draco.cc, the wrapper over libdraco (rt/io/draco.h)
CXX     ?= c++
CXXFLAGS ?=
CXXFLAGS += -std=c++17 $(WARN) $(OPT) -Iinclude -MMD -MP
LDLIBS  := -lstb -lOpenEXRCore -lmeshoptimizer -ldraco -lwebp -lstdc++ -ldl -lpthread -lm
BUILD   ?= build
SHARED  ?= ../shared
RT      ?= rt

# The library, by pipeline stage, lowest first: each stage includes and calls
# only the stages before it (docs/architecture.md); the driver is src/driver.
STAGES   := base image scene accel render io job
LIB_SRC  := $(foreach d,$(STAGES),$(wildcard src/$(d)/*.c))
LIB_CXX  := $(foreach d,$(STAGES),$(wildcard src/$(d)/*.cc))
LIB_OBJ  := $(LIB_SRC:src/%.c=$(BUILD)/obj/%.o) $(LIB_CXX:src/%.cc=$(BUILD)/obj/%.o)
DRV_SRC  := $(wildcard src/driver/*.c)
DRV_OBJ  := $(DRV_SRC:src/%.c=$(BUILD)/obj/%.o)
TEST_SRC := $(wildcard tests/test_*.c)
TEST_BIN := $(TEST_SRC:tests/%.c=$(BUILD)/tests/%)
DEPS_OK  := $(BUILD)/.deps-ok


.PHONY: test-slurm test-kubernetes test-parallel test-launchers
.PHONY: all test asan tsan profile scenes clean deps reference bench bench-load bench-compare bench-packets bench-instances bench-build bench-render bench-helmet bench-denoise fuzz install uninstall test-install denoiser ggx-albedo-table
all: $(RT)

deps: $(DEPS_OK)
$(DEPS_OK): tools/install-deps.sh
	@mkdir -p $(BUILD)
	@CC="$(CC)" sh tools/install-deps.sh
	@touch $@

$(BUILD)/obj/%.o: src/%.c | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -c -o $@ $<

$(BUILD)/obj/%.o: src/%.cc | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -c -o $@ $<

# --window needs SDL2 (libsdl2-dev): window.c is built against it when
# pkg-config finds it at build time, else as stubs that say so; rt links it
# only then. Its headers come in as system headers (-isystem): their
# warnings are not ours.
SDL2_CFLAGS = $$(pkg-config --exists sdl2 2>/dev/null && echo -DRT_HAVE_SDL2 $$(pkg-config --cflags sdl2 | sed 's/-I/-isystem /g'))
SDL2_LIBS   = $$(pkg-config --exists sdl2 2>/dev/null && pkg-config --libs sdl2)

# (a stamp named for whether SDL2 is there rebuilds window.o when that changes)
SDL2_STAMP := $(BUILD)/.sdl2-$(shell pkg-config --exists sdl2 2>/dev/null && echo yes || echo no)
$(SDL2_STAMP):
	@mkdir -p $(BUILD)
	@rm -f $(BUILD)/.sdl2-*
	@touch $@

$(BUILD)/obj/driver/window.o: src/driver/window.c $(SDL2_STAMP) | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) $(SDL2_CFLAGS) -c -o $@ $<

$(BUILD)/librt.a: $(LIB_OBJ)
	@rm -f $@
	ar rcs $@ $^

$(RT): $(DRV_OBJ) $(BUILD)/librt.a
	$(CC) $(CFLAGS) -o $@ $^ $(LDLIBS) $(SDL2_LIBS)

$(BUILD)/tests/%: tests/%.c $(BUILD)/librt.a tests/test_util.h tests/test_scenes.h tests/test_fixture.h tests/test_bsdf_check.h tests/test_terminal.h | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests -o $@ $< $(BUILD)/librt.a $(LDLIBS) -lcmocka

# the corpus replay test links the fuzz harness too
$(BUILD)/tests/test_corpus: tests/test_corpus.c tests/fuzz/harness.c tests/fuzz/harness.h $(BUILD)/librt.a tests/test_util.h tests/test_scenes.h | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests -o $@ tests/test_corpus.c tests/fuzz/harness.c $(BUILD)/librt.a $(LDLIBS) -lcmocka

# rt compare's driver code is tested in-process
$(BUILD)/tests/test_compare: tests/test_compare.c src/driver/cmd_compare.c src/driver/commands.h $(BUILD)/librt.a tests/test_util.h tests/test_scenes.h | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests -o $@ tests/test_compare.c src/driver/cmd_compare.c $(BUILD)/librt.a $(LDLIBS) -lcmocka

# rt convert's driver code is tested in-process too
$(BUILD)/tests/test_hdr: tests/test_hdr.c src/driver/cmd_convert.c src/driver/commands.h $(BUILD)/librt.a tests/test_util.h tests/test_scenes.h | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -Itests -o $@ tests/test_hdr.c src/driver/cmd_convert.c $(BUILD)/librt.a $(LDLIBS) -lcmocka

# the kd-tree's portable path (no AVX2), tested on machines that have AVX2 too
TEST_BIN += $(BUILD)/tests/test_kdtree_scalar
# (the same tests with RT_KD_SCALAR: their trees are built with params.portable,
# so their rays take the portable traversal that librt.a has beside the AVX2 one)
$(BUILD)/tests/test_kdtree_scalar: tests/test_kdtree.c $(BUILD)/librt.a tests/test_util.h tests/test_scenes.h | $(DEPS_OK)
	@mkdir -p $(dir $@)
	$(CC) $(CFLAGS) -DRT_KD_SCALAR -Itests -o $@ tests/test_kdtree.c $(BUILD)/librt.a $(LDLIBS) -lcmocka

# --denoise loads Intel Open Image Denoise at run time (src/image/denoise.c);
# Debian has no package, so the pyoidn wheel (which ships the library and its
# CPU device) goes into a project-local virtual environment. --no-deps: only
# the shared libraries are used, not the Python binding's numpy.
OIDN_VENV   := build/oidn-venv
OIDN_WHEEL  := pyoidn==2.5.1.0
denoiser: $(OIDN_VENV)/.installed
$(OIDN_VENV)/.installed:
	@echo "rt: installing Intel Open Image Denoise ($(OIDN_WHEEL)) into $(OIDN_VENV)" >&2
	python3 -m venv $(OIDN_VENV)
	$(OIDN_VENV)/bin/pip install -q --no-deps $(OIDN_WHEEL)
	@touch $@

# A skipped test is listed by name; with RT_FAIL_ON_SKIP=1 (CI) any skip
# not in SKIPS_ALLOWED fails the run (tests/run.sh).
SKIPS_ALLOWED ?=
test: $(RT) $(TEST_BIN)
	@sh tools/check-stages.sh
	@sh tools/check-doc-paths.sh
	@RT_SHARED=$(SHARED) RT_BIN=./$(RT) RT_SKIPS_ALLOWED="$(SKIPS_ALLOWED)" sh tests/run.sh $(TEST_BIN)

# The tests a sanitizer build cannot run, and why (each skips saying so):
# the denoiser's (denoise.c refuses --denoise there: OIDN's TBB dlopens with
# RTLD_DEEPBIND, which ASan and TSan abort on) and the memory caps' (rt does
# not enforce --max-memory there; RLIMIT_DATA is below what the runtime
# reserves: test_memory_budget, test_memory_budget_makes_clean_errors and
# test_instance_reuse's instances over a budget), and the peak-memory one of
# test_outputs (the runtime's shadow memory is resident). Under
# RT_FAIL_ON_SKIP=1 any other skip fails make asan/tsan.
SANITIZER_SKIPS := test_denoise_cornell test_denoise_quality_and_threads test_denoise_keeps_noisy \
	test_memory_budget test_memory_budget_makes_clean_errors test_tiny_files_claiming_huge_images \
	test_cli_instances_over_budget

# Sanitizer builds live in their own directories so they never mix objects.
asan:
	$(MAKE) --no-print-directory BUILD=build-asan RT=build-asan/rt SKIPS_ALLOWED="$(SANITIZER_SKIPS)" \
		OPT="-O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all" test

tsan:
	$(MAKE) --no-print-directory BUILD=build-tsan RT=build-tsan/rt SKIPS_ALLOWED="$(SANITIZER_SKIPS)" \
		OPT="-O1 -g -fsanitize=thread" test

profile:
	$(MAKE) --no-print-directory BUILD=build-profile RT=rt-profile OPT="-O2 -march=native -g -fno-omit-frame-pointer"

bench/rtbench: bench/rtbench.c $(BUILD)/librt.a | $(DEPS_OK)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/librt.a $(LDLIBS)

# Ray throughput on the shared benchmark rays (../shared/bench), checked against Embree's hits.
bench: bench/rtbench
	@SHARED=$(SHARED) sh bench/run.sh

# rt and Embree side by side on the same rays, as ratios (installs Embree 3 on first use);
# then the packets on the same tiles (bench-packets).
bench-compare: bench/rtbench
	@SHARED=$(SHARED) sh bench/compare.sh
	@SHARED=$(SHARED) python3 bench/packets.py

# rt's 8- and 16-ray packets and Embree's rtcIntersect8/16 on the same 4x2 and 4x4 tiles of the primary sets.
bench-packets: bench/rtbench
	@SHARED=$(SHARED) python3 bench/packets.py

# rt's instanced kd-tree against the same scene flattened and against Embree 3's instances
# (RTC_GEOMETRY_TYPE_INSTANCE, same transforms, same rays; bench/instances.py and bench/embree_instances.c):
# single rays, packets, frustum tiles and streams, 1 and 2 threads, interleaved.
bench-instances: bench/rtbench
	@SHARED=$(SHARED) python3 bench/instances.py

# rt's path tracer against Mitsuba 3 on the shared Cornell box (sets up Mitsuba in build/mitsuba-venv
# and Debian's libllvm19 on first use); RT_BINS="./rt other/rt" compares rt builds too.
RT_BINS ?= ./$(RT)
bench-render: $(RT)
	@SHARED=$(SHARED) sh bench/render.sh $(RT_BINS)

# The path tracer's rays per second, shading included, on DamagedHelmet under an environment map and
# a sun (bench/helmet.sh; RUNS, THREADS, RES, SPP); RT_BINS="./rt other/rt" runs builds interleaved.
bench-helmet: $(RT)
	@SHARED=$(SHARED) sh bench/helmet.sh $(RT_BINS)

# Load-time goals the unit tests do not time (bench/load.sh): a 30000-material OBJ in under 2 s.
bench-load: $(RT)
	@RT=./$(RT) sh bench/load.sh

# The path tracer against the shared Mitsuba reference through rt compare (docs/path-tracer.md, section 6):
# SPP (default 64) samples at 512x512; fails when the RMSE is over what noise explains.
reference: $(RT)
	@SHARED=$(SHARED) RT=./$(RT) sh tools/reference.sh

# --denoise on the shared Cornell box: 4/16/64 spp denoised against raw 256 and 1024 spp (docs/hdr.md).
bench-denoise: $(RT) denoiser
	@SHARED=$(SHARED) sh bench/denoise.sh ./$(RT)

bench/buildscale: bench/buildscale.c $(BUILD)/librt.a | $(DEPS_OK)
	$(CC) $(CFLAGS) -o $@ $< $(BUILD)/librt.a $(LDLIBS)

# kd-tree build time from 10k to 2M triangles (the N log N check) and on the shared bench models.
bench-build: bench/buildscale
	@./bench/buildscale $$(sed -n 's#^| [A-Za-z0-9_]* | `\([^`]*\)`.*#$(SHARED)/\1#p' $(SHARED)/bench/MANIFEST.md 2>/dev/null)

# Regenerates the committed GGX albedo tables of the energy compensation
# (src/render/ggx_albedo_table.c for conductors,
# src/render/ggx_albedo_dielectric_table.c for rough glass) from
# tools/ggx_albedo.c; about 15 s of CPU each.
ggx-albedo-table:
	@mkdir -p $(BUILD)
	$(CC) -std=c11 -O2 -D_DEFAULT_SOURCE -o $(BUILD)/ggx_albedo tools/ggx_albedo.c -lm
	$(BUILD)/ggx_albedo > src/render/ggx_albedo_table.c.tmp && mv src/render/ggx_albedo_table.c.tmp src/render/ggx_albedo_table.c
	$(BUILD)/ggx_albedo dielectric > src/render/ggx_albedo_dielectric_table.c.tmp && \
	    mv src/render/ggx_albedo_dielectric_table.c.tmp src/render/ggx_albedo_dielectric_table.c

SCENES := $(wildcard scenes/*.txt)
scenes: $(RT)
	@mkdir -p docs/images
	@for s in $(SCENES); do n=$$(basename $$s .txt); echo "rendering $$s"; ./rt -q -o docs/images/$$n.png $$s || exit 1; done

# make install: the library is installed as librtrender.a (pkg-config module
# `rtrender`), a name that cannot be taken for the C library's librt.
PREFIX     ?= /usr/local
BINDIR     ?= $(PREFIX)/bin
LIBDIR     ?= $(PREFIX)/lib
INCLUDEDIR ?= $(PREFIX)/include
PCDIR      ?= $(LIBDIR)/pkgconfig
install: $(RT) $(BUILD)/librt.a
	install -d $(DESTDIR)$(BINDIR) $(DESTDIR)$(LIBDIR) $(DESTDIR)$(PCDIR) $(DESTDIR)$(INCLUDEDIR)
	install -m 755 $(RT) $(DESTDIR)$(BINDIR)/rt
	install -m 644 $(BUILD)/librt.a $(DESTDIR)$(LIBDIR)/librtrender.a
	cd include && find rt -name '*.h' -exec install -D -m 644 {} $(DESTDIR)$(INCLUDEDIR)/{} \;
	sed -e 's#@PREFIX@#$(PREFIX)#' -e 's#@LIBDIR@#$(LIBDIR)#' -e 's#@INCLUDEDIR@#$(INCLUDEDIR)#' \
		-e 's#@LIBS@#$(LDLIBS)#' tools/rtrender.pc.in > $(DESTDIR)$(PCDIR)/rtrender.pc

uninstall:
	rm -f $(DESTDIR)$(BINDIR)/rt $(DESTDIR)$(LIBDIR)/librtrender.a $(DESTDIR)$(PCDIR)/rtrender.pc
	rm -rf $(DESTDIR)$(INCLUDEDIR)/rt

# Installs into a temporary DESTDIR and builds examples/library.c against it
# through pkg-config, as a user of the library would (run by .ci/run).
test-install: $(RT) $(BUILD)/librt.a
	@CC="$(CC)" sh tests/install.sh

# The launchers of examples/ (docs/farm.md), not in `make test`: they install
# tools (slurm-wlm, parallel) and start daemons. Each renders a small scene
# through its launcher and checks the merged image against a single render.
test-slurm: $(RT)
	@RT_BIN=./$(RT) sh tests/slurm.sh
test-kubernetes: $(RT)
	@RT_BIN=./$(RT) sh tests/kubernetes.sh
test-parallel: $(RT)
	@RT_BIN=./$(RT) sh tests/parallel.sh
test-launchers: test-kubernetes test-parallel test-slurm

clean:
	rm -rf build build-asan build-tsan build-profile build-fuzz build-portable rt rt-portable rt-profile bench/rtbench bench/buildscale

-include $(LIB_OBJ:.o=.d) $(DRV_OBJ:.o=.d)

# libFuzzer over every parser (installs clang on first use); FUZZ_SECONDS per target (default 60).
fuzz:
	@SHARED=$(SHARED) sh tools/fuzz.sh
