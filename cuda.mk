# CUDA labs (kind "gpu" in labs/labs.toml: 05-07): the nvcc rules. Included by the Makefile before the labs' lab.mk files,
# which build their labs with cuda_lab (below); each lab's own targets are in its lab.mk.
#
#   make cuda-variant VARIANT_LAB=<lab folder> VARIANT=DIR   a CUDA lab from a folder of sources
#   make kernel-report           registers, spills, stack and shared memory of every kernel
#   make check-gpu-headers       every header of common/cuda, common/wavefront and bench/gpu compiles alone
#   make check-speed-targets     the benchmarks' speed-target verdicts, on the host (no GPU needed)
#   make gpu-check OUT=DIR       on a GPU machine: build, test, benchmark, report (tools/gpu/check.sh)
#   make grade-gpu [LAB=NN]      without a GPU: grade on the course's GPU machines through Slurm
#   make run-gpu RUN='./lab05 ...'  without a GPU: run a command there through Slurm
#   make tradeoff-gpu OUT=DIR    on a GPU machine: make tradeoff's GPU rows (tools/gpu/tradeoff.sh)
#
# The shared GPU code is on the include path of every CUDA build, after the lab's own folder:
# common/cuda/ (error checks, device memory, timers, the scene upload, the reference
# megakernel), and for the wavefront labs common/wavefront/ (queues, pool layouts, kernels,
# stage loop, renderer). A file students write (labs/NN/skeleton/) stands in for the shared
# file of the same name, as lab 01's path_steps.h does (DESIGN.md, section 1).
#
# Architectures: the GPUs present (nvidia-smi's compute capability), or, where there is none
# (a student's machine building for `make run-gpu`), machine code for sm_75 (Turing), sm_80
# (A100), sm_86 (RTX 30), sm_89 (L4, RTX 40) and sm_90 (H100, H200) plus compute_90 PTX that
# newer GPUs compile when they load it. Under CI (CI=true) without a GPU, where nothing runs
# the binaries, only the ends of that range: compute_75 PTX (the compiler's front end rejects
# there what the oldest GPU lacks) and sm_90 machine code (what the kernel report and the
# tests read); the three between add build minutes, not checks; the benchmarks and variants
# there get sm_90 alone (CUDA_TOOL_ARCH). Set CUDA_ARCH on the command line to choose others,
# e.g. CUDA_ARCH='-arch=sm_90'.
# Without nvcc every CUDA target says so in one line and fails; nothing else is affected.

NVCC ?= nvcc
HAVE_NVCC := $(shell command -v $(NVCC) 2>/dev/null)

CUDA_ARCH_LIST := 75 80 86 89 90
CUDA_FALLBACK_ARCH := $(foreach a,$(CUDA_ARCH_LIST),-gencode arch=compute_$(a),code=sm_$(a)) \
                      -gencode arch=compute_90,code=compute_90
# Evaluated once, on first use (asking nvidia-smi costs a fraction of a second).
CUDA_GPU_CAPS = $(eval CUDA_GPU_CAPS := $$(sort $$(shell nvidia-smi \
    --query-gpu=compute_cap --format=csv,noheader 2>/dev/null | tr -d ' .')))$(CUDA_GPU_CAPS)
CUDA_CI_ARCH := -gencode arch=compute_75,code=compute_75 -gencode arch=compute_90,code=sm_90
CUDA_NO_GPU_ARCH := $(if $(filter true,$(CI)),$(CUDA_CI_ARCH),$(CUDA_FALLBACK_ARCH))
CUDA_ARCH ?= $(if $(CUDA_GPU_CAPS),$(foreach c,$(CUDA_GPU_CAPS),\
    -gencode arch=compute_$(c),code=sm_$(c)),$(CUDA_NO_GPU_ARCH))
# The benchmarks and lab 05's flag and precision variants are the labs' shared code under
# other flags: under CI without a GPU, where nothing runs them, sm_90 machine code alone (what
# the kernel report reads; the labs' own binaries put that code through compute_75's front
# end); everywhere else the labs' architectures. An object's architectures: OBJECT_CUDA_ARCH.
CUDA_TOOL_ARCH = $(if $(filter-out $(CUDA_CI_ARCH),$(CUDA_ARCH)),$(CUDA_ARCH),\
    -gencode arch=compute_90,code=sm_90)
