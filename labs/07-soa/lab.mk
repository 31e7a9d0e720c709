# Lab 07 (structure of arrays): `make lab07` builds skeleton/, `make lab07-ref` solution/,
# `make lab07-bench` the handout's measurements: lab 06's benchmark (labs/06-cuda-split/
# bench.cu) with both pool layouts, AoS and SoA, in the same run. Lab 07 reuses lab 06's
# kernels and host side (labs/06-cuda-split, its solution/ for the queue and stage loop) and
# lab 05's error checking and scene upload; only the pool's layout is its own.
LAB07 := labs/07-soa
LAB07_TARGETS := lab07 lab07-ref lab07-bench
LAB07_SHARED := -Ilabs/06-cuda-split/solution -Ilabs/06-cuda-split -Ilabs/05-cuda-mega
# Real files, not phony: a test that asks make for a binary that is up to date must not get it
# relinked under another test that is running it ("Text file busy").
ifeq ($(HAVE_NVCC),)
.PHONY: $(LAB07_TARGETS)
$(LAB07_TARGETS):
	@echo "$@: needs the CUDA toolkit ($(NVCC) not found)" >&2
	@exit 1
else
$(eval $(call cuda_lab,lab07,07-soa))
$(BUILD)/$(LAB07)/skeleton/%.o: LAB_INCLUDES += $(LAB07_SHARED)
$(BUILD)/$(LAB07)/solution/%.o: LAB_INCLUDES += $(LAB07_SHARED)

# The benchmark's source is lab 06's; this folder's bench_pools.cuh, first on the include
# path, adds the SoA pool to the layouts it measures.
$(BUILD)/$(LAB07)/bench.o: labs/06-cuda-split/bench.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) -I$(LAB07)/solution -I$(LAB07) $(LAB07_SHARED) \
	    -Ilabs/05-cuda-mega/solution $(INCLUDES) -MMD -MP -MF $(@:.o=.d) -c $< -o $@
lab07-bench: $(BUILD)/$(LAB07)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@

# Its variants (make cuda-variant VARIANT_LAB=07-soa) see the same folders.
VARIANT_INCLUDES_07-soa := -I$(LAB07) $(LAB07_SHARED)
endif

LAB_BINARIES += $(LAB07_TARGETS)
