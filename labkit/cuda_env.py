"""Whether CUDA code can be built and run here: asked once, by the grader (labkit/gpu.py),
the lab tests (tests/labs/cuda_env.py) and the tools alike. The driver comes with nvidia-smi:
no nvidia-smi, no driver; a driver that lists no GPU, no GPU."""
from __future__ import annotations

import functools
import shutil
import subprocess


@functools.lru_cache(maxsize=None)
def missing_nvcc() -> str | None:
    """Why CUDA code cannot be built here, or None."""
    return None if shutil.which("nvcc") else "no CUDA toolkit (nvcc) on this machine"


@functools.lru_cache(maxsize=None)
def missing_gpu() -> str | None:
    """Why nothing can run on an NVIDIA GPU here, or None."""
    if shutil.which("nvidia-smi") is None:
        return "this machine has no NVIDIA GPU (no driver: nvidia-smi not found)"
    try:
        p = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired) as e:
        return f"this machine's NVIDIA driver does not answer (nvidia-smi: {e})"
    if p.returncode != 0 or not p.stdout.strip():
        return "this machine has no NVIDIA GPU (nvidia-smi lists none)"
    return None


def gpu_name() -> str:
    """The first GPU's name, as nvidia-smi gives it (where missing_gpu() is None)."""
    p = subprocess.run(["nvidia-smi", "--query-gpu=name", "--format=csv,noheader"],
                       capture_output=True, text=True, check=True, timeout=60)
    return p.stdout.splitlines()[0].strip()
