# Lab 06 (CUDA split kernels, a wavefront): `make lab06` builds skeleton/, `make lab06-ref`
# solution/, `make lab06-bench` the measurements of the handout (bench.cu). The wavefront
# library is common/wavefront/ (kernels, pool, host side); students write its queue's reserve
# and its stage loop, their skeleton/queue_reserve.cuh and stage_loop.cuh standing in for the
# shared ones (the rest of the queue, common/wavefront/path_queue.cuh, is the library's).
LAB06 := labs/06-cuda-split
ifneq ($(HAVE_NVCC),)
$(eval $(call cuda_lab,lab06,06-cuda-split,common/wavefront,queue_reserve.cuh stage_loop.cuh))

# The benchmark has its own main and links the library part of common/host only. It runs
# the reference wavefront (common/wavefront/) and lab 05's reference megakernel.
$(BUILD)/$(LAB06)/bench.%: LAB_INCLUDES = $(GPU_BENCH_INCLUDES) -Icommon/wavefront
$(BUILD)/$(LAB06)/bench.%: OBJECT_CUDA_ARCH = $(CUDA_TOOL_ARCH)
lab06-bench: $(BUILD)/$(LAB06)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
endif
