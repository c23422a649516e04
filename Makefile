# pdt — parallel Delaunay triangulation and its step-by-step viewer.
#
# Targets
#   make            build bin/ (release) — pdt, pdtview
#   make test       install missing Debian packages, build release + sanitizer
#                   builds, run the whole suite (tests/run.sh)
#   make demo       install missing build packages (none: no apt-get), build,
#                   run the classroom demo
#   make lesson L=NN  record lesson NN (lessons/NN-*) and open the viewer on it
#                   (no display: render its key frames into build/lessons/NN);
#                   installs only missing build packages, like make demo
#   make bench      benchmarks against other tools (prints figures; no asserts)
#   make table1     the thesis' Table 1 (speedup) reproduced
#   make fuzz       build the libFuzzer targets (clang, bin/fuzz/) and run each
#                   for FUZZ_SECONDS; new crashes are kept in
#                   tests/fuzz/crashes/TARGET/ (make test replays them, and the
#                   seed corpus tests/fuzz/corpus/, without libFuzzer); the
#                   grown corpus stays in build/fuzz/corpus/ (tests/fuzz/run.sh)
#   make fuzz-seeds rewrite the binary trace seeds of tests/fuzz/corpus/
#   make install    install into $(DESTDIR)$(PREFIX) (see "install" below)
#   make uninstall  remove what make install put there
#   make smpi       install libsimgrid-dev if missing and build bin/smpi/pdt,
#                   the same program for SimGrid's SMPI (scripts/simulate.sh)
#   make simulate   simulated strong and weak scaling on a 1024-node cluster
#                   (scripts/simulate-scaling.sh; docs/simulation.md)
#   make simulate-picture  lesson 10's picture from its simulated table (gnuplot)
#   make deps       only install missing Debian packages
#   make clean
#
# Variables (override on the command line: make CC=clang OPT=-O3)
#   CC        C compiler                         (default: gcc)
#   OPT       optimisation flags, release build  (default: -O2 -g)
#   SAN       sanitizer flags, sanitizer build   (default: ASan + UBSan)
#   NP        ranks for demo runs                (default: 4)
#   SMPICC    SimGrid's compiler wrapper          (default: smpicc)
#   SIM_ARGS  arguments of make simulate (e.g. --sizes 1e6 --partition strips)
#   POINTS    your own point file for make demo / make lesson (default: the
#             bundled points; a lesson's checked facts hold for its own only)
#   VIEW      pdtview options for make demo / make lesson, e.g.
#             VIEW="--theme dark --font-scale 1.5" (pdtview --help)
#   TRACE=0   compile tracing out entirely (-DPDT_NO_TRACE)
#   PREFIX    install prefix                     (default: /usr/local)
#   DESTDIR   staging root for packaging         (default: empty)
#   FUZZ_SECONDS  time per fuzz target        (default: 60)
#   FUZZ_TARGETS  which fuzz targets to run   (default: all of them)
#   FUZZ_JOBS     targets fuzzed at once      (default: 1)
#
# Layout: build/rel/... and build/san/... hold objects; bin/ the release
# programs; bin/san/ the sanitizer programs; build/smpi/ and bin/smpi/pdt
# the simulated build (make smpi).  Sources are picked up by
# wildcard, one folder per module, each with its private header:
#   src/base    errors, clock, memory (bigmem), temporary files, checksums,
#               external sort, the option parser both programs use; public
#               headers include/pdt/{common,bigmem,tmpfile,checksum,xsort,
#               opts,exit}.h.  Everything below builds on it; it calls nothing.
#   src/geom    predicates, hull, kernel, checker, generators
#   src/io      point and triangle files
#   src/trace   the trace format: hook, writer, reader, checks, exports
#   src/par     the parallel driver: every file but comm_mpi.c goes into
#               libpdtpar.a, which unit tests link; the only code that
#               includes mpi.h is src/par/comm_mpi.c, linked into bin/pdt alone
#   src/cli     the pdt program
#   src/view    the viewer in three rooms: model/ (replay, kept index,
#               queries, synthetic and live runs; no cairo, no SDL:
#               libpdtmodel.a), render/ (cairo drawing and picture/animation
#               export: libpdtrender.a, and giflib for anim.c; FFmpeg's
#               libraries are opened with dlopen), app/ (the SDL2 program:
#               options, shell, editor, headless, bench: libpdtapp.a, and
#               pdtview.c's main; bin/pdtview also links libpdtpar.a for the
#               editor's live runs on simulated ranks).  Public headers of the viewer
#               are in include/pdt/view/.
# Unit tests named tests/unit/test_view*.c are compiled with the cairo/SDL
# flags and linked with the viewer's libraries.  Header dependencies are
# generated (-MMD -MP: build/VARIANT/**/*.d).
#
# Test hooks: the PDT_TEST_* fault-injection variables are read only by
# builds compiled with -DPDT_TEST_HOOKS (src/base/testhook.c): the
# sanitizer build and bin/test/pdt (the release objects linked with the
# hooked testhook.o), which the shell tests that inject faults run.  The
# release bin/pdt never reads them.

