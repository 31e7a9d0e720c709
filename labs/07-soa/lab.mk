# Lab 07 (structure of arrays): `make lab07` builds skeleton/, `make lab07-ref` solution/,
# `make lab07-bench` the handout's measurements (bench.cu): the wavefront benchmark with both
# pool layouts, AoS and SoA, in the same run. Lab 07 runs the wavefront library of
# common/wavefront/ (lab 06's kernels, queue and stage loop, in their reference form); only
# the pool's layout is its own: skeleton/path_pool_soa.cuh stands in for the shared one.
LAB07 := labs/07-soa
ifneq ($(HAVE_NVCC),)
$(eval $(call cuda_lab,lab07,07-soa,common/wavefront,path_pool_soa.cuh))

$(BUILD)/$(LAB07)/bench.%: LAB_INCLUDES = $(GPU_BENCH_INCLUDES) -Icommon/wavefront
$(BUILD)/$(LAB07)/bench.%: OBJECT_CUDA_ARCH = $(CUDA_TOOL_ARCH)
lab07-bench: $(BUILD)/$(LAB07)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
endif
