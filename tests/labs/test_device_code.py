"""The host+device code in common/ compiles under nvcc (the CUDA labs reuse it). Nothing runs
on a GPU here; the CUDA labs' own tests do that on a machine with a GPU (tools/gpu/check.sh)."""
import shutil
import subprocess

import pytest

from labkit.harness import ROOT


@pytest.mark.skipif(shutil.which("nvcc") is None, reason="no CUDA toolkit (nvcc) on this machine")
def test_common_compiles_for_the_gpu():
    p = subprocess.run(["make", "-s", "-C", str(ROOT), "check-nvcc"], capture_output=True,
                       text=True, timeout=300)
    assert p.returncode == 0, p.stdout + p.stderr
