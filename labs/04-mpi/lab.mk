# Lab 04: MPI. Run the binaries under mpirun, e.g. `mpirun -np 2 ./lab04-ref --out a.ppm`:
#   lab04           the student's code (labs/04-mpi/skeleton)
#   lab04-ref       the reference solution
#   lab04-simd-ref  the solution on lab 02's packet tracer at the CPU's width (common/simd/
#                   first on the include path); only on x86-64
# All three link labs/04-mpi/mpi_main.cpp (MPI around the shared driver) instead of
# common/host/main.cpp. RT_MPI_DISTRIBUTION=block|interleaved|dynamic picks the distribution.
LAB04 := labs/04-mpi
LAB04_BUILD := $(BUILD)/$(LAB04)
MPICXX ?= mpicxx

# OpenMPI's flags from its compiler wrapper (evaluated only when a lab-04 file is built). Its
# headers are system headers, so they raise no warnings under -Werror, and its deprecated C++
# bindings stay out.
LAB04_MPI_CFLAGS = $(patsubst -I%,-isystem %,$(filter -I%,$(shell $(MPICXX) --showme:compile))) \
                   -DOMPI_SKIP_MPICXX=1
LAB04_MPI_LIBS = $(shell $(MPICXX) --showme:link)
$(LAB04_BUILD)/%.o: CXXFLAGS += -fopenmp $(LAB04_MPI_CFLAGS)
# mpi_run.h (the plumbing students do not edit) is found from skeleton/ and solution/ alike.
$(LAB04_BUILD)/%.o: LAB_INCLUDES = -I$(LAB04)

LAB04_DRIVER := $(LAB04_BUILD)/mpi_main.o $(LAB04_BUILD)/mpi_run.o $(BUILD)/common/host/lab_main.o \
                $(LIB_OBJ)
LAB04_SKELETON_OBJ := $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard $(LAB04)/skeleton/*.cpp))
LAB04_SOLUTION_OBJ := $(patsubst %.cpp,$(BUILD)/%.o,$(wildcard $(LAB04)/solution/*.cpp))

# The SIMD variant: solution/render.cpp with common/simd/ first on the include path and
# -DRT_USE_SIMD (as lab 03's), entered through simd_entry.cpp (built without SIMD flags),
# which checks every rank's CPU first; the SIMD library's objects (SIMD_OBJ) come last.
$(LAB04_BUILD)/simd/render.o: $(LAB04)/solution/render.cpp
	@mkdir -p $(dir $@)
	$(CXX) $(CXXFLAGS) -DRT_USE_SIMD -I$(LAB04) $(SIMD_INCLUDES) -c $< -o $@
$(LAB04_BUILD)/simd_entry.o: LAB_INCLUDES = -I$(LAB04) -Icommon/simd
LAB04_SIMD_MISSING :=
ifeq ($(filter x86_64% i686% i386%,$(shell $(CXX) -dumpmachine)),)
LAB04_SIMD_MISSING := needs an x86-64 CPU and compiler (AVX2)
endif

ifeq ($(shell command -v $(MPICXX) 2>/dev/null),)
lab04 lab04-ref lab04-simd-ref:
	@echo "$@: needs OpenMPI ($(MPICXX) not found; run make deps)" >&2
	@exit 1
.PHONY: lab04 lab04-ref lab04-simd-ref
else
lab04: $(LAB04_SKELETON_OBJ) $(LAB04_DRIVER)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(LAB04_MPI_LIBS) $(INTO_TARGET)
lab04-ref: $(LAB04_SOLUTION_OBJ) $(LAB04_DRIVER)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(LAB04_MPI_LIBS) $(INTO_TARGET)
LAB_BINARIES += lab04 lab04-ref
VARIANT_FLAGS_04-mpi = -fopenmp $(LAB04_MPI_CFLAGS) -I$(LAB04)
VARIANT_DRIVER_04-mpi := $(LAB04_DRIVER)
VARIANT_LIBS_04-mpi = -fopenmp $(LAB04_MPI_LIBS)
ifeq ($(LAB04_SIMD_MISSING),)
lab04-simd-ref: $(LAB04_BUILD)/simd/render.o $(LAB04_BUILD)/simd_entry.o $(LAB04_DRIVER) $(SIMD_OBJ)
	$(CXX) $(CXXFLAGS) $^ -fopenmp $(LAB04_MPI_LIBS) $(INTO_TARGET)
LAB_BINARIES += lab04-simd-ref
else
lab04-simd-ref:
	@echo "lab04-simd-ref: $(LAB04_SIMD_MISSING)" >&2
	@exit 1
.PHONY: lab04-simd-ref
endif
endif
