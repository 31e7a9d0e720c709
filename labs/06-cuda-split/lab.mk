# Lab 06 (CUDA split kernels, a wavefront): `make lab06` builds skeleton/, `make lab06-ref`
# solution/, `make lab06-bench` the measurements of the handout (bench.cu). The lab's own
# folder holds what skeleton and solution share (kernels, pool, host side); lab 05's folder
# gives the CUDA error checking and the scene upload (cuda_check.h, scene_pool.cuh) and, to
# the benchmark only, the megakernel it is measured against.
LAB06 := labs/06-cuda-split
LAB06_TARGETS := lab06 lab06-ref lab06-bench
# Real files, not phony: a test that asks make for a binary that is up to date must not get it
# relinked under another test that is running it ("Text file busy").
ifeq ($(HAVE_NVCC),)
.PHONY: $(LAB06_TARGETS)
$(LAB06_TARGETS):
	@echo "$@: needs the CUDA toolkit ($(NVCC) not found)" >&2
	@exit 1
else
$(eval $(call cuda_lab,lab06,06-cuda-split))
$(BUILD)/$(LAB06)/skeleton/%.o: LAB_INCLUDES += -Ilabs/05-cuda-mega
$(BUILD)/$(LAB06)/solution/%.o: LAB_INCLUDES += -Ilabs/05-cuda-mega

# The benchmark has its own main and links the library part of common/host only. It runs
# the reference (solution/) kernels, next to lab 05's reference megakernel.
$(BUILD)/$(LAB06)/bench.o: LAB_INCLUDES = -I$(LAB06)/solution -I$(LAB06) \
    -Ilabs/05-cuda-mega/solution -Ilabs/05-cuda-mega
lab06-bench: $(BUILD)/$(LAB06)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@

# Its variants (make cuda-variant VARIANT_LAB=06-cuda-split) see the same folders.
VARIANT_INCLUDES_06-cuda-split := -I$(LAB06) -Ilabs/05-cuda-mega
endif

LAB_BINARIES += $(LAB06_TARGETS)