CC      ?= gcc
ifeq ($(origin CC),default)
CC      := gcc
endif
OPT     ?= -O2 -g
SAN     ?= -O1 -g -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined
NP      ?= 4
TRACE   ?= 1

WARN    := -Wall -Wextra -Wshadow -Wconversion -Wno-sign-conversion -Wstrict-prototypes \
           -Wmissing-prototypes -Wformat=2 -Wvla
CSTD    := -std=c17 -D_GNU_SOURCE
ifeq ($(TRACE),0)
CSTD    += -DPDT_NO_TRACE
endif
INC     := -Iinclude

MPI_CFLAGS  := $(shell pkg-config --cflags ompi-c 2>/dev/null)
MPI_LIBS    := $(shell pkg-config --libs ompi-c 2>/dev/null)
VIEW_CFLAGS := $(shell pkg-config --cflags cairo sdl2 2>/dev/null)
CAIRO_LIBS  := $(shell pkg-config --libs cairo 2>/dev/null)
SDL_LIBS    := $(shell pkg-config --libs sdl2 2>/dev/null)
# animation export (src/view/render/anim.c): giflib (no pkg-config file on Debian
# 12) is linked; FFmpeg's libraries are opened with dlopen when a video is
# written (their codec libraries' start-up code is more than valgrind runs)
AV_PKGS     := libavformat libavcodec libswscale libavutil
VIEW_CFLAGS += $(shell pkg-config --cflags $(AV_PKGS) 2>/dev/null)
ANIM_LIBS   := -lgif -ldl
OTF2_LIBS   := $(shell pkg-config --libs otf2 2>/dev/null || echo -lopen-trace-format2)
LIBS        := -lm -pthread

# Debian packages the build, the tests and the demo need.
DEB_BUILD := build-essential pkg-config libopenmpi-dev openmpi-bin libsdl2-dev libcairo2-dev fonts-dejavu-core \
             libgif-dev libavcodec-dev libavformat-dev libswscale-dev libavutil-dev libopen-trace-format2-dev
DEB_SMPI  := libsimgrid-dev
DEB_PLOT  := gnuplot-nox
DEB_TEST  := $(DEB_SMPI) time otf2-tools mandoc bash-completion qhull-bin xvfb xdotool x11-apps imagemagick poppler-utils librsvg2-bin python3 valgrind libxml2-utils procps slurmctld slurmd slurm-client munge ffmpeg openbox
DEB_BENCH := hyperfine libcgal-dev g++ nodejs npm valgrind time
DEB_FUZZ  := clang libclang-rt-dev

