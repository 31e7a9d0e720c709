# Lab 03: OpenMP. ./lab03 (skeleton) and ./lab03-ref (solution), plus the variants the
# handout measures, all with the shared command line:
#   lab03-bench            the solution with schedule(runtime): OMP_SCHEDULE picks the loop
#                          schedule (tools/bench/openmp.py; the default build keeps the best)
#   lab03-simd-ref         the solution on lab 02's packet tracer at the CPU's width (16
#                          AVX-512 lanes or 8 AVX2, compacted); only on x86-64
#   lab03-shared-rng       the classic mistake: one generator shared by all threads, locked
#   lab03-shared-rng-race  the same without the lock: a data race
#   lab03-row-costs        lab 01's serial render, timing each row (the cost profile)
LAB03 := labs/03-openmp
LAB03_BUILD := $(BUILD)/$(LAB03)

# Every object of this lab is compiled with OpenMP; binaries link with it (cpu_lab's third
# argument and the rules below).
$(LAB03_BUILD)/%.o: CXXFLAGS += -fopenmp
$(eval $(call cpu_lab,lab03,03-openmp,-fopenmp))

# Variants: one source, other defines, objects in their own folders.
$(LAB03_BUILD)/bench/render.o: $(LAB03)/solution/render.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_RUNTIME_SCHEDULE $(INCLUDES) -c $< -o $@
$(LAB03_BUILD)/shared-rng-race/shared_rng.o: $(LAB03)/shared_rng.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_SHARED_RNG_RACE $(INCLUDES) -c $< -o $@

lab03-bench: $(LAB03_BUILD)/bench/render.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)
lab03-shared-rng: $(LAB03_BUILD)/shared_rng.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)
lab03-shared-rng-race: $(LAB03_BUILD)/shared-rng-race/shared_rng.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)
lab03-row-costs: $(LAB03_BUILD)/row_costs.o $(COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)

VARIANT_FLAGS_03-openmp := -fopenmp
VARIANT_DRIVER_03-openmp := $(COMMON_OBJ)
VARIANT_LIBS_03-openmp := -fopenmp

LAB_BINARIES += lab03 lab03-ref lab03-bench lab03-shared-rng lab03-shared-rng-race \
                lab03-row-costs

# The SIMD variant: solution/render.cpp with common/simd/ first on the include path (its
# pixel_renderer.h renders with lab 02's packets at the CPU's width) and -DRT_USE_SIMD (which
# renames its render() to render_avx2), entered through simd_entry.cpp (built without SIMD
# flags), which checks the CPU; the SIMD library's objects (SIMD_OBJ, Makefile) come last.
ifneq ($(filter x86_64% i686% i386%,$(shell $(CXX) -dumpmachine)),)
$(LAB03_BUILD)/simd/render.o: $(LAB03)/solution/render.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_USE_SIMD $(SIMD_INCLUDES) -c $< -o $@
$(LAB03_BUILD)/simd_entry.o: LAB_INCLUDES = -Icommon/simd
lab03-simd-ref: $(LAB03_BUILD)/simd/render.o $(LAB03_BUILD)/simd_entry.o $(COMMON_OBJ) $(SIMD_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)
LAB_BINARIES += lab03-simd-ref
else
lab03-simd-ref:
	@echo "lab03-simd-ref: needs an x86-64 CPU and compiler (AVX2)" >&2
	@exit 1
.PHONY: lab03-simd-ref
endif

# The reference in double (OpenMP over lab 01's scalar renderer), which lab03-ref and
# lab03-simd-ref carry and hand a scene float cannot place (common/host/double_twin.h).
$(DOUBLE_BUILD)/$(LAB03)/%.o: CXXFLAGS += -fopenmp
$(DOUBLE_BUILD)/$(LAB03)/solution/%.o: LAB_INCLUDES = -I$(LAB03)/solution
lab03-ref-double: $(patsubst %.cpp,$(DOUBLE_BUILD)/%.o,$(wildcard $(LAB03)/solution/*.cpp)) \
                  $(DOUBLE_COMMON_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(INTO_TARGET)
lab03-ref lab03-simd-ref: $(BUILD)/twins/lab03-ref-double.o
LAB_BINARIES += lab03-ref-double
