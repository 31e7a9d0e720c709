// Lab 02, a worked example: SIMD across primitives. One ray is tested against 8 primitives per
// AVX2 instruction, over the structure-of-arrays packets of simd_scene.h, and the shared path
// loop of path_tracer.h does the rest (it is generic over its geometry: passing a
// SimdSceneView instead of a SceneView makes it call the overloads below).
//
// It is exact: per lane the arithmetic is the scalar code's, so every distance and every hit
// is lab 01's and the image is lab 01's, bit for bit. And it gains little (./lab02-prims
// measures it): only closest_hit and occluded are vectorised, about two thirds of lab 01's
// time; and even those gain little in a scene of 6 primitives (the Cornell box's 5
// rectangles and a sphere), where 3 of 8 rectangle lanes and 7 of 8 sphere lanes are padding,
// each lane picks the ray's components for its own axis with selects, and each packet ends in
// a horizontal minimum (with triangles, a packet also runs the full test whenever any of its 8
// passes the plane cull, where the scalar loop rejects most after the cull alone). Convex
// quads, which no shipped scene has, are tested one at a time. Part B's packet tracer
// (packet_tracer.h) vectorises the whole path instead, 8 rays per instruction.
#pragma once

#include <path_tracer.h>
#include <simd8.h>
#include <simd_scene.h>

// One ray in all 8 lanes, with the per-ray constants of the watertight test: computed once
// per ray, used for every packet.
struct BroadcastRay {
    RayShear shear;      // axis permutation and shear (triangle.h)
    Vec3x8 origin;       // the same in every lane
    Vec3x8 direction;
    Float8 sx, sy;       // the shear constants

    explicit BroadcastRay(const Ray& r)
        : shear(r.direction),
          origin(r.origin),
          direction(r.direction),
          sx(shear.sx),
          sy(shear.sy) {}
};

inline Vec3x8 load3(const float (&rows)[3][kSimdWidth]) {
    return {Float8::load(rows[0]), Float8::load(rows[1]), Float8::load(rows[2])};
}

// intersect_sphere (sphere.h) for one ray against 8 spheres.
inline Float8 intersect_spheres8(const BroadcastRay& r, const SpherePacket& p, Float8 t_max) {
    const Vec3x8 f = r.origin - load3(p.center);
    const Float8 b = -dot(f, r.direction);
    const Vec3x8 perpendicular = f + r.direction * b;
    const Float8 r2 = Float8::load(p.radius2);
    const Float8 disc = r2 - length_squared(perpendicular);
    const Mask8 crosses = disc >= 0.0f;
    if (none(crosses)) return t_max;
    const Float8 q = b + copysign(sqrt(disc), b);
    const Float8 c = length_squared(f) - r2;
    const Float8 t_a = c / q;
    const Float8 t_b = q;
    const Float8 t_near = min(t_a, t_b);
    const Float8 t_far = max(t_a, t_b);
    const Mask8 near_ok = (t_near > 0.0f) & (t_near < t_max);
    const Mask8 far_ok = (t_far > 0.0f) & (t_far < t_max);
    return select(crosses, select(near_ok, t_near, select(far_ok, t_far, t_max)), t_max);
}