# the comm front and its local (threads) backend need no MPI: in libpdt.a
COMM_SRC := src/par/comm.c src/par/comm_local.c src/par/comm_hops.c
LIB_SRC  := $(wildcard src/base/*.c src/geom/*.c src/io/*.c src/trace/*.c) $(COMM_SRC)
PAR_SRC  := $(filter-out $(COMM_SRC) src/par/comm_mpi.c,$(wildcard src/par/*.c))
CLI_SRC  := $(wildcard src/cli/*.c)
MODEL_SRC  := $(wildcard src/view/model/*.c)
RENDER_SRC := $(wildcard src/view/render/*.c)
APP_SRC  := $(filter-out src/view/app/pdtview.c,$(wildcard src/view/app/*.c))
UNIT_SRC := $(wildcard tests/unit/*.c)

# ---- one build variant: $(call variant,NAME,FLAGS,BINDIR) -------------------
define variant
$(1)_OBJ := build/$(1)
$(1)_LIB := build/$(1)/libpdt.a
$(1)_PARLIB := build/$(1)/libpdtpar.a

build/$(1)/%.o: %.c | build/$(1)/.dirs
	@mkdir -p $$(dir $$@)
	$$(CC) $(CSTD) $(2) $(WARN) $(INC) -MMD -MP $$(if $$(findstring src/par/comm_mpi,$$<),$(MPI_CFLAGS)) $$(if $$(findstring /view/render/,$$<)$$(findstring /view/app/,$$<),$(VIEW_CFLAGS)) $$(if $$(findstring tests/unit/test_view,$$<),$(VIEW_CFLAGS)) -c $$< -o $$@

# the test hooks' reader, compiled to read them (linked ahead of libpdt.a
# into the programs and tests that inject faults)
build/$(1)/hooks/testhook.o: src/base/testhook.c | build/$(1)/.dirs
	@mkdir -p $$(dir $$@)
	$$(CC) $(CSTD) $(2) $(WARN) $(INC) -MMD -MP -DPDT_TEST_HOOKS -c $$< -o $$@

build/$(1)/.dirs:
	@mkdir -p build/$(1) $(3)
	@touch $$@

build/$(1)/libpdt.a: $$(patsubst %.c,build/$(1)/%.o,$(LIB_SRC))
	@rm -f $$@
	ar rcs $$@ $$^

build/$(1)/libpdtpar.a: $$(patsubst %.c,build/$(1)/%.o,$(PAR_SRC))
	@rm -f $$@
	ar rcs $$@ $$^

build/$(1)/libpdtmodel.a: $$(patsubst %.c,build/$(1)/%.o,$(MODEL_SRC))
	@rm -f $$@
	ar rcs $$@ $$^

build/$(1)/libpdtrender.a: $$(patsubst %.c,build/$(1)/%.o,$(RENDER_SRC))
	@rm -f $$@
	ar rcs $$@ $$^

build/$(1)/libpdtapp.a: $$(patsubst %.c,build/$(1)/%.o,$(APP_SRC))
	@rm -f $$@
	ar rcs $$@ $$^

$(3)/pdt: $$(patsubst %.c,build/$(1)/%.o,$(CLI_SRC) src/par/comm_mpi.c) $(4) build/$(1)/libpdtpar.a build/$(1)/libpdt.a
	$$(CC) $(2) -o $$@ $$^ $(MPI_LIBS) $(OTF2_LIBS) $(LIBS)

$(3)/test/pdt: $$(patsubst %.c,build/$(1)/%.o,$(CLI_SRC) src/par/comm_mpi.c) build/$(1)/hooks/testhook.o build/$(1)/libpdtpar.a build/$(1)/libpdt.a
	@mkdir -p $$(dir $$@)
	$$(CC) $(2) -o $$@ $$^ $(MPI_LIBS) $(OTF2_LIBS) $(LIBS)

$(3)/pdtview: build/$(1)/src/view/app/pdtview.o $(4) build/$(1)/libpdtapp.a build/$(1)/libpdtrender.a build/$(1)/libpdtmodel.a build/$(1)/libpdtpar.a build/$(1)/libpdt.a
	$$(CC) $(2) -o $$@ $$^ $(SDL_LIBS) $(CAIRO_LIBS) $(ANIM_LIBS) $(LIBS)

$(3)/tests/%: build/$(1)/tests/unit/%.o build/$(1)/hooks/testhook.o build/$(1)/libpdtapp.a build/$(1)/libpdtrender.a build/$(1)/libpdtmodel.a build/$(1)/libpdtpar.a build/$(1)/libpdt.a
	@mkdir -p $$(dir $$@)
	$$(CC) $(2) -o $$@ $$^ $(CAIRO_LIBS) $(ANIM_LIBS) $(LIBS)

$(1)-all: $(3)/pdt $(3)/test/pdt $(3)/pdtview $(patsubst tests/unit/%.c,$(3)/tests/%,$(UNIT_SRC))

-include $$(shell find build/$(1) -name '*.d' 2>/dev/null)
endef

# variant NAME, flags, programs' folder, what the programs link ahead of
# libpdt.a (the sanitizer build is a test build: its programs read the hooks)
$(eval $(call variant,rel,$(OPT),bin,))
$(eval $(call variant,san,$(SAN),bin/san,build/san/hooks/testhook.o))

.PHONY: all deps deps-bench deps-fuzz deps-lesson test demo lesson bench table1 clean rel-all san-all fuzz fuzz-build fuzz-seeds \
        smpi smpi-build simulate simulate-picture
.DEFAULT_GOAL := all

all: rel-all

# Install whatever Debian packages are missing (apt-get update once, then
# install).  Needs root; does nothing when everything is present.
deps:
	@scripts/deps.sh $(DEB_BUILD) $(DEB_TEST)

# what make lesson / make demo need: the build, and python3 for the lesson
# checks (no test tools: nothing is installed when these are present)
deps-lesson:
	@scripts/deps.sh $(DEB_BUILD) python3

deps-bench:
	@scripts/deps.sh $(DEB_BUILD) $(DEB_TEST) $(DEB_BENCH)

test: deps
	$(MAKE) -j2 rel-all san-all smpi-build
	tests/run.sh

demo: deps-lesson
	$(MAKE) rel-all
	scripts/demo.sh $(if $(VIEW),--view '$(VIEW)') $(if $(POINTS),$(abspath $(POINTS)))

lesson: deps-lesson
	@test -n "$(L)" || { echo "usage: make lesson L=NN   (lessons: $(notdir $(wildcard lessons/[0-9]*)))"; exit 2; }
	$(MAKE) rel-all
	scripts/lesson.sh $(if $(VIEW),--view '$(VIEW)') $(if $(POINTS),--points $(abspath $(POINTS))) $(L)

bench: deps-bench
	$(MAKE) rel-all
	scripts/bench.sh

table1: deps-bench
	$(MAKE) rel-all
	scripts/table1.sh

# ---- the simulated build (SimGrid's SMPI) ------------------------------------
# bin/smpi/pdt is the same program for smpirun: smpicc links a shared object
# that SimGrid's loader copies once per rank (each rank gets its own globals),
# so every object is position independent, and comm_mpi.c alone is compiled
# by smpicc (SMPI's mpi.h; PDT_SMPI selects the few calls that differ there).
# No debug information: the object is copied P times into the temporary folder.
SMPICC    ?= smpicc
SMPI_OPT  := $(filter-out -g,$(OPT)) -fPIC
SMPI_OBJ  := $(patsubst %.c,build/smpi/%.o,$(LIB_SRC) $(PAR_SRC) $(CLI_SRC) src/par/comm_mpi.c)

build/smpi/%.o: %.c $(wildcard include/pdt/*.h src/*/*.h)
	@mkdir -p $(dir $@)
	$(CC) $(CSTD) $(SMPI_OPT) $(WARN) $(INC) -c $< -o $@

