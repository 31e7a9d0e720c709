// GPU time by CUDA events, and what the GPU labs say their `seconds` cover.
#pragma once

#include <cuda_runtime.h>

#include <cuda_check.h>

// RenderStats::timing of every GPU lab: `seconds` is GPU time between CUDA events around the
// kernels (each band's, summed), nothing the host does around them.
inline constexpr const char kKernelTimeOnly[] =
    "kernel only (CUDA events); excludes context creation, module load and copies";

// A pair of CUDA events around GPU work: its time on the GPU itself, which leaves out what
// the host does around it (context creation, module loading, copies).
class GpuTimer {
public:
    GpuTimer() {
        check(cudaEventCreate(&start_), "creating a CUDA event");
        const cudaError_t status = cudaEventCreate(&stop_);
        if (status != cudaSuccess) cudaEventDestroy(start_);
        check(status, "creating a CUDA event");
    }
    ~GpuTimer() {
        cudaEventDestroy(start_);
        cudaEventDestroy(stop_);
    }
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    void start() { check(cudaEventRecord(start_), "recording a CUDA event"); }
    void stop() { check(cudaEventRecord(stop_), "recording a CUDA event"); }
    // Seconds between start() and stop(); waits for stop() to be reached.
    double seconds() const {
        check(cudaEventSynchronize(stop_), "waiting for the GPU");
        float ms = 0;
        check(cudaEventElapsedTime(&ms, start_, stop_), "reading a CUDA event timer");
        return ms * 1e-3;
    }

private:
    cudaEvent_t start_ = nullptr, stop_ = nullptr;
};
