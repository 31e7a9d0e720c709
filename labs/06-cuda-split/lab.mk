# Lab 06 (CUDA split kernels, a wavefront): `make lab06` builds skeleton/, `make lab06-ref`
# solution/, `make lab06-bench` the measurements of the handout (bench.cu). The wavefront
# library is common/wavefront/ (kernels, pool, host side); students write its queue's reserve
# and its stage loop, their skeleton/path_queue.cuh and stage_loop.cuh standing in for the
# shared ones.
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
$(eval $(call cuda_lab,lab06,06-cuda-split,common/wavefront,path_queue.cuh stage_loop.cuh))

# The benchmark has its own main and links the library part of common/host only. It runs
# the reference wavefront (common/wavefront/) and lab 05's reference megakernel.
$(BUILD)/$(LAB06)/bench.o: LAB_INCLUDES = -Icommon/wavefront
lab06-bench: $(BUILD)/$(LAB06)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@
endif

LAB_BINARIES += $(LAB06_TARGETS)
