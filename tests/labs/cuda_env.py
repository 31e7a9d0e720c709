"""Whether CUDA code can be built and run here: the reasons the CUDA labs' tests skip."""
import functools
import shutil
import subprocess

NO_GPU_HINT = "tools/gpu/check.sh runs the GPU tests on a machine with one"


@functools.lru_cache(maxsize=None)
def missing_nvcc() -> str | None:
    """Why CUDA code cannot be built here, or None."""
    return None if shutil.which("nvcc") else "no CUDA toolkit (nvcc) on this machine"


@functools.lru_cache(maxsize=None)
def missing_gpu() -> str | None:
    """Why nothing can run on a GPU here, or None. Asks nvidia-smi, which comes with the
    driver: no driver, no GPU."""
    if shutil.which("nvidia-smi") is None:
        return f"no NVIDIA GPU here (no driver: nvidia-smi not found); {NO_GPU_HINT}"
    p = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                       capture_output=True, text=True, timeout=60)
    if p.returncode != 0 or not p.stdout.strip():
        return f"no NVIDIA GPU here (nvidia-smi lists none); {NO_GPU_HINT}"
    return None


def gpu_name() -> str:
    p = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                       capture_output=True, text=True, check=True)
    return p.stdout.splitlines()[0].strip()
