"""What grading a GPU lab (kind "gpu" in labs/labs.toml) needs of the machine: an NVIDIA
GPU, and a sandbox that lets a CUDA program reach it.

A CUDA program talks to the driver through device nodes (/dev/nvidiactl, /dev/nvidia-uvm,
/dev/nvidia0, ...) and the driver's user-space library (libcuda.so), which the CUDA runtime
linked into every lab binary loads at start-up. bubblewrap's `--dev /dev` gives a sandbox a
minimal /dev without them, and `--clearenv` drops the LD_LIBRARY_PATH that finds libcuda.so
where it lies outside the loader's cache (/usr/local/nvidia/lib64 on container GPU machines).
So a GPU lab's runs get exactly those nodes and folders, read-only for the folders, and the
sysfs folders the driver may read (SYSFS); CPU labs get none of it.
"""
from __future__ import annotations

import functools
import glob
import os
import subprocess

from labkit import registry
from labkit.cuda_env import missing_gpu

# The labs that run on a GPU: those of kind "gpu" in labs/labs.toml.
GPU_LABS = frozenset(registry.gpu_labs())

DEV = "/dev"
# Where the driver's libcuda.so may live: Debian/Ubuntu's multiarch folder, the folder the
# NVIDIA container runtime mounts, the RPM distributions' folder. The grader's own
# LD_LIBRARY_PATH is searched too (lib_dirs()).
DRIVER_LIB_DIRS = ("/usr/lib/x86_64-linux-gnu", "/usr/local/nvidia/lib64", "/usr/lib64")
# What the driver's library may read to place the GPU (its PCI device, NUMA node, the
# module's parameters), as flatpak shows it to sandboxed GPU programs: read-only hardware
# facts, no one's data. The sandbox otherwise shows only /sys/devices/system/{cpu,node}.
SYSFS = ("/sys/bus/pci", "/sys/devices", "/sys/module/nvidia")


def is_gpu_lab(lab: str) -> bool:
    return lab in GPU_LABS


