// Lab 05's megakernel (render_kernel, over the loops of render_kernel.cuh, the file its
// students write, and the parts of megakernel_parts.cuh): what lab 05's renderer and benchmark
// include, and the wavefront benchmark (bench/gpu/wavefront_bench.cuh), which measures the
// wavefront labs against it.
#pragma once

#include <render_kernel.cuh>
