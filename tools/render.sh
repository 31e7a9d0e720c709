#!/usr/bin/env bash
# `make render`: the default scene (Cornell box, 600x600, 512 spp, 4 bounces) to cornell.ppm
# with the fastest reference this machine can run: the CUDA megakernel where a GPU and nvcc
# are present, else OpenMP on every core over lab 02's packets at the CPU's width (16 AVX-512
# lanes where it has them, else 8 of AVX2, compacted), else plain OpenMP.
set -uo pipefail
cd "$(dirname "$0")/.."
MAKE=${MAKE:-make}
out=cornell.ppm

say() { echo "make render: $*"; }

try() {  # try TARGET DESCRIPTION: build and run it; non-zero if either fails
    local target=$1 what=$2
    say "using $target ($what)"
    "$MAKE" --no-print-directory -s -j"$(nproc)" "$target" >/dev/null || { say "$target did not build"; return 1; }
    "./$target" --out "$out"
}

done_with() {
    say "wrote $out with $1"
    say "the serial baseline (lab 01, one core) renders the same image: make lab01-ref && ./lab01-ref --out cornell-serial.ppm"
    exit 0
}

if command -v nvcc >/dev/null && nvidia-smi -L >/dev/null 2>&1; then
    try lab05-ref "CUDA megakernel on $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" \
        && done_with lab05-ref
    say "the GPU render failed; falling back to the CPU"
fi
if grep -qw avx2 /proc/cpuinfo && grep -qw fma /proc/cpuinfo; then
    width="8 paths per AVX2 packet"
    if grep -w avx512f /proc/cpuinfo | grep -w avx512dq | grep -w avx512vl | grep -qw avx512bw; then
        width="16 paths per AVX-512 packet"
    fi
    try lab03-simd-ref "OpenMP on all $(nproc) cores, $width, compacted" && done_with lab03-simd-ref
else
    try lab03-ref "OpenMP on all $(nproc) cores" && done_with lab03-ref
fi
say "rendering failed"
exit 1
