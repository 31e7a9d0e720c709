# CUDA labs (05-07): the nvcc rules. Included by the Makefile before the labs' lab.mk files (labs 06 and 07 use cuda_lab).
#
#   make lab05 / lab05-ref       lab 05's student build / reference (labs/05-cuda-mega)
#   make lab05-bench             the kernel shapes the handout measures (labs/05-cuda-mega/bench.cu)
#   make lab05-bench-fast-math   the same built with --use_fast_math
#   make lab05-ref-fast-math     the reference built with --use_fast_math (accuracy table)
#   make lab05-ref-no-fma        the reference built with --fmad=false (no fused multiply-add)
#   make lab05-ref-double        the reference in double precision (common/core/real.h)
#   make kernel-report           registers, spills, stack and shared memory of every kernel
#   make gpu-check OUT=DIR       on a GPU machine: build, test, benchmark, report (tools/gpu_check.sh)
#
# Architectures: the GPUs present (nvidia-smi's compute capability), or, where there is none
# (CI), machine code for sm_75 (Turing), sm_80 (A100), sm_86 (RTX 30), sm_89 (L4, RTX 40) and
# sm_90 (H100, H200) plus compute_90 PTX that newer GPUs compile when they load it. Set
# CUDA_ARCH on the command line to choose others, e.g. CUDA_ARCH='-arch=sm_90'.
# Without nvcc every CUDA target says so in one line and fails; nothing else is affected.

NVCC ?= nvcc
HAVE_NVCC := $(shell command -v $(NVCC) 2>/dev/null)

CUDA_ARCH_LIST := 75 80 86 89 90
CUDA_FALLBACK_ARCH := $(foreach a,$(CUDA_ARCH_LIST),-gencode arch=compute_$(a),code=sm_$(a)) \
                      -gencode arch=compute_90,code=compute_90
# Evaluated once, on first use (asking nvidia-smi costs a fraction of a second).
CUDA_GPU_CAPS = $(eval CUDA_GPU_CAPS := $$(sort $$(shell nvidia-smi \
    --query-gpu=compute_cap --format=csv,noheader 2>/dev/null | tr -d ' .')))$(CUDA_GPU_CAPS)
CUDA_ARCH ?= $(if $(CUDA_GPU_CAPS),$(foreach c,$(CUDA_GPU_CAPS),\
    -gencode arch=compute_$(c),code=sm_$(c)),$(CUDA_FALLBACK_ARCH))

# Warnings as errors under CI, for our host code (-Xcompiler) and for nvcc's own.
CUDA_WARN := -Xcompiler -Wall
ifeq ($(CI),true)
CUDA_WARN := -Xcompiler -Wall,-Werror -Werror all-warnings
endif
# --threads 0: one compiler process per architecture, in parallel.
NVCCFLAGS := -std=c++17 -O3 --threads 0 $(CUDA_WARN)

$(BUILD)/%.o: %.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) $(CUDA_VARIANT_FLAGS) $(LAB_INCLUDES) $(INCLUDES) \
	    -MMD -MP -MF $(@:.o=.d) -c $< -o $@

# The exact nvcc command lab objects are built with (tests build the pristine skeleton so).
print-cuda-build-command:
	@echo $(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) $(INCLUDES)