OBJECT_CUDA_ARCH = $(CUDA_ARCH)

# Warnings as errors under CI, for our host code (-Xcompiler) and for nvcc's own.
CUDA_WARN := -Xcompiler -Wall
ifeq ($(CI),true)
CUDA_WARN := -Xcompiler -Wall,-Werror -Werror all-warnings
endif
# --threads 0: one compiler process per architecture, in parallel.
NVCCFLAGS := -std=c++17 -O3 --threads 0 $(CUDA_WARN)

# After a lab's own folders (LAB_INCLUDES), before common/core and common/host.
CUDA_INCLUDES := -Icommon/cuda
# The GPU benchmarks' own code (their main, speed targets, the wavefront benchmark): on the
# include path of the benchmarks only, never of a lab.
GPU_BENCH_INCLUDES := -Ibench/gpu

# Each object comes with the compiler's resource report of its kernels (ptxas -v: registers,
# spills and stack per kernel and architecture) in $*.ptxas beside it, which make kernel-report
# reads; what else nvcc says is shown as usual. (Both files are the one recipe's targets.)
$(BUILD)/%.o $(BUILD)/%.ptxas: %.cu
	@mkdir -p $(dir $@)
	$(NVCC) $(NVCCFLAGS) $(OBJECT_CUDA_ARCH) $(CUDA_VARIANT_FLAGS) $(LAB_INCLUDES) \
	    $(CUDA_INCLUDES) $(INCLUDES) -Xptxas -v -MMD -MP -MF $(BUILD)/$*.d -c $< -o $(BUILD)/$*.o \
	    2> $(BUILD)/$*.ptxas; status=$$?; \
	    grep -v -e '^ptxas info' -e ' bytes stack frame, ' $(BUILD)/$*.ptxas >&2; exit $$status

# The exact nvcc command lab objects are built with (tests build the pristine skeleton so).
print-cuda-build-command:
	@echo $(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) $(CUDA_INCLUDES) $(INCLUDES)

