// Where a path-pool layout puts neighbouring items: the bytes from a queued path's ray
// origin x at place 0 to the same field at place 1, found by storing two paths with the
// layout's own store and searching the memory it wrote. A structure of arrays puts them 4
// bytes apart; lab 06's array of structures, a record (48 bytes) apart. The wavefront labs
// report it in --json ("layout"), and lab 07's grader checks it: speed alone cannot tell
// the layouts apart, as both are within a few percent of each other on the baseline
// (handouts/07-soa.md).
#pragma once

#include <cstring>
#include <string>
#include <vector>

#include <cuda_check.h>
#include <device_array.h>
#include <path_pool.cuh>

// The ray origin x of the probe's paths at places 0 and 1: values no other field holds.
__host__ __device__ constexpr float probe_marker(int place) {
    return place == 0 ? 1234.5f : -4321.25f;
}

template <class Paths>
__global__ void store_two_probe_paths(const Paths paths) {
    const int k = static_cast<int>(threadIdx.x);
    if (k < 2)
        paths.store(
            k,
            QueuedPath{{Vec3(probe_marker(k), 0.0f, 0.0f), Vec3(0.0f, 0.0f, 1.0f)}, Vec3(0.0f), 0});
}

// The distance in bytes, or -1 when the markers are not both found (a layout that stores
// nothing: the lab 07 skeleton).
template <class Layout>
long long neighbour_bytes() {
    constexpr int kSlots = 64;
    ArrayCarver measure(nullptr, kSlots);
    typename Layout::Paths paths;
    paths.carve(measure);
    DeviceArray<unsigned char> memory(measure.bytes(), "allocating the layout probe");
    check(cudaMemset(memory.data(), 0, memory.bytes()), "clearing the layout probe");
    ArrayCarver carver(memory.data(), kSlots);
    paths.carve(carver);
    store_two_probe_paths<<<1, 32>>>(paths);
    check_launch("probing the path pool's layout");
    std::vector<unsigned char> bytes(memory.bytes());
    check(cudaMemcpy(bytes.data(), memory.data(), bytes.size(), cudaMemcpyDeviceToHost),
          "copying the layout probe back");
    long long at[2] = {-1, -1};
    for (size_t i = 0; i + sizeof(float) <= bytes.size(); i += sizeof(float)) {
        float v;
        std::memcpy(&v, &bytes[i], sizeof v);
        for (int m = 0; m < 2; ++m)
            if (v == probe_marker(m) && at[m] < 0) at[m] = static_cast<long long>(i);
    }
    return at[0] >= 0 && at[1] >= 0 ? at[1] - at[0] : -1;
}

// For --json: {"name": "SoA", "bytes_between_neighbours": 4}
template <class Layout>
std::string describe_layout() {
    return std::string("{\"name\": \"") + Layout::kName +
           "\", \"bytes_between_neighbours\": " + std::to_string(neighbour_bytes<Layout>()) + "}";
}
