// Device memory owned by a host object: freed on every path out, errors included, so a
// failure part-way through a render leaks nothing.
#pragma once

#include <cuda_runtime.h>

#include <cstddef>
#include <utility>

#include <cuda_check.h>

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
