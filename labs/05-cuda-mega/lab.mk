# Lab 05 (CUDA megakernel): `make lab05` builds skeleton/, `make lab05-ref` solution/ (its
# kernel's loops are common/cuda/render_kernel.cuh, which skeleton/render_kernel.cuh stands in
# for), and
#   make lab05-bench             the kernel shapes the handout measures (bench.cu)
#   make lab05-bench-fast-math   the same built with --use_fast_math
#   make lab05-ref-fast-math     the reference built with --use_fast_math (accuracy table)
#   make lab05-ref-no-fma        the reference built with --fmad=false (no fused multiply-add)
#   make lab05-ref-double        the reference in double precision (common/core/real.h)
LAB05 := labs/05-cuda-mega
LAB05_BUILD := $(BUILD)/$(LAB05)
ifneq ($(HAVE_NVCC),)
$(eval $(call cuda_lab,lab05,05-cuda-mega,,render_kernel.cuh))

# Variants of the reference and the benchmark: the same source under other flags, objects in
# folders of their own. $(1): the variant's folder, $(2): the source, $(3): the flags.
define lab05_variant_object
$(LAB05_BUILD)/$(1)/$(basename $(notdir $(2))).o: $(2)
	@mkdir -p $$(dir $$@)
	$$(NVCC) $$(NVCCFLAGS) $$(CUDA_TOOL_ARCH) $(3) -I$(LAB05)/solution $$(CUDA_INCLUDES) \
	    $$(INCLUDES) -MMD -MP -MF $$(@:.o=.d) -c $$< -o $$@
endef
# nvcc defines no macro for --use_fast_math; RT_LAB05_FAST_MATH tells the sources (the
# small-scene kernel's register cap, common/cuda/kernel_choice.cuh). Fast math's short
# operations let ptxas's scheduler keep far more values live than that cap holds, so at its
# default level it spills inside the loop; --register-usage-level=3 keeps it within the cap.
LAB05_FAST_MATH := --use_fast_math -DRT_LAB05_FAST_MATH -Xptxas --register-usage-level=3
$(eval $(call lab05_variant_object,fast-math,$(LAB05)/solution/render.cu,$(LAB05_FAST_MATH)))
$(eval $(call lab05_variant_object,no-fma,$(LAB05)/solution/render.cu,--fmad=false))
$(eval $(call lab05_variant_object,double,$(LAB05)/solution/render.cu,-DRT_DOUBLE))
$(eval $(call lab05_variant_object,fast-math,$(LAB05)/bench.cu,$(LAB05_FAST_MATH) $(GPU_BENCH_INCLUDES)))
lab05-ref-fast-math: $(LAB05_BUILD)/fast-math/render.o $(COMMON_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
lab05-ref-no-fma: $(LAB05_BUILD)/no-fma/render.o $(COMMON_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
# The reference in double: linked with the double build's host objects (Makefile).
lab05-ref-double: $(LAB05_BUILD)/double/render.o $(DOUBLE_COMMON_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
# lab05-ref carries it and hands it a scene float cannot place (common/host/double_twin.h).
lab05-ref: $(BUILD)/twins/lab05-ref-double.o

# The benchmark has its own main; it links the library part of common/host only. It runs the
# reference kernel (common/cuda/megakernel.cuh) in every shape it measures.
$(LAB05_BUILD)/bench.%: LAB_INCLUDES = $(GPU_BENCH_INCLUDES)
$(LAB05_BUILD)/bench.%: OBJECT_CUDA_ARCH = $(CUDA_TOOL_ARCH)
lab05-bench: $(LAB05_BUILD)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
lab05-bench-fast-math: $(LAB05_BUILD)/fast-math/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_TOOL_ARCH) $^ $(INTO_TARGET)
endif
