// The path pool as an array of structures (AoS): one record per slot holding everything the
// stages pass each other about that path. Lab 07 turns it into a structure of arrays with the
// same member functions, so the kernels (wavefront_kernels.cuh) are written once against
// this interface and differ only in the layout type they are instantiated with:
//
//   static size_t bytes_for(int slots)   device memory a pool of that many slots takes
//   static Pool carve(void*, int slots)  the pool laid out in one such allocation
//   load_path / store_path               the core's PathState (shade_hits, generate)
//   load_ray                             only the ray (find_closest_hits)
//   load_hit / store_hit                 the closest hit found for the ray
//   load_shadow / store_shadow           the shadow ray the bounce step asked for
//   load_radiance / add_radiance         what the path has gathered (shadow rays, the sum)
//
// The bytes each stage moves per path, AoS against SoA: handouts/07-soa.md.
#pragma once

#include <cstddef>

#include <path_tracer.h>

struct AosPathPool {
    // One path's record: 56 + 12 + 40 = 108 bytes, 4-byte aligned.
    struct Record {
        PathState path;    // ray, throughput, radiance, bounce, alive
        Hit hit;           // what find_closest_hits found for path.ray
        ShadowRay shadow;  // the light sample of the last diffuse hit, if any
    };
    Record* records;  // one per slot

    static constexpr const char* kName = "AoS";
    static size_t bytes_for(int slots) { return sizeof(Record) * static_cast<size_t>(slots); }
    static AosPathPool carve(void* memory, int /*slots*/) {
        return {static_cast<Record*>(memory)};
    }

    __device__ PathState load_path(int i) const { return records[i].path; }
    __device__ void store_path(int i, const PathState& p) const { records[i].path = p; }
    __device__ Ray load_ray(int i) const { return records[i].path.ray; }
    __device__ Hit load_hit(int i) const { return records[i].hit; }
    __device__ void store_hit(int i, const Hit& h) const { records[i].hit = h; }
    __device__ ShadowRay load_shadow(int i) const { return records[i].shadow; }
    __device__ void store_shadow(int i, const ShadowRay& s) const { records[i].shadow = s; }
    __device__ Vec3 load_radiance(int i) const { return records[i].path.radiance; }
    __device__ void add_radiance(int i, Vec3 r) const { records[i].path.radiance += r; }
};