// intersect_triangle (triangle.h) for one ray against 8 triangles. The axis permutation is
// the ray's, the same in every lane, so it picks rows of the packet, not lanes.
inline Float8 intersect_triangles8(const BroadcastRay& r, const TrianglePacket& p, Float8 t_max) {
    const Vec3x8 normal = load3(p.normal);
    const Float8 denom = dot(normal, r.direction);
    const Float8 num = Float8::load(p.plane_offset) - dot(normal, r.origin);
    const Mask8 not_behind{_mm256_cmp_ps((num * denom).v, _mm256_setzero_ps(), _CMP_NLE_UQ)};
    const Mask8 not_beyond{
        _mm256_cmp_ps(abs(num).v, (t_max * 1.00001f * abs(denom)).v, _CMP_NGE_UQ)};
    const Mask8 candidates = not_behind & not_beyond;
    if (none(candidates)) return t_max;

    const int kx = r.shear.kx, ky = r.shear.ky, kz = r.shear.kz;
    const Float8 o[3] = {r.origin.x, r.origin.y, r.origin.z};
    const Float8 az = Float8::load(p.vertex[0][kz]) - o[kz];
    const Float8 bz = Float8::load(p.vertex[1][kz]) - o[kz];
    const Float8 cz = Float8::load(p.vertex[2][kz]) - o[kz];
    const Float8 ax = (Float8::load(p.vertex[0][kx]) - o[kx]) - r.sx * az;
    const Float8 ay = (Float8::load(p.vertex[0][ky]) - o[ky]) - r.sy * az;
    const Float8 bx = (Float8::load(p.vertex[1][kx]) - o[kx]) - r.sx * bz;
    const Float8 by = (Float8::load(p.vertex[1][ky]) - o[ky]) - r.sy * bz;
    const Float8 cx = (Float8::load(p.vertex[2][kx]) - o[kx]) - r.sx * cz;
    const Float8 cy = (Float8::load(p.vertex[2][ky]) - o[ky]) - r.sy * cz;
    Float8 u = cx * by - cy * bx;  // never fused: watertight
    Float8 v = ax * cy - ay * cx;
    Float8 w = bx * ay - by * ax;
    const Mask8 on_edge = candidates & ((u == 0.0f) | (v == 0.0f) | (w == 0.0f));
    if (any(on_edge)) redo_edges_exactly(on_edge, ax, ay, bx, by, cx, cy, u, v, w);  // rare
    const Mask8 any_negative = (u < 0.0f) | (v < 0.0f) | (w < 0.0f);
    const Mask8 any_positive = (u > 0.0f) | (v > 0.0f) | (w > 0.0f);
    const Float8 det = u + v + w;
    const Float8 t = num / denom;  // the plane's distance, as the scalar test
    const Mask8 hit =
        and_not(candidates, any_negative & any_positive) & (det != 0.0f) & (t > 0.0f) & (t < t_max);
    if (none(hit)) return t_max;
    return select(hit, t, t_max);
}

// The lane holding the smallest t among `hit_bits` (lanes outside hold t_max, larger than
// any hit); the lowest such lane on a tie, as lab 01's loop keeps the first of equal hits.
// The one horizontal operation of this method: min with halves, pairs, neighbours swapped.
inline int nearest_lane(Float8 t, int hit_bits) {
    __m256 m = _mm256_min_ps(t.v, _mm256_permute2f128_ps(t.v, t.v, 1));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(1, 0, 3, 2)));
    m = _mm256_min_ps(m, _mm256_shuffle_ps(m, m, _MM_SHUFFLE(2, 3, 0, 1)));
    return __builtin_ctz(static_cast<unsigned>((t == Float8(m)).bits() & hit_bits));
}

// intersect_rect (axis_rect.h) for one ray against 8 rectangles. Here each lane has its own
// axis, so each picks the ray's components with selects; the arithmetic per lane is the
// scalar test's, both orders of the canonical edge function computed and one selected.
inline Float8 intersect_rects8(const BroadcastRay& r, const RectPacket& p, Float8 t_max) {
    const Int8 axis = Int8::load(p.axis);
    const Mask8 on_x = axis == 0, on_z = axis == 2;
    const Mask8 on_y = axis == 1;
    const Float8 d_a = select(on_x, r.direction.x, select(on_y, r.direction.y, r.direction.z));
    const Float8 o_a = select(on_x, r.origin.x, select(on_y, r.origin.y, r.origin.z));
    const Float8 to_plane = Float8::load(p.plane) - o_a;
    const Float8 t = to_plane / d_a;
    const Mask8 crosses = (t > 0.0f) & (t < t_max) & (abs(d_a) > 0.0f);
    if (none(crosses)) return t_max;
    // u is y for axis x, else x; v is y for axis z, else z. a < u only for axis x, a < v
    // except for axis z.
    const Float8 d_u = select(on_x, r.direction.y, r.direction.x);
    const Float8 o_u = select(on_x, r.origin.y, r.origin.x);
    const Float8 d_v = select(on_z, r.direction.y, r.direction.z);
    const Float8 o_v = select(on_z, r.origin.y, r.origin.z);
    const Float8 sign_a = copysign(1.0f, d_a);
    const Float8 sign_u = select(on_x, sign_a, -sign_a);
    const Float8 sign_v = select(on_z, -sign_a, sign_a);
    const auto edge = [&](Mask8 plane_first, Float8 to_other, Float8 d_other) {
        const Float8 p1 = to_plane * d_other, p2 = to_other * d_a;  // never fused
        return select(plane_first, p1 - p2, p2 - p1);
    };
    const Mask8 below_z = ~on_z;
    const Float8 lo_u = edge(on_x, Float8::load(p.lo[0]) - o_u, d_u) * sign_u;
    const Float8 hi_u = edge(on_x, Float8::load(p.hi[0]) - o_u, d_u) * sign_u;
    const Float8 lo_v = edge(below_z, Float8::load(p.lo[1]) - o_v, d_v) * sign_v;
    const Float8 hi_v = edge(below_z, Float8::load(p.hi[1]) - o_v, d_v) * sign_v;
    const Mask8 hit = crosses & (lo_u >= 0.0f) & (hi_u <= 0.0f) & (lo_v >= 0.0f) & (hi_v <= 0.0f);
    return select(hit, t, t_max);
}

