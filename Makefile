# Parallel Ray Tracer Labs. `make help` lists the targets.
#
# Every lab binary links the shared renderer in common/. Objects go to build/.
# CI sets CI=true, which turns warnings into errors for our own code.

CXX      ?= g++
PYTHON   ?= python3
BUILD    := build
# -ffp-contract=off: no fused multiply-add behind our back, so every CPU lab computes each
# path with the same roundings and the serial, OpenMP and MPI images match bit for bit.
OPT      := -O3 -march=native -ffp-contract=off -fno-math-errno -fno-trapping-math
WARN     := -Wall -Wextra -Wpedantic -Wshadow
ifeq ($(CI),true)
WARN     += -Werror
endif
CXXFLAGS := -std=c++17 $(OPT) $(WARN) -MMD -MP
# The source tree's location is compiled into one file (cli.cpp's source_tree_path: the default
# scene, the unit tests' scenes), in every build folder, so that every other object is the same
# wherever a copy of the tree lies (a release or a copy the tests make reuses them through ccache).
%/common/host/cli.o: CXXFLAGS += -DRT_SOURCE_DIR='"$(CURDIR)"'
# common/ in three layers: core/ (the scalar renderer, host and device), host/ (the driver),
# simd/ (lab 02's AVX2 library, only for the builds that put it on the include path). Shared
# headers include each other with <...>, so a folder earlier on the include path (a lab's
# skeleton, a variant, a test's mutant) stands in for any of them.
INCLUDES      := -Icommon/core -Icommon/host
SIMD_INCLUDES := -Icommon/simd $(INCLUDES)
# The SIMD library (x86-64 only; labs 02-04's lab.mk use it): its 8-lane object is built with
# AVX2, its 16-lane one with AVX-512, and the choice between them (packet_renderer.o) with
# neither, so a binary runs on any CPU with AVX2 and uses AVX-512 where the CPU has it
# (common/simd/packet_renderer.h). SIMD_OBJ goes last on a link line, the AVX-512 object
# last of all: where that object and another both define an inline function out of line
# (std::string's, say), the linker keeps the first definition, so code that runs on an
# AVX2-only CPU never calls a copy compiled with AVX-512.
SIMD_AVX2_FLAGS   := -mavx2 -mfma
SIMD_AVX512_FLAGS := -mavx512f -mavx512dq -mavx512vl -mavx512bw -mavx2 -mfma
SIMD_OBJ := $(BUILD)/common/simd/packet_renderer.o $(BUILD)/common/simd/packets_avx2.o \
            $(BUILD)/common/simd/packets_avx512.o
$(BUILD)/common/simd/%.o: LAB_INCLUDES = -Icommon/simd
$(BUILD)/common/simd/packets_avx2.o: CXXFLAGS += $(SIMD_AVX2_FLAGS)
$(BUILD)/common/simd/packets_avx512.o: CXXFLAGS += $(SIMD_AVX512_FLAGS)

# The library part of common/host (what unit tests link) and the driver every lab binary adds.
LIB_SRC    := common/host/scene_loader.cpp common/host/json_with_positions.cpp common/host/image.cpp common/host/cli.cpp \
              common/host/progress.cpp common/host/interrupt_cleanup.cpp \
              common/host/scene_centring.cpp common/host/scene_report.cpp \
              common/host/scene_limits.cpp common/host/double_twin.cpp \
              common/host/t_junctions.cpp common/host/scene_schema.cpp
LIB_OBJ    := $(LIB_SRC:%.cpp=$(BUILD)/%.o)
DRIVER_OBJ := $(BUILD)/common/host/lab_main.o $(BUILD)/common/host/main.o
COMMON_OBJ := $(LIB_OBJ) $(DRIVER_OBJ)

