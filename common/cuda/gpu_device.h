// Opening the GPU a lab renders on, and naming it.
#pragma once

#include <cuda_runtime.h>

#include <string>

#include <cuda_check.h>

// The first CUDA device, checked: one line when there is none or the driver cannot run it.
// Returns its properties; creates the context now, so nothing timed later pays for it.
inline cudaDeviceProp open_device() {
    int count = 0;
    const cudaError_t status = cudaGetDeviceCount(&count);
    if (status == cudaErrorNoDevice || (status == cudaSuccess && count == 0)) {
        throw GpuError("GPU: no CUDA GPU found (the CUDA labs render on an NVIDIA GPU)");
    }
    if (status == cudaErrorInsufficientDriver) {  // also what a machine with no driver says
        throw GpuError(
            "GPU: no usable CUDA GPU: no NVIDIA driver, or one older than this "
            "program's CUDA runtime (cudaErrorInsufficientDriver)");
    }
    check(status, "looking for a CUDA GPU");
    check(cudaSetDevice(0), "selecting GPU 0");
    check(cudaFree(nullptr), "creating the CUDA context");
    cudaDeviceProp prop{};
    check(cudaGetDeviceProperties(&prop, 0), "reading the GPU's properties");
    return prop;
}

// "NVIDIA H200 (sm_90, 132 SMs)": what RenderStats::device says.
inline std::string describe(const cudaDeviceProp& prop) {
    return std::string(prop.name) + " (sm_" + std::to_string(prop.major) +
           std::to_string(prop.minor) + ", " + std::to_string(prop.multiProcessorCount) + " SMs)";
}
