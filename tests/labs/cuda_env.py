"""Whether CUDA code can be built and run here: the reasons the CUDA labs' tests skip
(labkit/cuda_env.py, which the grader asks too)."""
from labkit.cuda_env import gpu_name, missing_gpu, missing_nvcc

NO_GPU_HINT = "tools/gpu/check.sh runs the GPU tests on a machine with one"

__all__ = ["NO_GPU_HINT", "gpu_name", "missing_gpu", "missing_nvcc"]
