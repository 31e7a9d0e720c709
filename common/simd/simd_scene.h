// Lab 02, SIMD across primitives (simd_geometry.h): the scene's primitives as a structure of
// arrays, 8 to a packet, so that one AVX2 load fetches the same field of 8 primitives
// (Embree's layout for its 8-wide nodes and triangles, without the BVH).
//
//   TrianglePacket (one per 8 triangles, 32-byte aligned, 416 bytes)
//     vertex[0][x]: | t0.v0.x | t1.v0.x | t2.v0.x | ... | t7.v0.x |   <- one __m256
//     vertex[0][y]: | t0.v0.y | t1.v0.y | ...                      |
//     ...            (3 vertices x 3 axes = 9 rows)
//     normal[x..z], plane_offset                                       (4 more rows)
//
//   RectPacket (one per 8 axis-aligned rectangles, 32-byte aligned, 192 bytes)
//     plane, lo[u], lo[v], hi[u], hi[v], axis: one row each, a lane per rectangle
//
// The last packet is padded with triangles that are never hit (zero normal: the plane cull
// rejects them), spheres that are never hit (radius squared -1) and rectangles that are never
// hit (a NaN plane), so no loop needs a tail. Convex quads stay in the SceneView's array and
// are tested one at a time: no scene of the course has many.
// Only geometry lives here: materials and shading normals are read from the SceneView
// through the index that a Hit records (packet * 8 + lane, the primitive's own index).
//
// Plain data and no intrinsics, so any translation unit may include it.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <scene_view.h>

constexpr int kSimdWidth = 8;  // AVX2: 8 floats per register

// 8 triangles, field by field.
struct alignas(32) TrianglePacket {
    float vertex[3][3][kSimdWidth];  // [vertex v0..v2][axis x..z][lane]
    float normal[3][kSimdWidth];     // unit geometric normal [axis][lane]; zero in padding lanes
    float plane_offset[kSimdWidth];  // dot(normal, v0), as Triangle::plane_offset
};

// 8 spheres, field by field.
struct alignas(32) SpherePacket {
    float center[3][kSimdWidth];  // [axis][lane]
    float radius2[kSimdWidth];    // radius * radius; -1 in padding lanes (never hit)
};

// 8 axis-aligned rectangles (axis_rect.h), field by field: each lane has its own axis.
struct alignas(32) RectPacket {
    float plane[kSimdWidth];         // AxisRect::plane; NaN in padding lanes (never hit)
    float lo[2][kSimdWidth];         // [u, v][lane]: lo_u, lo_v
    float hi[2][kSimdWidth];         // hi_u, hi_v
    int32_t axis[kSimdWidth];        // rect_axis
};

// Non-owning view of the packets: what the 8-wide closest_hit / occluded read.
struct SimdSceneView {
    const TrianglePacket* triangles;  // ceil(num_triangles / 8) packets
    int num_triangle_packets;
    const SpherePacket* spheres;  // ceil(num_spheres / 8) packets
    int num_sphere_packets;
    const RectPacket* rects;  // ceil(num_rects / 8) packets
    int num_rect_packets;
    // The scene's own arrays: the kinds tested one by one (convex quads, and any kind with no
    // packet here, simd_geometry.h).
    SceneView one_by_one;
};

// The SoA copy of a scene's spheres, triangles and rectangles. Owns its packets (a copy of
// it, say one per renderer object, shares only the scene's arrays of the other kinds); building it costs
// microseconds.
class SimdScene {
public:
    explicit SimdScene(const SceneView& scene)
        : triangles_(packets_for(scene.of<Triangle>().count)),
          spheres_(packets_for(scene.of<Sphere>().count)),
          rects_(packets_for(scene.of<AxisRect>().count)),
          scene_(scene) {
        for (int i = 0; i < scene.of<Triangle>().count; ++i) {
            const Triangle& tri = scene.of<Triangle>()[i];
            TrianglePacket& p = triangles_[i / kSimdWidth];
            const int lane = i % kSimdWidth;
            const Vec3 v[3] = {tri.v0, tri.v1, tri.v2};
            for (int k = 0; k < 3; ++k) {
                for (int axis = 0; axis < 3; ++axis) p.vertex[k][axis][lane] = v[k][axis];
            }
            for (int axis = 0; axis < 3; ++axis) p.normal[axis][lane] = tri.normal[axis];
            p.plane_offset[lane] = tri.plane_offset;
        }
        for (SpherePacket& p : spheres_) {
            for (float& r2 : p.radius2) r2 = -1.0f;  // padding until a sphere fills the lane
        }
        for (int i = 0; i < scene.of<Sphere>().count; ++i) {
            const Sphere& s = scene.of<Sphere>()[i];
            SpherePacket& p = spheres_[i / kSimdWidth];
            const int lane = i % kSimdWidth;
            for (int axis = 0; axis < 3; ++axis) p.center[axis][lane] = s.center[axis];
            p.radius2[lane] = s.radius * s.radius;  // the same rounding as intersect_sphere's
        }
        for (RectPacket& p : rects_) {
            for (float& plane : p.plane) plane = NAN;  // padding until a rectangle fills the lane
        }
        for (int i = 0; i < scene.of<AxisRect>().count; ++i) {
            const AxisRect& r = scene.of<AxisRect>()[i];
            RectPacket& p = rects_[i / kSimdWidth];
            const int lane = i % kSimdWidth;
            p.plane[lane] = r.plane;
            p.lo[0][lane] = r.lo_u;
            p.lo[1][lane] = r.lo_v;
            p.hi[0][lane] = r.hi_u;
            p.hi[1][lane] = r.hi_v;
            p.axis[lane] = rect_axis(r);
        }
    }

    SimdSceneView view() const {
        return {triangles_.data(),
                static_cast<int>(triangles_.size()),
                spheres_.data(),
                static_cast<int>(spheres_.size()),
                rects_.data(),
                static_cast<int>(rects_.size()),
                scene_};
    }

private:
    // Value-initialised packets: every padding field is zero until filled.
    static size_t packets_for(int count) {
        return static_cast<size_t>((count + kSimdWidth - 1) / kSimdWidth);
    }

    std::vector<TrianglePacket> triangles_;  // C++17 new honours alignas(32)
    std::vector<SpherePacket> spheres_;
    std::vector<RectPacket> rects_;
    SceneView scene_;  // its arrays are not owned: the scene's
};