build/smpi/src/par/comm_mpi.o: src/par/comm_mpi.c $(wildcard include/pdt/*.h src/*/*.h)
	@mkdir -p $(dir $@)
	$(SMPICC) $(CSTD) $(SMPI_OPT) $(WARN) $(INC) -DPDT_SMPI=1 -c $< -o $@

bin/smpi/pdt: $(SMPI_OBJ)
	@mkdir -p $(dir $@)
	$(SMPICC) $(SMPI_OPT) -o $@ $^ $(OTF2_LIBS) $(LIBS)

deps-smpi:
	@scripts/deps.sh $(DEB_SMPI)

smpi-build: bin/smpi/pdt

smpi: deps-smpi
	$(MAKE) smpi-build

simulate: deps-smpi
	$(MAKE) rel-all smpi-build
	scripts/simulate-scaling.sh $(SIM_ARGS)

# lesson 10's picture from its table (a make simulate table of one size)
simulate-picture:
	@scripts/deps.sh $(DEB_PLOT)
	scripts/plot-phases.sh lessons/10-speedup/simulated-1e6.md lessons/10-speedup/phases-1e6.png

# ---- fuzzing (clang + libFuzzer; see tests/fuzz/fuzz_common.h) ----------------
FUZZ_CC      ?= clang
FUZZ_SECONDS ?= 60
FUZZ_JOBS    ?= 1
FUZZ_TARGETS ?= points_text points_node tris manifest trace_rank trace_run
FUZZ_FLAGS   := -g -O1 -fno-omit-frame-pointer -fsanitize=address,undefined \
                -fno-sanitize-recover=undefined