# $(1): binary stem (lab05), $(2): lab folder (05-cuda-mega). The lab's own folder is on the
# include path after skeleton/ or solution/, for the files both share.
define cuda_lab
$(BUILD)/labs/$(2)/skeleton/%.o: LAB_INCLUDES = -Ilabs/$(2)/skeleton -Ilabs/$(2)
$(BUILD)/labs/$(2)/solution/%.o: LAB_INCLUDES = -Ilabs/$(2)/solution -Ilabs/$(2)
$(1): $(patsubst %.cu,$(BUILD)/%.o,$(wildcard labs/$(2)/skeleton/*.cu)) $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $$^ -o $$@
$(1)-ref: $(patsubst %.cu,$(BUILD)/%.o,$(wildcard labs/$(2)/solution/*.cu)) $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $$^ -o $$@
endef

# ---- lab 05 -------------------------------------------------------------------------------
LAB05 := labs/05-cuda-mega
LAB05_BUILD := $(BUILD)/$(LAB05)
LAB05_TARGETS := lab05 lab05-ref lab05-bench lab05-bench-fast-math lab05-ref-fast-math \
                 lab05-ref-no-fma lab05-ref-double
.PHONY: $(LAB05_TARGETS) kernel-report gpu-check print-cuda-build-command cuda-variant

ifeq ($(HAVE_NVCC),)
$(LAB05_TARGETS) kernel-report cuda-variant:
	@echo "$@: needs the CUDA toolkit ($(NVCC) not found)" >&2
	@exit 1
else
$(eval $(call cuda_lab,lab05,05-cuda-mega))

# Variants of the reference: the same source under other flags, objects in their own folders.
$(LAB05_BUILD)/fast-math/render.o: CUDA_VARIANT_FLAGS = --use_fast_math
$(LAB05_BUILD)/no-fma/render.o: CUDA_VARIANT_FLAGS = --fmad=false
$(LAB05_BUILD)/fast-math/render.o $(LAB05_BUILD)/no-fma/render.o: $(LAB05)/solution/render.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) $(CUDA_VARIANT_FLAGS) -I$(LAB05)/solution -I$(LAB05) \
	    $(INCLUDES) -MMD -MP -MF $(@:.o=.d) -c $< -o $@
lab05-ref-fast-math: $(LAB05_BUILD)/fast-math/render.o $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@
lab05-ref-no-fma: $(LAB05_BUILD)/no-fma/render.o $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@
# The reference in double: -DRT_DOUBLE, linked with the double build's host objects (Makefile).
$(LAB05_BUILD)/double/render.o: $(LAB05)/solution/render.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) -DRT_DOUBLE -I$(LAB05)/solution -I$(LAB05) \
	    $(INCLUDES) -MMD -MP -MF $(@:.o=.d) -c $< -o $@
lab05-ref-double: $(LAB05_BUILD)/double/render.o $(DOUBLE_COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@

# A CUDA lab built from a folder of edited sources (the pristine skeleton, a mutant), as
# `make variant` does for the CPU labs: `make cuda-variant VARIANT_LAB=05-cuda-mega
# VARIANT=DIR` compiles DIR/*.cu with DIR first on the include path, then the folders the
# lab's own build uses (VARIANT_INCLUDES_<lab>), and links the shared driver into DIR/lab.
VARIANT_INCLUDES_05-cuda-mega := -I$(LAB05)
cuda-variant: $(COMMON_OBJ)
	@test -n "$(VARIANT)" -a -n "$(VARIANT_INCLUDES_$(VARIANT_LAB))" || \
	    { echo "cuda-variant: needs VARIANT=DIR and VARIANT_LAB=<a CUDA lab folder>" >&2; exit 2; }
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) -I$(VARIANT) $(VARIANT_INCLUDES_$(VARIANT_LAB)) $(INCLUDES) \
	    $(sort $(wildcard $(VARIANT)/*.cu)) $(COMMON_OBJ) -o $(VARIANT)/lab

# The benchmark has its own main; it links the library part of common/host only.
$(LAB05_BUILD)/bench.o: LAB_INCLUDES = -I$(LAB05)/solution -I$(LAB05)
lab05-bench: $(LAB05_BUILD)/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@
$(LAB05_BUILD)/fast-math/bench.o: $(LAB05)/bench.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) --use_fast_math -I$(LAB05)/solution -I$(LAB05) \
	    $(INCLUDES) -MMD -MP -MF $(@:.o=.d) -c $< -o $@
lab05-bench-fast-math: $(LAB05_BUILD)/fast-math/bench.o $(LIB_OBJ)
	$(NVCC) $(CUDA_ARCH) $^ -o $@

LAB_BINARIES += $(LAB05_TARGETS)
labs: $(LAB05_TARGETS)

# The compiler's resource report (ptxas -v) for every kernel of the GPU references and
# lab 05's benchmark (the course report's Table 1 for our kernels), for one architecture: the
# GPU present, else sm_90. Writes build/kernel-report.md. Each source gets the include path
# its own build uses.
KERNEL_REPORT_ARCH = $(if $(CUDA_GPU_CAPS),sm_$(firstword $(CUDA_GPU_CAPS)),sm_90)
KERNEL_REPORT_NVCC = $(NVCC) -std=c++17 -O3 -arch=$(KERNEL_REPORT_ARCH) -Xptxas -v
kernel-report:
	@mkdir -p $(BUILD)/kernel-report
	@{ $(KERNEL_REPORT_NVCC) -I$(LAB05)/solution -I$(LAB05) $(INCLUDES) \
	       -c $(LAB05)/solution/render.cu -o $(BUILD)/kernel-report/lab05.o && \
	   $(KERNEL_REPORT_NVCC) -I$(LAB05)/solution -I$(LAB05) $(INCLUDES) \
	       -c $(LAB05)/bench.cu -o $(BUILD)/kernel-report/lab05-bench.o && \
	   $(KERNEL_REPORT_NVCC) -Ilabs/06-cuda-split/solution $(VARIANT_INCLUDES_06-cuda-split) \
	       $(INCLUDES) -c labs/06-cuda-split/solution/render.cu -o $(BUILD)/kernel-report/lab06.o && \
	   $(KERNEL_REPORT_NVCC) -Ilabs/07-soa/solution $(VARIANT_INCLUDES_07-soa) \
	       $(INCLUDES) -c labs/07-soa/solution/render.cu -o $(BUILD)/kernel-report/lab07.o; \
	 } > $(BUILD)/kernel-report/ptxas.log 2>&1 || { cat $(BUILD)/kernel-report/ptxas.log; exit 1; }
	@$(PYTHON) $(LAB05)/kernel_report.py $(BUILD)/kernel-report/ptxas.log \
	    --arch $(KERNEL_REPORT_ARCH) --out $(BUILD)/kernel-report.md
endif

# Everything the device machine should do, in one call: tools/gpu_check.sh OUT.
OUT ?= $(BUILD)/gpu-check
gpu-check:
	bash tools/gpu_check.sh $(OUT)