# $(1): binary stem (lab05), $(2): lab folder (05-cuda-mega), $(3): the shared GPU folders
# the lab builds on besides common/cuda (common/wavefront), $(4): the files its students
# write that stand in for shared ones (render_kernel.cuh: the lab's `shared` in labs/labs.toml).
# skeleton/ or solution/ comes first on the include path, then $(3), then CUDA_INCLUDES.
define cuda_lab
CUDA_LAB_FOLDERS += $(2)
CUDA_SHARED_INCLUDES_$(2) := $(addprefix -I,$(3))
CUDA_STUDENT_FILES_$(2) := $(4)
$(BUILD)/labs/$(2)/skeleton/%: LAB_INCLUDES = -Ilabs/$(2)/skeleton $(addprefix -I,$(3))
$(BUILD)/labs/$(2)/solution/%: LAB_INCLUDES = -Ilabs/$(2)/solution $(addprefix -I,$(3))
$(1): $(patsubst %.cu,$(BUILD)/%.o,$(wildcard labs/$(2)/skeleton/*.cu)) $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $$^ $$(INTO_TARGET)
$(1)-ref: $(patsubst %.cu,$(BUILD)/%.o,$(wildcard labs/$(2)/solution/*.cu)) $(COMMON_OBJ)
	$(NVCC) $(CUDA_ARCH) $$^ $$(INTO_TARGET)
endef

# Without nvcc, each GPU lab's targets (the registry's) say so in one line and fail; the
# labs' lab.mk files build them only where nvcc is.
ifeq ($(HAVE_NVCC),)
GPU_LAB_TARGETS := $(foreach n,$(GPU_LABS),$(LAB_TARGETS_$(n)))
.PHONY: $(GPU_LAB_TARGETS)
$(GPU_LAB_TARGETS):
	@echo "$@: needs the CUDA toolkit ($(NVCC) not found)" >&2
	@exit 1
UNBUILDABLE += $(GPU_LAB_TARGETS)
endif

.PHONY: kernel-report gpu-check print-cuda-build-command cuda-variant check-gpu-headers \
        check-speed-targets
ifeq ($(HAVE_NVCC),)
kernel-report cuda-variant check-gpu-headers check-speed-targets:
	@echo "$@: needs the CUDA toolkit ($(NVCC) not found)" >&2
	@exit 1
else
# A CUDA lab built from a folder of edited sources (the pristine skeleton, a mutant, a
# submission), as `make variant` does for the CPU labs: `make cuda-variant VARIANT_LAB=
# 05-cuda-mega VARIANT=DIR` compiles DIR/*.cu with DIR first on the include path, then the
# shared folders the lab's own build uses, and links the shared driver into DIR/lab. DIR
# must hold every file the lab's students write: without one, the shared reference of the
# same name would be compiled in its place.
cuda-variant: $(COMMON_OBJ)
	@test -n "$(VARIANT)" -a -n "$(filter $(VARIANT_LAB),$(CUDA_LAB_FOLDERS))" || \
	    { echo "cuda-variant: needs VARIANT=DIR and VARIANT_LAB=<a CUDA lab folder: $(CUDA_LAB_FOLDERS)>" >&2; exit 2; }
	@missing="$(filter-out $(notdir $(wildcard $(VARIANT)/*)),$(CUDA_STUDENT_FILES_$(VARIANT_LAB)))"; \
	    test -z "$$missing" || { echo "error: $(VARIANT) has no $$missing: lab $(VARIANT_LAB)'s students write it" >&2; exit 2; }
	$(NVCC) $(NVCCFLAGS) $(CUDA_ARCH) -I'$(VARIANT)' $(CUDA_SHARED_INCLUDES_$(VARIANT_LAB)) \
	    $(CUDA_INCLUDES) $(INCLUDES) $(call quoted,$(sort $(wildcard $(VARIANT)/*.cu))) \
	    $(COMMON_OBJ) -o '$(VARIANT)/lab'


# Each shared GPU header compiles alone, for sm_90 with warnings as errors: it includes what
# it uses, whichever file includes it first (make check-nvcc does the same for common/core).
# To PTX: nvcc's front end reads the whole file and its device code is compiled; the host
# compiler's pass, most of a full compile's time, adds nothing the labs' own builds do not check.
GPU_HEADERS := $(wildcard common/cuda/*.h common/cuda/*.cuh common/wavefront/*.cuh \
                          bench/gpu/*.h bench/gpu/*.cuh)
$(BUILD)/gpu-headers/%.ptx: %
	@mkdir -p $(dir $@)
	@printf '#include <%s>\n' $(notdir $<) > $(@:.ptx=.cu)
	$(NVCC) -std=c++17 -arch=sm_90 -Werror all-warnings -Icommon/wavefront \
	    $(GPU_BENCH_INCLUDES) $(CUDA_INCLUDES) $(INCLUDES) -MMD -MP -MF $(@:.ptx=.d) -MT $@ \
	    -ptx $(@:.ptx=.cu) -o $@
check-gpu-headers: $(patsubst %,$(BUILD)/gpu-headers/%.ptx,$(GPU_HEADERS))
	@echo "check-gpu-headers: $(words $(GPU_HEADERS)) headers of common/cuda, common/wavefront and bench/gpu compile alone for sm_90"

# Host code only: the verdicts the benchmarks print (tests/cuda/speed_targets_check.cu).
$(BUILD)/cuda/speed_targets_check: tests/cuda/speed_targets_check.cu
	@mkdir -p $(dir $@)
	$(NVCC) -std=c++17 -arch=sm_90 -Xcompiler -Wall,-Werror -Werror all-warnings \
	    $(GPU_BENCH_INCLUDES) $(CUDA_INCLUDES) $(INCLUDES) -MMD -MP -MF $@.d $< -o $@
check-speed-targets: $(BUILD)/cuda/speed_targets_check
	@$<

# The compiler's resource report (ptxas -v) for every kernel of the GPU references (every
# GPU lab of labs/labs.toml) and lab 05's benchmark (the course report's Table 1 for our
# kernels), for one architecture: the GPU present, else sm_90. Writes build/kernel-report.md.
# It reads the reports the build wrote beside those objects, so it compiles nothing the build
# has compiled; the build's architectures include this one unless CUDA_ARCH names others.
KERNEL_REPORT_ARCH = $(if $(CUDA_GPU_CAPS),sm_$(firstword $(CUDA_GPU_CAPS)),sm_90)
# A lab whose solution is not here (a student release) is reported from skeleton/: the
# student's own kernels, compiled without a GPU.
kernel_report_dir = $(if $(wildcard labs/$(1)/solution),solution,skeleton)
KERNEL_REPORT_LOGS = $(foreach n,$(GPU_LABS),\
    $(BUILD)/labs/$(LAB_FOLDER_$(n))/$(call kernel_report_dir,$(LAB_FOLDER_$(n)))/render.ptxas) \
    $(if $(wildcard labs/05-cuda-mega/solution),$(BUILD)/labs/05-cuda-mega/bench.ptxas)
kernel-report: $(KERNEL_REPORT_LOGS)
	@$(PYTHON) labs/05-cuda-mega/kernel_report.py $^ --arch $(KERNEL_REPORT_ARCH) \
	    --out $(BUILD)/kernel-report.md
endif

# Without a GPU of one's own: `make grade-gpu` grades lab LAB (`make grade` as here) and
# `make run-gpu RUN='./lab05 --out quick.ppm'` runs a command, each as one Slurm job on the
# course's GPU machines (one GPU, --gres=gpu:1), from this folder, which must be on a file system
# they see (a checkout under your home on the course's login node, where sbatch is). It waits
# for the job and prints its log (grade-gpu-JOB.log here, beside results.json and the images).
# GPU_PARTITION, GPU_TIME (default 0:30:00), GPU_MEM (default 8G) and GPU_GRES (default
# --gres=gpu:1) are the job's.
GPU_TIME ?= 0:30:00
GPU_MEM ?= 8G
GPU_GRES ?= --gres=gpu:1
.PHONY: grade-gpu run-gpu
grade-gpu: RUN = $(MAKE) --no-print-directory grade LAB=$(LAB)
grade-gpu run-gpu:
	@test -n "$(RUN)" || { echo "run-gpu: needs RUN='command', e.g. RUN='./lab$(LAB) --out quick.ppm'" >&2; exit 2; }
	@command -v sbatch >/dev/null || { echo "$@: no sbatch here: run it on the course's login node, where Slurm is (ssh there, then make $@ in your checkout)" >&2; exit 2; }
	@echo "$@: one Slurm job on a GPU machine ($(GPU_GRES) --time=$(GPU_TIME) --mem=$(GPU_MEM)$(if $(GPU_PARTITION), --partition=$(GPU_PARTITION))); waiting for it (minutes if the queue is busy)"
	@job=$$(sbatch --parsable --wait --job-name=$@-lab$(LAB) $(GPU_GRES) --time=$(GPU_TIME) \
	    --mem=$(GPU_MEM) $(if $(GPU_PARTITION),--partition=$(GPU_PARTITION)) --chdir="$(CURDIR)" \
	    --output="$(CURDIR)/$@-%j.log" --wrap='$(RUN)'); status=$$?; job=$${job%%;*}; \
	    if [ -z "$$job" ]; then echo "$@: sbatch did not take the job (its error is above)" >&2; exit 2; fi; \
	    cat "$@-$$job.log" 2>/dev/null; echo "$@: job $$job ended with status $$status; its log is $@-$$job.log"; \
	    exit $$status

# Everything a GPU machine should check, in one call: tools/gpu/check.sh OUT.
OUT ?= $(BUILD)/gpu-check
gpu-check:
	bash tools/gpu/check.sh $(OUT)

# make tradeoff's GPU rows on a GPU machine without matplotlib (tools/gpu/tradeoff.sh); the
# plots are drawn afterwards elsewhere (python3 -m tools.tradeoff --replot DIR/tradeoff).
.PHONY: tradeoff-gpu
tradeoff-gpu:
	bash tools/gpu/tradeoff.sh $(if $(filter command line,$(origin OUT)),$(OUT))