build/fuzz/%.o: %.c
	@mkdir -p $(dir $@)
	$(FUZZ_CC) $(CSTD) $(FUZZ_FLAGS) -fsanitize=fuzzer-no-link $(INC) -MMD -MP -c $< -o $@

-include $(shell find build/fuzz -name '*.d' 2>/dev/null)

build/fuzz/libpdt.a: $(patsubst %.c,build/fuzz/%.o,$(LIB_SRC))
	@rm -f $@
	ar rcs $@ $^

bin/fuzz/fuzz_%: tests/fuzz/fuzz_main.c $(wildcard tests/fuzz/*.c tests/fuzz/*.h) build/fuzz/libpdt.a
	@mkdir -p bin/fuzz
	$(FUZZ_CC) $(CSTD) $(FUZZ_FLAGS) -fsanitize=fuzzer $(INC) -DFUZZ_FN=fuzz_$* \
	    tests/fuzz/fuzz_main.c build/fuzz/libpdt.a $(LIBS) -o $@

fuzz-build: $(patsubst %,bin/fuzz/fuzz_%,$(FUZZ_TARGETS))

deps-fuzz:
	@scripts/deps.sh $(DEB_BUILD) $(DEB_FUZZ)

fuzz: deps-fuzz
	$(MAKE) fuzz-build
	FUZZ_SECONDS=$(FUZZ_SECONDS) FUZZ_JOBS=$(FUZZ_JOBS) tests/fuzz/run.sh $(FUZZ_TARGETS)

build/fuzz-seeds/make_seeds: tests/fuzz/make_seeds.c build/rel/libpdt.a
	@mkdir -p $(dir $@)
	$(CC) $(CSTD) $(OPT) $(WARN) $(INC) $< build/rel/libpdt.a $(LIBS) -o $@

fuzz-seeds: build/fuzz-seeds/make_seeds
	rm -rf build/fuzz-seeds/tmp && mkdir -p build/fuzz-seeds/tmp
	build/fuzz-seeds/make_seeds build/fuzz-seeds/tmp tests/fuzz/corpus

clean:
	rm -rf build bin

# ---- install / uninstall ------------------------------------------------------
# make install [PREFIX=/usr/local] [DESTDIR=/staging] puts
#   PREFIX/bin/pdt, pdtview, pdt-lesson (scripts/lesson.sh: finds its lessons
#       in ../share/pdt beside itself, or in $PDT_DATADIR)
#   PREFIX/share/pdt/lessons/, assets/, lesson-check.py
#   PREFIX/share/man/man1/pdt.1, pdtview.1 (mdoc; `mandoc -T lint` in make test)
#   PREFIX/share/bash-completion/completions/pdt, pdtview
# pdtview reads no data files (fonts come from fontconfig).  Nothing in the
# installed tree refers to the checkout, so it works with the checkout gone.
PREFIX  ?= /usr/local
DESTDIR ?=
I_BIN   := $(DESTDIR)$(PREFIX)/bin
I_DATA  := $(DESTDIR)$(PREFIX)/share/pdt
I_MAN   := $(DESTDIR)$(PREFIX)/share/man/man1
I_COMP  := $(DESTDIR)$(PREFIX)/share/bash-completion/completions

.PHONY: install uninstall
install: rel-all
	install -d $(I_BIN) $(I_DATA) $(I_MAN) $(I_COMP)
	install -m 755 bin/pdt bin/pdtview $(I_BIN)/
	install -m 755 scripts/lesson.sh $(I_BIN)/pdt-lesson
	rm -rf $(I_DATA)/lessons $(I_DATA)/assets
	cp -R lessons assets $(I_DATA)/
	install -m 644 scripts/lesson-check.py $(I_DATA)/
	install -m 644 man/pdt.1 man/pdtview.1 $(I_MAN)/
	install -m 644 completions/pdt completions/pdtview $(I_COMP)/

uninstall:
	rm -f $(I_BIN)/pdt $(I_BIN)/pdtview $(I_BIN)/pdt-lesson
	rm -rf $(I_DATA)
	rm -f $(I_MAN)/pdt.1 $(I_MAN)/pdtview.1
	rm -f $(I_COMP)/pdt $(I_COMP)/pdtview