// closest_hit (path_steps.h) over every packet: 8 primitives per test, then the nearest lane;
// the convex quads, and any kind after the rectangles in AllPrimitives (one added to the list),
// one by one with their scalar hooks (primitive_kinds.h), in the scalar loops' order. Primitives: the kinds compiled in
// (geometry_set.h); the loops of kinds the scene lacks cost a comparison, and are kept.
template <class Primitives = AnyGeometry>
inline Hit closest_hit(const SimdSceneView& scene, const Ray& ray) {
    Hit hit;
    const BroadcastRay r(ray);
    for (int i = 0; i < scene.num_sphere_packets; ++i) {
        const Float8 t_max = hit.t;
        const Float8 t = intersect_spheres8(r, scene.spheres[i], t_max);
        const int hits = (t < t_max).bits();
        if (hits == 0) continue;
        const int lane = nearest_lane(t, hits);
        hit = {t.lane(lane), primitive_kind<Sphere>, i * kSimdWidth + lane};
    }
    for (int i = 0; i < scene.num_triangle_packets; ++i) {
        const Float8 t_max = hit.t;
        const Float8 t = intersect_triangles8(r, scene.triangles[i], t_max);
        const int hits = (t < t_max).bits();
        if (hits == 0) continue;
        const int lane = nearest_lane(t, hits);
        hit = {t.lane(lane), primitive_kind<Triangle>, i * kSimdWidth + lane};
    }
    for (int i = 0; i < scene.one_by_one.of<ConvexQuad>().count; ++i) {
        const float t = intersect_quad(ray, r.shear, scene.one_by_one.of<ConvexQuad>()[i], hit.t);
        if (t < hit.t) hit = {t, primitive_kind<ConvexQuad>, i};
    }
    for (int i = 0; i < scene.num_rect_packets; ++i) {
        const Float8 t_max = hit.t;
        const Float8 t = intersect_rects8(r, scene.rects[i], t_max);
        const int hits = (t < t_max).bits();
        if (hits == 0) continue;
        const int lane = nearest_lane(t, hits);
        hit = {t.lane(lane), primitive_kind<AxisRect>, i * kSimdWidth + lane};
    }
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (kind_index<AllPrimitives, K> > kind_index<AllPrimitives, AxisRect>) {
            for (int i = 0; i < scene.one_by_one.of<K>().count; ++i) {
                float t;
                if constexpr (K::kShearsRay)
                    t = intersect(ray, r.shear, scene.one_by_one.of<K>()[i], hit.t);
                else t = intersect(ray, scene.one_by_one.of<K>()[i], hit.t);
                if (t < hit.t) hit = {t, primitive_kind<K>, i};
            }
        }
    });
    return hit;
}

// occluded (path_steps.h): stops at the first packet with a hit.
template <class Primitives = AnyGeometry>
inline bool occluded(const SimdSceneView& scene, const Ray& ray, float t_max) {
    const BroadcastRay r(ray);
    const Float8 limit = t_max;
    for (int i = 0; i < scene.num_sphere_packets; ++i) {
        if (any(intersect_spheres8(r, scene.spheres[i], limit) < limit)) return true;
    }
    for (int i = 0; i < scene.num_triangle_packets; ++i) {
        if (any(intersect_triangles8(r, scene.triangles[i], limit) < limit)) return true;
    }
    for (int i = 0; i < scene.one_by_one.of<ConvexQuad>().count; ++i) {
        if (intersect_quad(ray, r.shear, scene.one_by_one.of<ConvexQuad>()[i], t_max) < t_max)
            return true;
    }
    for (int i = 0; i < scene.num_rect_packets; ++i) {
        if (any(intersect_rects8(r, scene.rects[i], limit) < limit)) return true;
    }
    bool blocked = false;
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (kind_index<AllPrimitives, K> > kind_index<AllPrimitives, AxisRect>) {
            for (int i = 0; !blocked && i < scene.one_by_one.of<K>().count; ++i)
                if constexpr (K::kShearsRay)
                    blocked = occludes(ray, r.shear, scene.one_by_one.of<K>()[i], t_max);
                else blocked = occludes(ray, scene.one_by_one.of<K>()[i], t_max);
        }
    });
    return blocked;
}
