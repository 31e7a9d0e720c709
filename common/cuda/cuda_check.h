// Every CUDA call of the CUDA labs goes through check(): a failure becomes one line naming
// what was being done and what CUDA said, and the shared main exits with status 3 on it
// (kExitDeviceError). The owning wrappers (device_array.h, gpu_timer.h) release what they
// hold on every path out, errors included.
#pragma once

#include <cuda_runtime.h>

#include <string>

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
