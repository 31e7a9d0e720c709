// Every CUDA call of the CUDA labs goes through check(): a failure becomes one line naming
// what was being done and what CUDA said, and the shared main exits non-zero with it. Owning
// wrappers free device memory and events on every path out, errors included.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <string>
#include <utility>

#include <errors.h>

// A GPU failure: no device, a failed allocation or copy, a kernel fault. The shared main
// reports a DeviceError as one line ("error: ...") and exit status 3, after the output
// files' destructors have removed their temporaries.
struct GpuError : DeviceError {
    using DeviceError::DeviceError;
};

// Throws GpuError "GPU: <what>: <CUDA's message> (<error name>)" unless `status` is success.
inline void check(cudaError_t status, const char* what) {
    if (status == cudaSuccess) return;
    throw GpuError(std::string("GPU: ") + what + ": " + cudaGetErrorString(status) + " (" +
                   cudaGetErrorName(status) + ")");
}

// After a launch: the launch itself (bad configuration) and, once the kernel has run, any
// fault inside it. Both are asynchronous, so a launch needs both checks.
inline void check_launch(const char* what) {
    check(cudaGetLastError(), what);
    check(cudaDeviceSynchronize(), what);
}

// An array in device memory, freed when it goes out of scope.
template <class T>
class DeviceArray {
public:
    DeviceArray() = default;
    DeviceArray(size_t count, const char* what) : count_(count) {
        void* p = nullptr;
        check(cudaMalloc(&p, count * sizeof(T) + (count == 0)), what);  // never a 0-byte ask
        data_ = static_cast<T*>(p);
    }
    ~DeviceArray() { cudaFree(data_); }  // nothing to report on the way out
    DeviceArray(DeviceArray&& other) noexcept : data_(other.data_), count_(other.count_) {
        other.data_ = nullptr;
        other.count_ = 0;
    }
    DeviceArray& operator=(DeviceArray&& other) noexcept {
        std::swap(data_, other.data_);
        std::swap(count_, other.count_);
        return *this;
    }
    DeviceArray(const DeviceArray&) = delete;
    DeviceArray& operator=(const DeviceArray&) = delete;

    T* data() const { return data_; }
    size_t size() const { return count_; }
    size_t bytes() const { return count_ * sizeof(T); }

private:
    T* data_ = nullptr;  // device pointer, or null
    size_t count_ = 0;   // elements
};

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

// The first CUDA device, checked: one line when there is none or the driver cannot run it.
// Returns its properties; creates the context now, so nothing timed later pays for it.
inline cudaDeviceProp open_device() {
    int count = 0;
    const cudaError_t status = cudaGetDeviceCount(&count);
    if (status == cudaErrorNoDevice || (status == cudaSuccess && count == 0)) {
        throw GpuError("GPU: no CUDA GPU found (the CUDA labs render on an NVIDIA GPU)");
    }
    if (status == cudaErrorInsufficientDriver) {  // also what a machine with no driver says
        throw GpuError("GPU: no usable CUDA GPU: no NVIDIA driver, or one older than this "
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
           std::to_string(prop.minor) + ", " + std::to_string(prop.multiProcessorCount) +
           " SMs)";
}