# The double build (common/core/real.h): the same sources with -DRT_DOUBLE, every object in
# build/double/ (a float object and a double one must never be linked together: Vec3 differs).
# Offered for lab 01 and the GPU megakernel (lab05-ref-double, labs/05-cuda-mega/lab.mk);
# labs 02-04 use lab 02's 8-wide float AVX2 code and have no double build.
DOUBLE_BUILD      := $(BUILD)/double
DOUBLE_LIB_OBJ    := $(LIB_OBJ:$(BUILD)/%=$(DOUBLE_BUILD)/%)
DOUBLE_COMMON_OBJ := $(COMMON_OBJ:$(BUILD)/%=$(DOUBLE_BUILD)/%)

# A lab binary is a real file that make leaves alone while it is up to date, and is linked
# into a private file renamed over it: a grader running ./lab01-ref while another process
# relinks it runs the old binary or the new one, never a half-written one ("Permission
# denied", "Text file busy"). A link rule ends with $(INTO_TARGET) in place of -o $@.
INTO_TARGET = -o $@.partial-$$$$ && mv -f $@.partial-$$$$ $@

PHONY_EXTRA := variant
PHONY_EXTRA += render grade handin check-nvcc bench-micro bench-cpu bench-serial count-work bench-precision
PHONY_EXTRA += bench-simd bench-openmp bench-mpi extremes-report
PHONY_EXTRA += lint format gpu-figures
.PHONY: all help deps labs $(PHONY_EXTRA) test test-quick test-unit test-labs skeletons check-skeletons golden bench tradeoff \
        clean
.DEFAULT_GOAL := help

# The staff section only where its targets work: the course repository, not a release (which
# has no grading/releases/release.py, no solutions to build every lab from).
help: help-students $(if $(wildcard grading/releases/release.py),help-staff)
.PHONY: help-students help-staff
help-students:
	@echo "For students"
	@echo "  make labNN        build your code for lab NN (labs/NN-name/skeleton) into ./labNN"
	@echo "  make labNN-ref    lab NN's reference solution into ./labNN-ref"
	@echo "  make grade        grade your code (LAB=NN: which lab): score table and results.json"
	@echo "  make handin       handin-labNN.zip of your lab's files, for Gradescope (LAB=NN)"
	@echo "  make render       render the default scene to cornell.ppm with the fastest"
	@echo "                    reference here (GPU, else OpenMP+AVX2)"
	@echo "  make test         the unit tests of common/ and the lab tests"
	@echo "  make test-quick   a few minutes' check: lint, the unit tests and the fast pytest files"
	@echo "  make deps         install what is missing (JSON library, OpenMPI, tools/requirements.txt)"
	@echo "  make bench-serial time the lab-01 reference on the Cornell baseline (minutes)"
	@echo "  make bench-cpu    the CPU labs side by side with load and capacity (Table 4 here)"
	@echo "  make bench-simd   lab 02's variants against lab01-ref on one core (BENCH_ARGS=--full)"
	@echo "  make bench-openmp lab 03's schedules x threads and the shared-RNG rows (minutes)"
	@echo "  make bench-mpi    lab 04's distributions x ranks against lab01-ref (minutes)"
	@echo "  make tradeoff     speed against accuracy: error vs time of every lab here, bias vs"
	@echo "                    bounces, fast math, ray offsets (QUICK=1: CI size; PLOTS=0: no plots)"
	@echo "  make lab05-bench  the lab-05 kernel shapes the handout measures (needs a GPU)"
	@echo "  make kernel-report registers, spills, stack and shared memory of every CUDA kernel"
	@echo "                    (needs nvcc, no GPU: your own kernels where the solution is not here)"
	@echo "  make grade-gpu    no GPU here: grade LAB on the course's GPU machines (Slurm, from"
	@echo "                    the course's login node); make run-gpu RUN='./lab05 ...' runs one"
	@echo "                    labs: $(LAB_BINARIES)"