@functools.lru_cache(maxsize=None)
def cuda_arch_flags() -> str:
    """nvcc's target for the GPUs here ("-gencode arch=compute_90,code=sm_90" for an H200), or
    "" where nvidia-smi lists none. A submission's CUDA sources are compiled in the sandbox,
    where nvidia-smi cannot reach the driver, so cuda.mk would build for its whole fallback
    list (five architectures and PTX): six compilations for a program that runs here only,
    in parallel threads of one nvcc that then need more address space than the sandbox's
    limit leaves it."""
    if missing_gpu():
        return ""
    try:
        p = subprocess.run(["nvidia-smi", "--query-gpu=compute_cap", "--format=csv,noheader"],
                           capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return ""
    caps = sorted({line.strip().replace(".", "") for line in p.stdout.splitlines()
                   if line.strip().replace(".", "").isdigit()})
    return " ".join(f"-gencode arch=compute_{c},code=sm_{c}" for c in caps)


def device_nodes(dev: str = DEV) -> list[str]:
    """The NVIDIA device nodes present (names below `dev`): nvidiactl, nvidia-uvm,
    nvidia-uvm-tools, nvidia0, nvidia1, ..., and the nvidia-caps folder (MIG)."""
    return sorted(os.path.basename(p) for p in glob.glob(os.path.join(dev, "nvidia*")))


def node_paths(dev: str = DEV) -> list[str]:
    """Every NVIDIA device node's path, which a sandboxed CUDA program opens for writing (its
    driver's requests go through them: labkit/confine.py lets it)."""
    return [os.path.join(dev, name) for name in device_nodes(dev)]


def lib_dirs(candidates=DRIVER_LIB_DIRS, environment: str | None = None) -> list[str]:
    """The folders, of `candidates` and of the LD_LIBRARY_PATH `environment` (default: the
    grader's), that hold the driver's library libcuda.so*, in that order, each once."""
    if environment is None:
        environment = os.environ.get("LD_LIBRARY_PATH", "")
    found = []
    for folder in [*environment.split(":"), *candidates]:
        if folder and folder not in found and glob.glob(os.path.join(folder, "libcuda.so*")):
            found.append(folder)
    return found


def gpu_minor_numbers(proc: str = "/proc/driver/nvidia/gpus") -> dict[str, str]:
    """nvidia-smi's index of each GPU -> the minor number of its device node (/dev/nvidiaN);
    {} where nvidia-smi lists none. The two can differ: the index follows the PCI bus, the
    minor number the order the driver found the devices in. nvidia-smi gives each index's PCI
    address; the driver's folder for that address (`proc`) names its minor number."""
    try:
        p = subprocess.run(["nvidia-smi", "--query-gpu=index,pci.bus_id",
                            "--format=csv,noheader"], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return {}
    minors = {}
    for line in p.stdout.splitlines() if p.returncode == 0 else []:
        index, _, bus = (part.strip() for part in line.partition(","))
        # nvidia-smi writes an 8-digit PCI domain (00000000:00:06.0), the driver 4 digits.
        folder = os.path.join(proc, bus.lower()[-12:], "information")
        try:
            with open(folder) as f:
                minor = next((line.split(":", 1)[1].strip() for line in f
                              if line.startswith("Device Minor:")), "")
        except OSError:
            continue
        if index.isdigit() and minor.isdigit():
            minors[index] = minor
    return minors


def assigned_node(environment=None, minors=None) -> str | None:
    """The device node of the one GPU this grader was given, or None (then every GPU's node is
    shown). grading/classes/batch.py gives each grader one GPU as CUDA_VISIBLE_DEVICES=<nvidia-smi
    index> with CUDA_DEVICE_ORDER=PCI_BUS_ID (so CUDA counts as nvidia-smi does). The sandbox
    clears the environment, so the assignment reaches a sandboxed program as the one node it
    shows: CUDA then finds that GPU only, as in a container given one GPU."""
    environment = os.environ if environment is None else environment
    visible = environment.get("CUDA_VISIBLE_DEVICES", "").strip()
    if not visible.isdigit():  # unset, several GPUs, a UUID: not one index
        return None
    minor = (gpu_minor_numbers() if minors is None else minors).get(visible)
    return f"nvidia{minor}" if minor is not None else None


_FROM_ENVIRONMENT = object()


def sandbox_args(dev: str = DEV, libs: list[str] | None = None, sysfs=SYSFS,
                 only=_FROM_ENVIRONMENT) -> list[str]:
    """bubblewrap arguments that give a sandboxed CUDA program the GPU: each NVIDIA device
    node, bound as a device (`--dev-bind`; it must come after `--dev /dev`), the `sysfs`
    folders read-only where they exist, and each folder holding libcuda.so, read-only, with
    LD_LIBRARY_PATH naming them (it must come after `--clearenv`). Built from what exists:
    on a machine without a GPU (no device node) it is empty. `only` (default: assigned_node()
    of the grader's environment) names the one GPU node to show; the others are left out, and
    the nodes every GPU shares (nvidiactl, nvidia-uvm, ...) stay."""
    libs = lib_dirs() if libs is None else libs
    nodes = device_nodes(dev)
    if not nodes:
        return []
    only = assigned_node() if only is _FROM_ENVIRONMENT else only
    if only is not None and only in nodes:
        nodes = [n for n in nodes if n == only or not n.removeprefix("nvidia").isdigit()]
    args: list[str] = []
    for name in nodes:
        args += ["--dev-bind", os.path.join(dev, name), f"/dev/{name}"]
    for folder in sysfs:
        args += ["--ro-bind-try", folder, folder]
    for folder in libs:
        args += ["--ro-bind", folder, folder]
    if libs:
        args += ["--setenv", "LD_LIBRARY_PATH", ":".join(libs)]
    return args
