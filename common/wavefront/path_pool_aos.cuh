// The path pool as an array of structures (AoS): each queued path, each shadow ray and each
// slot's radiance is one record of 16-byte rows, read and written whole (one LDG.128 or
// STG.128 per row). Lab 07 lays the same fields out as a structure of arrays behind the same
// member functions (path_pool.cuh lists them), so the kernels differ only in the layout type
// they are instantiated with.
//
// A queue is dense (path_queue.cuh): the 32 threads of a warp work on 32 neighbouring
// records, so a warp's row access covers 32 records side by side and the other rows of those
// records are then in the L1. What a stage writes without reading it first is whole records,
// which fill the 32-byte sectors memory moves (a sector written in part must be read from
// DRAM first). Rows (x, y, z, w), and who reads (r) or writes (w) them:
//
//   a queued path, 48 bytes
//     0  ray origin x y z, ray direction x       shade w (generate for bounce 0), closest hits r, shade r
//     1  ray direction y z, hit t, hit primitive  the same; closest hits writes only z, w
//     2  throughput x y z, slot                   shade w (generate), shade r
//   a queued shadow ray, 48 bytes
//     0  origin x y z, direction x                shade w, shadow rays r
//     1  direction y z, t_max, slot               shade w, shadow rays r
//     2  radiance x y z, -                        shade w, shadow rays r
//   a slot's radiance, 16 bytes
//     0  radiance x y z, -                        generate w, shade and shadow rays r/w, accumulate r
//
// A push writes its records through shared memory (RowRecords::store_together): stored one
// record per thread, a warp's 16-byte stores land 48 bytes apart and each covers twelve cache
// lines in part; staged, the block writes its run of records out as consecutive rows, every
// warp's store four whole lines.
//
// The bytes each stage moves per path, AoS against SoA: handouts/07-soa.md.
#pragma once

#include <climits>

#include <path_pool.cuh>

// One record of kRows 16-byte rows per place, taken from the pool's allocation.
template <int kRows>
struct RowRecords {
    struct alignas(16) Record {
        float4 row[kRows];
    };
    Record* records;

    void carve(ArrayCarver& c) { records = c.take<Record>(); }

    // The records of one push (path_queue.cuh): every thread of the block calls it together,
    // with the place its reserve gave it. A reserve like the reference's gives the block's
    // pushing threads one run of places, first .. first + count - 1, in whatever order; then
    // each thread puts its record at its offset in the run in shared memory, and the block
    // copies the run out row by row, consecutive threads on consecutive rows. Places that are
    // not one run, or not distinct (a reserve with one atomic per thread, or a racy one), are
    // stored by each thread as they are: only the speed depends on the reserve, never what
    // lands where.
    __device__ void store_together(int place, bool wants, const Record& record) const {
        __shared__ Record staged[kStageThreads];
        __shared__ int owner[kStageThreads];
        __shared__ int first, last, count, clash;
        const int me = static_cast<int>(threadIdx.x);
        __syncthreads();  // every thread is done with the previous push's shared state
        if (me == 0) {
            first = INT_MAX;
            last = INT_MIN;
            count = clash = 0;
        }
        __syncthreads();
        if (wants) {
            atomicMin(&first, place);
            atomicMax(&last, place);
            atomicAdd(&count, 1);
        }
        __syncthreads();
        const int run_first = first, run = count;
        const bool one_run = run > 0 && static_cast<long long>(last) - run_first == run - 1;
        if (one_run && wants) {
            staged[place - run_first] = record;
            owner[place - run_first] = me;
        }
        __syncthreads();
        if (one_run && wants && owner[place - run_first] != me) clash = 1;
        __syncthreads();
        if (!one_run || clash) {
            if (wants) records[place] = record;
            return;
        }
        const float4* from = &staged[0].row[0];
        float4* to = &records[run_first].row[0];
        for (int r = me; r < run * kRows; r += static_cast<int>(blockDim.x)) to[r] = from[r];
    }
};

struct AosPaths : RowRecords<3> {
    // The whole record: the hit's place gets "nothing hit", find_closest_hits fills it in.
    __device__ static Record record_of(const QueuedPath& p) {
        const Ray& r = p.ray;
        return {
            {make_float4(r.origin.x, r.origin.y, r.origin.z, r.direction.x),
             make_float4(r.direction.y, r.direction.z, 0.0f, __int_as_float(-1)),
             make_float4(p.throughput.x, p.throughput.y, p.throughput.z, __int_as_float(p.slot))}};
    }
    __device__ void store(int k, const QueuedPath& p) const { records[k] = record_of(p); }
    __device__ void store_together(int k, bool wants, const QueuedPath& p) const {
        RowRecords::store_together(k, wants, record_of(p));
    }
    __device__ QueuedPath load(int k) const {
        const float4 c = records[k].row[2];
        return {load_ray(k), Vec3(c.x, c.y, c.z), __float_as_int(c.w)};
    }
    __device__ Ray load_ray(int k) const {
        const float4 a = records[k].row[0], b = records[k].row[1];
        return {Vec3(a.x, a.y, a.z), Vec3(a.w, b.x, b.y)};
    }
    __device__ void store_hit(int k, const Hit& h) const {
        const PackedHit packed = pack_hit(h);
        *reinterpret_cast<float2*>(&records[k].row[1].z) =
            make_float2(packed.t, __int_as_float(packed.primitive));
    }
    __device__ Hit load_hit(int k) const {
        const float4 b = records[k].row[1];
        return unpack_hit({b.z, __float_as_int(b.w)});
    }
};

struct AosShadowRays : RowRecords<3> {
    __device__ static Record record_of(const QueuedShadowRay& q) {
        const Ray& r = q.shadow.ray;
        const Vec3& l = q.shadow.radiance;
        return {{make_float4(r.origin.x, r.origin.y, r.origin.z, r.direction.x),
                 make_float4(r.direction.y, r.direction.z, q.shadow.t_max, __int_as_float(q.slot)),
                 make_float4(l.x, l.y, l.z, 0.0f)}};
    }
    __device__ void store(int k, const QueuedShadowRay& q) const { records[k] = record_of(q); }
    __device__ void store_together(int k, bool wants, const QueuedShadowRay& q) const {
        RowRecords::store_together(k, wants, record_of(q));
    }
    __device__ QueuedShadowRay load(int k) const {
        const float4 a = records[k].row[0], b = records[k].row[1], c = records[k].row[2];
        return {{{Vec3(a.x, a.y, a.z), Vec3(a.w, b.x, b.y)}, b.z, Vec3(c.x, c.y, c.z)},
                __float_as_int(b.w)};
    }
};

struct AosRadiance : RowRecords<1> {
    __device__ void start(int slot, Vec3 v) const {
        records[slot].row[0] = make_float4(v.x, v.y, v.z, 0.0f);
    }
    __device__ void add(int slot, Vec3 v) const { start(slot, load(slot) + v); }
    __device__ Vec3 load(int slot) const {
        const float4 v = records[slot].row[0];
        return Vec3(v.x, v.y, v.z);
    }
};

struct AosPathPool {
    static constexpr const char* kName = "AoS";
    using Paths = AosPaths;
    using ShadowRays = AosShadowRays;
    using Radiance = AosRadiance;
};