help-staff:
	@echo "For course staff"
	@echo "  make release LAB=NN OUT=DIR  the student repository for lab NN (grading/README.md)"
	@echo "  make gradescope LAB=NN       the Gradescope autograder zip for lab NN, in build/"
	@echo "  make grade-batch LAB=NN SUBMISSIONS=DIR [REPORT=DIR]  grade a class: one folder"
	@echo "                    or hand-in zip per student, or Gradescope's export as it comes;"
	@echo "                    grades.csv and report.html in REPORT (ONLY=flagged: regrade those)"
	@echo "  make grade-slurm LAB=NN SUBMISSIONS=DIR [REPORT=DIR]  the same as a Slurm job array"
	@echo "  make bench        the report's Tables 4-7 here: every lab, baseline + 3 sweeps"
	@echo "                    (QUICK=1: CI size; SCALE=K: sides / K; full: ~25 min a round, 2 cores)"
	@echo "  make bench-micro  Google Benchmark of the inner loops (closest hit, shadow ray, path)"
	@echo "  make count-work   instructions per camera path, split by query (needs valgrind)"
	@echo "  make lab01-ref-double  lab 01's reference in double (lab05-ref-double: GPU)"
	@echo "  make bench-precision  float against double: time and error of lab 01's reference"
	@echo "  make extremes-report  the extreme scenes in float and double (docs/extremes.md's table)"
	@echo "  make check-nvcc   compile every header of common/core for the GPU (needs nvcc)"
	@echo "  make gpu-figures  the handouts' GPU tables from the records in reference/gpu/ (CHECK=1: compare)"
	@echo "  make gpu-check OUT=DIR  on a GPU machine: build, test and benchmark the CUDA labs"
	@echo "  make tradeoff-gpu OUT=DIR  on a GPU machine: make tradeoff's GPU rows (no plots)"
	@echo "  make golden       regenerate the golden images in reference/ (minutes)"
	@echo "  make skeletons    regenerate the skeletons from the solutions (check-skeletons: check)"
	@echo "  make lint         ruff on the Python and its layers, clang-format --dry-run on the C++/CUDA (make test runs it)"
	@echo "  make format       apply clang-format and ruff's fixes, then regenerate the skeletons"
	@echo "  make labs         every binary of the course (needs the solutions)"
	@echo "  make clean        remove build products"

deps:
	@bash tools/install_deps.sh

# LAB_INCLUDES: a lab's own folder, set per object below, first on the include path.
$(BUILD)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(LAB_INCLUDES) $(INCLUDES) -c $< -o $@
$(DOUBLE_BUILD)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_DOUBLE $(LAB_INCLUDES) $(INCLUDES) -c $< -o $@

