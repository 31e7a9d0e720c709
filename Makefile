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
CXXFLAGS := -std=c++17 $(OPT) $(WARN) -DRT_SOURCE_DIR='"$(CURDIR)"' -MMD -MP
INCLUDES := -Icommon

# The library part of common/ (what unit tests link) and the driver every lab binary adds.
LIB_SRC    := common/scene_loader.cpp common/image.cpp common/cli.cpp common/progress.cpp
LIB_OBJ    := $(LIB_SRC:%.cpp=$(BUILD)/%.o)
DRIVER_OBJ := $(BUILD)/common/lab_main.o $(BUILD)/common/main.o
COMMON_OBJ := $(LIB_OBJ) $(DRIVER_OBJ)

PHONY_EXTRA := print-build-command
PHONY_EXTRA += render grade check-nvcc bench-micro bench-cpu count-work
.PHONY: all help deps labs $(PHONY_EXTRA) test test-unit test-labs skeletons check-skeletons golden bench tradeoff \
        clean
.DEFAULT_GOAL := help

help:
	@echo "make labNN        build your code for lab NN (labs/NN-name/skeleton) into ./labNN"
	@echo "make labNN-ref    build lab NN's reference solution into ./labNN-ref"
	@echo "                  labs: $(LAB_BINARIES)"
	@echo "make render       install what is missing, render the default scene to cornell.ppm"
	@echo "make deps         install what is missing (JSON library, OpenMPI, pytest, numpy)"
	@echo "make grade LAB=NN grade your lab NN code (01-04): score table and results.json"
	@echo "make test         build everything and run every test"
	@echo "make bench        time the lab-01 reference on the Cornell baseline (minutes)"
	@echo "make bench-cpu    the CPU labs side by side (the report's Table 4 for this machine)"
	@echo "make bench-micro  Google Benchmark of the inner loops (closest hit, shadow ray, path)"
	@echo "make count-work   instructions per camera path, split by query (needs valgrind)"
	@echo "make tradeoff     error against time: RMSE vs spp for the lab-01 reference"
	@echo "make golden       regenerate the golden images in reference/ (minutes)"
	@echo "make skeletons    regenerate the skeletons from the solutions"
	@echo "make clean        remove build products"

deps:
	@bash tools/install_deps.sh

$(BUILD)/%.o: %.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) $(INCLUDES) -c $< -o $@

# ---- labs -------------------------------------------------------------------------------
# lab01 builds labs/01-serial/skeleton, lab01-ref builds labs/01-serial/solution. A source
# includes "path_tracer.h" by quotes, so the skeleton's own copy shadows common/'s.
define cpu_lab
$(1): $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard labs/$(2)/skeleton/*.cpp)) $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $$^ -o $$@ $(3)
$(1)-ref: $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard labs/$(2)/solution/*.cpp)) $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $$^ -o $$@ $(3)
.PHONY: $(1) $(1)-ref
endef

# Each lab's own rules (its binaries, extra flags) live in labs/NN-name/lab.mk; each adds
# its binaries to LAB_BINARIES.
LAB_BINARIES :=
include $(sort $(wildcard labs/*/lab.mk))
labs: $(LAB_BINARIES)

# ---- tests ------------------------------------------------------------------------------
UNIT_SRC := $(wildcard tests/unit/*.cpp)
UNIT_OBJ := $(UNIT_SRC:%.cpp=$(BUILD)/%.o)

$(BUILD)/unit_tests: $(UNIT_OBJ) $(LIB_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@ -lgtest -lgtest_main -pthread

test-unit: $(BUILD)/unit_tests
	$(BUILD)/unit_tests --gtest_brief=1

test-labs: labs
	$(PYTHON) -m pytest -q tests

# Every test: installs what is missing first, so it works on a fresh machine.
test: deps
	$(MAKE) --no-print-directory test-unit
	$(MAKE) --no-print-directory test-labs

# Render the default scene (the Cornell baseline) with the lab-01 reference.
render: deps
	$(MAKE) --no-print-directory lab01-ref
	./lab01-ref --out cornell.ppm

skeletons:
	$(PYTHON) tools/skeletons.py

check-skeletons:
	$(PYTHON) tools/skeletons.py --check

# The shared host+device code must build for the GPU too (CUDA labs reuse it).
NVCC ?= nvcc
check-nvcc:
	@command -v $(NVCC) >/dev/null || { echo "check-nvcc: no CUDA toolkit (nvcc) found"; exit 2; }
	@mkdir -p $(BUILD)/cuda
	$(NVCC) -std=c++17 -O3 -Icommon -arch=sm_90 -Xcompiler -Wall,-Werror \
	    -c tests/cuda/device_compile_check.cu -o $(BUILD)/cuda/device_compile_check.o

LAB ?= 01
grade:
	$(PYTHON) -m grading.grade $(LAB)

golden: lab01-ref
	$(PYTHON) tools/make_golden.py

bench: lab01-ref
	$(PYTHON) tools/bench_serial.py baseline

$(BUILD)/intersect_bench: $(BUILD)/bench/intersect_bench.o $(LIB_OBJ)
	$(CXX) $(CXXFLAGS) $^ -o $@ -lbenchmark -pthread

bench-cpu: labs
	$(PYTHON) tools/bench_cpu.py

count-work:
	$(PYTHON) tools/count_work.py

bench-micro: $(BUILD)/intersect_bench
	$(BUILD)/intersect_bench --benchmark_min_time=0.2

tradeoff: lab01-ref
	$(PYTHON) tools/bench_serial.py tradeoff

# The exact compiler command lab binaries are built with (the mutation tests reuse it).
print-build-command:
	@echo $(CXX) $(CXXFLAGS)

clean:
	rm -rf $(BUILD) $(LAB_BINARIES) .pytest_cache

-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)
