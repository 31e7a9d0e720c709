// The path pool as an array of structures (AoS): one record per slot holding everything the
// stages pass each other about that path. Lab 07 turns it into a structure of arrays with the
// same member functions, so the kernels (wavefront_kernels.cuh) are written once against
// this interface and differ only in the layout type they are instantiated with:
//
//   static size_t bytes_for(int slots)   device memory a pool of that many slots takes
//   static Pool carve(void*, int slots)  the pool laid out in one such allocation
//   start_path                           a new camera path: ray, throughput, zero radiance
//   load_path(i, bounce)                 the core's PathState as shade_hits needs it
//   store_path                           the next ray and throughput of a path that goes on
//   load_ray                             only the ray (find_closest_hits)
//   load_hit / store_hit                 the closest hit found for the ray (8 bytes)
//   load_shadow / store_shadow           the shadow ray the bounce step asked for
//   load_radiance / add_radiance         what the path has gathered (shadow rays, the sum)
//
// What the pool does not store, because the queues already say it: a path's bounce number
// (every path on the active queue of bounce b is about to make interaction b) and whether it
// is alive (it is alive while it is on a queue). What shade_hits does not write back: the
// radiance, which only grows by additions (add_radiance), and the ray and throughput of a
// path that has ended.
//
// The record is one 128-byte cache line of eight 16-byte rows, each read and written whole
// (one LDG.128 or STG.128). A warp's 32 threads touch 32 records at once, so every access is
// scattered; what keeps it cheap is that the rows a stage needs are side by side, and that
// what a stage writes without reading it first fills whole 32-byte sectors (two rows):
// memory moves sectors, and a sector written in part must be read from DRAM first. (The
// first version of this pool stored the core's structs as they are, field by field, 108
// bytes a record: every 4-byte access cost the warp 32 transactions, and it ran 2.4 times
// slower than lab 07's SoA.) Rows (x, y, z, w), and who reads (r) or writes (w) them:
//
//   0  ray origin x y z, ray direction x        generate w, closest hits r, shade r/w
//   1  ray direction y z, hit t, hit primitive  the same; closest hits writes only z, w
//   2  throughput x y z                         generate w, shade r/w
//   3  radiance x y z                           generate w, shadow rays r/w, accumulate r
//   4  shadow origin x y z, shadow direction x  shade w, shadow rays r
//   5  shadow direction y z, shadow t_max       shade w, shadow rays r
//   6  shadow radiance x y z                    shade w, shadow rays r
//   7  nothing: written with row 6, so that shade writes that sector whole
//
// The bytes each stage moves per path, AoS against SoA: handouts/07-soa.md.
#pragma once

#include <cstddef>

#include <path_tracer.h>

#include "packed_hit.cuh"

struct AosPathPool {
    struct alignas(128) Record {
        float4 row[8];
    };
    Record* records;  // one per slot

    static constexpr const char* kName = "AoS";
    static size_t bytes_for(int slots) { return sizeof(Record) * static_cast<size_t>(slots); }
    static AosPathPool carve(void* memory, int /*slots*/) {
        return {static_cast<Record*>(memory)};
    }

    __device__ void start_path(int i, const PathState& p) const {
        store_ray(i, p.ray);
        store_xyz(i, 2, p.throughput);
        store_xyz(i, 3, p.radiance);
    }
    __device__ PathState load_path(int i, int bounce) const {
        return {load_ray(i), load_xyz(i, 2), Vec3(0.0f), bounce, true};
    }
    __device__ void store_path(int i, const PathState& p) const {
        store_ray(i, p.ray);
        store_xyz(i, 2, p.throughput);
    }
    __device__ Ray load_ray(int i) const {
        const float4 a = records[i].row[0], b = records[i].row[1];
        return {Vec3(a.x, a.y, a.z), Vec3(a.w, b.x, b.y)};
    }
    __device__ Hit load_hit(int i) const {
        const float4 b = records[i].row[1];
        return unpack_hit({b.z, __float_as_int(b.w)});
    }
    __device__ void store_hit(int i, const Hit& h) const {
        const PackedHit packed = pack_hit(h);
        *reinterpret_cast<float2*>(&records[i].row[1].z) =
            make_float2(packed.t, __int_as_float(packed.primitive));
    }
    __device__ ShadowRay load_shadow(int i) const {
        const float4 a = records[i].row[4], b = records[i].row[5];
        return {{Vec3(a.x, a.y, a.z), Vec3(a.w, b.x, b.y)}, b.z, load_xyz(i, 6)};
    }
    __device__ void store_shadow(int i, const ShadowRay& s) const {
        const Ray& r = s.ray;
        records[i].row[4] = make_float4(r.origin.x, r.origin.y, r.origin.z, r.direction.x);
        records[i].row[5] = make_float4(r.direction.y, r.direction.z, s.t_max, 0.0f);
        store_xyz(i, 6, s.radiance);
        records[i].row[7] = make_float4(0.0f, 0.0f, 0.0f, 0.0f);
    }
    __device__ Vec3 load_radiance(int i) const { return load_xyz(i, 3); }
    __device__ void add_radiance(int i, Vec3 r) const { store_xyz(i, 3, load_xyz(i, 3) + r); }

private:
    // Rows 0 and 1 whole: the hit's place gets zeros, find_closest_hits fills it in.
    __device__ void store_ray(int i, const Ray& r) const {
        records[i].row[0] = make_float4(r.origin.x, r.origin.y, r.origin.z, r.direction.x);
        records[i].row[1] = make_float4(r.direction.y, r.direction.z, 0.0f, 0.0f);
    }
    __device__ Vec3 load_xyz(int i, int row) const {
        const float4 v = records[i].row[row];
        return Vec3(v.x, v.y, v.z);
    }
    __device__ void store_xyz(int i, int row, Vec3 v) const {
        records[i].row[row] = make_float4(v.x, v.y, v.z, 0.0f);
    }
};