# ---- labs -------------------------------------------------------------------------------
# lab01 builds labs/01-serial/skeleton, lab01-ref builds labs/01-serial/solution. Each
# folder comes first on the include path of its own objects, so the skeleton's copy of a
# shared header (lab 01's path_steps.h) stands in for common/'s.
define cpu_lab
$(BUILD)/labs/$(2)/skeleton/%.o: LAB_INCLUDES = -Ilabs/$(2)/skeleton
$(BUILD)/labs/$(2)/solution/%.o: LAB_INCLUDES = -Ilabs/$(2)/solution
$(1): $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard labs/$(2)/skeleton/*.cpp)) $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $$^ $(3) $$(INTO_TARGET)
$(1)-ref: $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard labs/$(2)/solution/*.cpp)) $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $$^ $(3) $$(INTO_TARGET)
endef

# The labs are declared once, in labs/labs.toml (DESIGN.md section 2); build/labs.mk is what
# make knows of it (LABS, GPU_LABS, LAB_FOLDER_NN, LAB_KIND_NN, REGISTERED_TARGETS, ...),
# written by labkit/registry.py and rewritten, then read again, whenever the registry changes.
$(BUILD)/labs.mk: labs/labs.toml labkit/registry.py
	@mkdir -p $(dir $@)
	@$(PYTHON) -m labkit.registry make > $@.partial || { rm -f $@.partial; exit 2; }
	@mv $@.partial $@
include $(BUILD)/labs.mk

# Each registered lab's own rules (how its binaries are built, extra flags) live in
# labs/NN-name/lab.mk; which binaries a lab has is the registry's (LAB_TARGETS_NN). A lab.mk
# whose tools are missing here (nvcc, OpenMPI, an x86-64 compiler) gives its targets a rule
# that says so and adds them to UNBUILDABLE, which `make labs` leaves out.
# cuda.mk (nvcc, the cuda_lab rule) comes first: the CUDA labs' lab.mk files use it.
UNBUILDABLE :=
include cuda.mk
include $(foreach n,$(LABS),labs/$(LAB_FOLDER_$(n))/lab.mk)
include grading/grading.mk

# Lab 01's reference in double, with the same scene files and command line (--json says
# "precision": "double"). A real file, not phony: lab01-ref carries it (below).
$(DOUBLE_BUILD)/labs/01-serial/solution/%.o: LAB_INCLUDES = -Ilabs/01-serial/solution
lab01-ref-double: $(patsubst %.cpp,$(DOUBLE_BUILD)/%.o,$(wildcard labs/01-serial/solution/*.cpp)) \
                  $(DOUBLE_COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ $(INTO_TARGET)

# A reference renders in double what float cannot place (common/host/double_twin.h): it links
# build/twins/X.o, which carries the double binary X as data. Each lab's lab.mk names its
# references' twins (lab01-ref here, lab03-ref and lab03-simd-ref, lab05-ref).
$(BUILD)/twins/%.o: % common/host/double_twin.S
	@mkdir -p $(dir $@)
	$(CXX) -c -x assembler-with-cpp -DTWIN_PATH='"$<"' common/host/double_twin.S -o $@
lab01-ref: $(BUILD)/twins/lab01-ref-double.o

LAB_BINARIES := $(filter-out $(UNBUILDABLE),$(REGISTERED_TARGETS))
labs: $(LAB_BINARIES)

# ---- tests ------------------------------------------------------------------------------
UNIT_SRC := $(wildcard tests/unit/*.cpp)
UNIT_OBJ := $(UNIT_SRC:%.cpp=$(BUILD)/%.o)

$(BUILD)/unit_tests: $(UNIT_OBJ) $(LIB_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@ -lgtest -lgtest_main -pthread

# The unit tests that show the double build computes in double (tests/precision/), and the
# unit tests written in `real` that the double build must pass too (placement, T-junctions).
$(BUILD)/precision_tests_double: $(DOUBLE_BUILD)/tests/precision/test_double.o \
                                 $(DOUBLE_BUILD)/tests/unit/test_scene_placement.o \
                                 $(DOUBLE_BUILD)/tests/unit/test_t_junctions.o $(DOUBLE_LIB_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@ -lgtest -lgtest_main -pthread

# The test targets build on every core (PARALLEL) unless make already runs jobs in parallel
# (make -jN test); pytest gets no jobserver to inherit, which the makes its tests run could not
# reach (Python closes the descriptors) and would warn about.
JOBS     := $(shell nproc 2>/dev/null || echo 1)
PARALLEL  = $(if $(findstring jobserver,$(MAKEFLAGS)),,-j$(JOBS))
# The tests compile the same sources many times over: the repository, then each release, copy
# of the repository and students' tree they make. So the test targets compile through ccache
# where it is installed (make deps installs it): its compiler links first on PATH, its cache in
# build/ccache (make clean removes it), or the one CCACHE_DIR names already (the tests' own
# `make test` in a release they made: the release then finds what the course repository
# compiled); nvcc through it too (NVCC, which the Makefile's `?=` takes; without the working
# folder in the key, the copies elsewhere find what it compiled).
# Only what the tests start sees it; the grader's sandbox builds a hand-in with a PATH and an
# nvcc of its own, never through a cache a run could write.
CCACHE_LINKS := $(wildcard /usr/lib/ccache)
TEST_ENV := $(if $(CCACHE_LINKS),PATH="$(CCACHE_LINKS):$$PATH" CCACHE_DIR="$${CCACHE_DIR:-$(CURDIR)/$(BUILD)/ccache}" \
    CCACHE_NOHASHDIR=1 $(if $(shell command -v nvcc),NVCC="ccache nvcc"))
test-unit:
	@$(TEST_ENV) $(MAKE) --no-print-directory $(PARALLEL) $(BUILD)/unit_tests
	$(BUILD)/unit_tests --gtest_brief=1

# With pytest-xdist (make deps) on a machine of several cores, the tests run on every core, a
# test file to a process (a group: tests/conftest.py), all but those marked `timed` (they
# measure speedups and the machine's capacity, so they need the cores to themselves), which run
# after, alone (a pass that finds no test of its kind, as in a release that has none, passes).
XDIST := $(shell [ $(JOBS) -gt 1 ] && $(PYTHON) -c 'import xdist' 2>/dev/null && echo yes)
PYTEST_PASSES := $(if $(XDIST),"-n $(JOBS) -m 'not timed'" "-m timed","")
test-labs:
	@$(TEST_ENV) $(MAKE) --no-print-directory $(PARALLEL) labs
	@for pass in $(PYTEST_PASSES); do \
	    echo "$(PYTHON) -m pytest -q $$pass tests"; \
	    $(TEST_ENV) MAKEFLAGS='$(filter-out -j% --jobserver%,$(MAKEFLAGS))' \
	        sh -c "$(PYTHON) -m pytest -q $$pass tests" || [ $$? -eq 5 ] || exit 1; \
	done

# The quick tier, beside the full make test: the style, the unit tests and the pytest files
# that run in seconds and build at most lab 01 (the registry, the layout of the kit, the
# handouts' tables and GPU figures, DESIGN.md's scene-file table, the image comparison's
# statistics, the speed credit, the hand-in, lab 01's own tests); not the image-comparison
# suites of every lab, the grader's sandbox and hostile submissions, the releases or the
# benchmarks, which make test runs.
QUICK_TESTS := tests/tools/test_registry.py tests/tools/test_python_layout.py \
               tests/tools/test_gpu_report.py tests/tools/test_gpu_figures.py \
               tests/grading/test_handout_tables.py tests/grading/test_speed_credit.py \
               tests/grading/test_handin.py tests/grading/test_golden_sums.py \
               tests/grading/test_compare.py tests/grading/test_symptoms.py \
               tests/labs/test_lab01.py tests/labs/test_scene_report.py \
               tests/tools/test_scene_schema.py
test-quick:
	$(if $(wildcard .clang-format),$(MAKE) --no-print-directory lint)
	$(MAKE) --no-print-directory test-unit
	$(TEST_ENV) $(PYTHON) -m pytest -q $(QUICK_TESTS)

# Every test: installs what is missing first, so it works on a fresh machine; the style first,
# where the style is configured (the course repository: a student release ships no style rules,
# and a student's formatting is theirs).
test: deps
	$(if $(wildcard .clang-format),$(MAKE) --no-print-directory lint)
	$(MAKE) --no-print-directory test-unit
	$(MAKE) --no-print-directory test-labs

# Render the default scene (the Cornell baseline) with the fastest reference this machine can
# run, saying which and how long it took (tools/render.sh).
render: deps
	@MAKE="$(MAKE)" bash tools/render.sh

skeletons:
	$(PYTHON) -m labkit.skeletons

# Style: ruff (pyproject.toml) on the Python, clang-format (.clang-format) on every tracked
# C++/CUDA file, both at the versions of tools/requirements.txt (make deps); and the Python's
# layers (tests/tools/test_python_layout.py: which package imports which, the grader's floors
# and its top's size; files read only, a second or two). The skeletons are
# generated from the solutions, so make format regenerates them after formatting.
CLANG_FORMAT ?= $(PYTHON) -c 'import clang_format; clang_format.clang_format()'
CXX_SOURCES = $(shell git ls-files '*.cpp' '*.h' '*.cu' '*.cuh')
lint:
	$(PYTHON) -m ruff check --quiet .
	@$(CLANG_FORMAT) --dry-run --Werror $(CXX_SOURCES)
	$(PYTHON) -m pytest -qq -p no:cacheprovider tests/tools/test_python_layout.py
	@echo "lint: ruff and clang-format find nothing to change; the Python keeps its layers"

format:
	$(PYTHON) -m ruff check --quiet --fix .
	@$(CLANG_FORMAT) -i $(CXX_SOURCES)
	$(PYTHON) -m labkit.skeletons

check-skeletons:
	$(PYTHON) -m labkit.skeletons --check

# common/core/ is exactly what runs on the GPU too: every header of it must compile under nvcc
# on its own, with nothing but core/ on the include path, in the float and the double build
# (real.h), and a kernel must call the path tracer.
NVCC ?= nvcc
CORE_HEADERS := $(notdir $(wildcard common/core/*.h))
check-nvcc:
	@command -v $(NVCC) >/dev/null || { echo "check-nvcc: no CUDA toolkit (nvcc) found"; exit 2; }
	@mkdir -p $(BUILD)/cuda
	@for h in $(CORE_HEADERS); do \
	    printf '#include <%s>\n' $$h > $(BUILD)/cuda/header_$${h%.h}.cu; \
	    for precision in "" -DRT_DOUBLE; do \
	        $(NVCC) -std=c++17 -Icommon/core -arch=sm_90 -Werror all-warnings \
	            $$precision -ptx $(BUILD)/cuda/header_$${h%.h}.cu -o $(BUILD)/cuda/header_$${h%.h}.ptx || exit 1; \
	    done; \
	done
	$(NVCC) -std=c++17 -O3 -Icommon/core -arch=sm_90 -Xcompiler -Wall,-Werror -Werror all-warnings \
	    -c tests/cuda/device_compile_check.cu -o $(BUILD)/cuda/device_compile_check.o
	@echo "check-nvcc: $(words $(CORE_HEADERS)) headers of common/core (float and double builds) and the kernel check compile for sm_90"

# GRADE_ARGS: more options of grading/grade.py (e.g. --budget-seconds 30)
LAB ?= 01
grade:
	$(PYTHON) -m grading.grade $(LAB) --trusted $(GRADE_ARGS)

# The hand-in zip of lab LAB's skeleton files, for Gradescope and make grade-batch
# (grading/releases/handin.py).
handin:
	@$(PYTHON) -m grading.releases.handin $(LAB)

golden: lab01-ref
	$(PYTHON) -m tools.make_golden

# The course report's Tables 4-7 for this machine (tools/bench/report.py): every lab this host
# runs, baseline and three sweeps, beside the report's numbers; CSV, Markdown and PNG plots go
# to REPORTS/bench. QUICK=1 is the CI size; SCALE=K divides every image side by K.
bench: lab01-ref
	$(PYTHON) -m tools.bench.report --out $(REPORTS)/bench \
	    $(if $(filter 1 true yes,$(QUICK)),--quick) $(if $(SCALE),--scale $(SCALE))

# BENCH_ARGS: more options of the bench-* tools, e.g. --repeat N (each lists its own with
# `python3 -m tools.bench.NAME --help`; tools/bench/__init__.py names them).
bench-serial: lab01-ref
	$(PYTHON) -m tools.bench.serial baseline $(BENCH_ARGS)

# The handouts' tables of labs 02-04; each builds what it times.
bench-simd:
	$(PYTHON) -m tools.bench.simd $(BENCH_ARGS)

bench-openmp:
	$(PYTHON) -m tools.bench.openmp $(BENCH_ARGS)

bench-mpi:
	$(PYTHON) -m tools.bench.mpi table $(BENCH_ARGS)

$(BUILD)/intersect_bench: $(BUILD)/bench/intersect_bench.o $(LIB_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@ -lbenchmark -pthread

# Builds only the binaries it times (tools/bench/cpu.py), each that builds here.
bench-cpu:
	$(PYTHON) -m tools.bench.cpu

count-work:
	$(PYTHON) -m tools.bench.count_work $(BENCH_ARGS)

# The extreme scenes in float and double, as docs/extremes.md's Markdown table (builds what it
# needs).
extremes-report:
	$(PYTHON) -m tools.extremes_report

bench-micro: $(BUILD)/intersect_bench
	$(BUILD)/intersect_bench --benchmark_min_time=0.2

# Speed against accuracy (tools/tradeoff/): error against time for every renderer here,
# bias against bounces, fast math and ray offsets; fails when a check does. CSV, Markdown,
# JSON and PNG plots go to REPORTS. QUICK=1 is the CI size (tests/tools/test_tradeoff.py runs
# it); PLAN=gpu the GPU machine's (tools/gpu/tradeoff.sh); PLOTS=0 needs no matplotlib and
# draws nothing (`python3 -m tools.tradeoff --replot DIR` draws the plots later).
REPORTS ?= $(BUILD)/reports
tradeoff: lab01-ref
	$(PYTHON) -m tools.tradeoff --out $(REPORTS) $(if $(filter 1 true yes,$(QUICK)),--quick) \
	    $(if $(PLAN),--plan $(PLAN)) $(if $(filter 0 false no,$(PLOTS)),--no-plots)

# The GPU records' figures in the handouts and READMEs (tools/gpu/figures.py): the tables
# regenerated from the records in reference/gpu/ after a new one; CHECK=1 only compares,
# naming every figure that differs.
gpu-figures:
	$(PYTHON) -m tools.gpu.figures $(if $(filter 1 true yes,$(CHECK)),--check)

# Float against double: time and error of lab01-ref and lab01-ref-double (tools/bench/precision.py).
bench-precision: lab01-ref lab01-ref-double
	$(PYTHON) -m tools.bench.precision

# ---- variants -----------------------------------------------------------------------------
# A lab built from a folder of edited sources outside the tree: the pristine skeleton as
# generated, a mutation test's mutant. `make variant VARIANT_LAB=01-serial VARIANT=DIR`
# compiles DIR/*.cpp with DIR first on the include path (a header there stands in for the
# shared one) and links the lab's driver into DIR/lab. Each lab.mk sets VARIANT_FLAGS_<lab>,
# VARIANT_DRIVER_<lab> and VARIANT_LIBS_<lab> to what its own binaries are built with.
# A hand-in's file names reach the shell quoted (the grader also refuses any outside
# [A-Za-z0-9_.+-]): each word of $(1) in single quotes, a quote in it as '\''.
quoted = $(foreach f,$(1),'$(subst ','\'',$(f))')

variant: $(VARIANT_DRIVER_$(VARIANT_LAB))
	@test -n "$(VARIANT)" -a -n "$(VARIANT_DRIVER_$(VARIANT_LAB))" || \
	    { echo "variant: needs VARIANT=DIR and VARIANT_LAB=<a lab with VARIANT_DRIVER_<lab>>" >&2; exit 2; }
	$(CXX) $(filter-out -MMD -MP,$(CXXFLAGS)) -w -I'$(VARIANT)' $(VARIANT_FLAGS_$(VARIANT_LAB)) \
	    $(INCLUDES) $(call quoted,$(sort $(wildcard $(VARIANT)/*.cpp))) \
	    $(VARIANT_DRIVER_$(VARIANT_LAB)) -o '$(VARIANT)/lab' $(VARIANT_LIBS_$(VARIANT_LAB))

clean:
	rm -rf $(BUILD) $(REGISTERED_TARGETS) .pytest_cache

-include $(shell find $(BUILD) -path $(BUILD)/ccache -prune -o -name '*.d' -print 2>/dev/null)
