"""Fixtures of the CUDA labs' tests: the toolkit, the GPU, lab 05's binaries.

Tests that need only nvcc (building, the compiler's report, bad input, which the shared main
rejects before any GPU work) run wherever nvcc is, CI included. Tests that render need an
NVIDIA GPU; elsewhere they skip and say why. tools/gpu/check.sh runs them on a GPU machine."""
import pytest
from cuda_env import NO_GPU_HINT, missing_gpu, missing_nvcc

from labkit.harness import build


@pytest.fixture(scope="session")
def nvcc():
    """Skips the test where CUDA code cannot be built."""
    if reason := missing_nvcc():
        pytest.skip(reason)


@pytest.fixture(scope="session")
def gpu(nvcc):
    """Skips the test where there is no GPU to run on."""
    if reason := missing_gpu():
        pytest.skip(f"{reason}; {NO_GPU_HINT}")


@pytest.fixture(scope="session")
def lab05_ref(nvcc):
    return build("lab05-ref")[0]


@pytest.fixture(scope="session")
def lab05(nvcc):
    """The student's own lab-05 build (whatever state it is in)."""
    return build("lab05")[0]
