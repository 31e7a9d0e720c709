// Lab 02 Part B: the path tracer on packets of paths, one path per SIMD lane (SIMD across
// rays, as Embree's ray packets and ISPC programs do). A pixel's samples go 8 at a time (16 on
// AVX-512): lane i of a packet traces sample s + i, through the same code as lab 01's
// trace_path (a loop of closest hit, bounce step, shadow ray), with each branch turned into a
// mask: a lane whose path has ended keeps computing but changes nothing.
//
// Written once for any lane type F: Float8 (8 AVX2 lanes, simd8.h: what lab 02 builds) or
// Float16 (16 AVX-512 lanes, simd16.h). Read F as Float8, MaskOf<F> as Mask8, IntOf<F> as
// Int8 and kLanes as 8. The width is chosen at build time, by which header an object includes
// (labs/02-simd/lab.mk); compacted_tracer.h runs the same bounce step on packets it refills.
//
// The scene stays as loaded (arrays of spheres, triangles, quads, rectangles and materials):
// each primitive is broadcast to all lanes and tested against all rays at once (the packet
// intersection tests, packet_hits.h: what lab 02's students write), and shading fetches
// per-lane data with gathers. The structure of arrays is the packet: Vec3xN keeps the rays' x
// in one register, their y in another, their z in a third.
//
// Per lane the arithmetic is lab 01's, operation for operation (sin and cos included: both
// use the same polynomial, material.h and lane_math.h), so every hit and every shading result has
// lab 01's bits and lab 02's image is lab 01's, bit for bit (tests/labs/test_lab02.py).
#pragma once

#include <cfloat>
#include <cstddef>
#include <type_traits>

#include <camera.h>
#include <geometry_set.h>
#include <packet_hits.h>  // the intersection tests
#include <ray_packet.h>  // RayPacket, RayShearN
#include <sample_sum.h>
#include <scene_view.h>
#include <simd8.h>  // and lane_math.h; a 16-lane build includes simd16.h first

// The nearest surface of each lane's ray.
template <class F>
struct HitPacket {
    F t;  // distance; t_max where nothing was hit
    IntOf<F> kind;  // PrimitiveKind of the primitive hit, as an int (0: nothing)
    IntOf<F> index;  // its index in its kind's array

    MaskOf<F> found() const { return ~(kind == 0); }
    MaskOf<F> on(PrimitiveKind k) const { return kind == static_cast<int>(k); }
};

// ---- kinds without a packet test: lane by lane
// The kinds this file tests N rays at a time. Any other kind of AllPrimitives (one added to the
// list) is tested, shaded and stepped off lane by lane with its scalar hooks
// (primitive_kinds.h): lab 01's bits at once, at a scalar kind's speed until it has a packet
// test. Such kinds come after these in the list, so that both visit the kinds in one order.
using PacketKinds = Kinds<Sphere, Triangle, ConvexQuad, AxisRect>;
template <class K>
constexpr bool lane_by_lane = !has_kind<PacketKinds, K>;
static_assert(kinds_within<PacketKinds, AllPrimitives> &&
                  kind_index<AllPrimitives, AxisRect> == PacketKinds::kCount - 1,
              "the kinds without a packet test follow those with one in AllPrimitives");
// And take no RayShear: the scalar loops visit the kinds that do together with the triangles
// (for_each_kind_with_shear), which would put such a kind in another place of the order.
template <class... K>
constexpr bool lane_by_lane_kinds_shear(Kinds<K...>) {
    return (false || ... || (lane_by_lane<K> && K::kShearsRay));
}
static_assert(!lane_by_lane_kinds_shear(AllPrimitives{}),
              "a kind without a packet test takes no RayShear");

// An N-lane value: op(lane) in the lanes of `lanes`, `otherwise` in the others.
template <class F, class Op>
inline F from_lanes(MaskOf<F> lanes, F otherwise, Op&& op) {
    alignas(64) float v[F::kLanes];
    otherwise.store(v);
    for (int l = 0; l < F::kLanes; ++l) {
        if (lanes.bits() >> l & 1) v[l] = op(l);
    }
    return F::load(v);
}
template <class F, class Op>
inline Vec3xN<F> vectors_from_lanes(MaskOf<F> lanes, const Vec3xN<F>& otherwise, Op&& op) {
    alignas(64) float v[3][F::kLanes];
    otherwise.x.store(v[0]);
    otherwise.y.store(v[1]);
    otherwise.z.store(v[2]);
    for (int l = 0; l < F::kLanes; ++l) {
        if (!(lanes.bits() >> l & 1)) continue;
        const Vec3 value = op(l);
        v[0][l] = value.x;
        v[1][l] = value.y;
        v[2][l] = value.z;
    }
    return {F::load(v[0]), F::load(v[1]), F::load(v[2])};
}
// A kind's scalar test on the rays of `lanes`, lane by lane; t_max in the others.
template <class F, class K>
inline F intersect_lanes(const RayPacket<F>& ray, const K& item, F t_max, MaskOf<F> lanes) {
    return from_lanes(lanes, t_max, [&](int l) {
        const Ray r = ray.lane(l);
        if constexpr (K::kShearsRay)
            return intersect(r, RayShear(r.direction), item, t_max.lane(l));
        else return intersect(r, item, t_max.lane(l));
    });
}

// closest_hit (path_steps.h) for N rays: every primitive against all lanes, keeping each
// lane's nearest hit with a masked update, in the scalar loops' order. Lanes outside `active`
// find nothing (their t_max is 0, which every test rejects).
template <class F>
inline HitPacket<F> closest_hit(const SceneView& scene, const RayPacket<F>& ray, MaskOf<F> active) {
    using I = IntOf<F>;
    HitPacket<F> hit{select(active, F(FLT_MAX), F(0.0f)), I(0), I(-1)};
    const auto keep = [&](F t, PrimitiveKind kind, int i) {
        const auto nearer = t < hit.t;
        hit.t = select(nearer, t, hit.t);
        hit.kind = select(nearer, I(static_cast<int>(kind)), hit.kind);
        hit.index = select(nearer, I(i), hit.index);
    };
    for (int i = 0; i < scene.of<Sphere>().count; ++i)
        keep(intersect_sphere(ray, scene.of<Sphere>()[i], hit.t), primitive_kind<Sphere>, i);
    if (scene.of<Triangle>().count > 0 || scene.of<ConvexQuad>().count > 0) {
        const RayShearN<F> shear(ray);
        for (int i = 0; i < scene.of<Triangle>().count; ++i) {
            keep(intersect_triangle(ray, shear, scene.of<Triangle>()[i], hit.t),
                 primitive_kind<Triangle>, i);
        }
        for (int i = 0; i < scene.of<ConvexQuad>().count; ++i)
            keep(intersect_quad(ray, shear, scene.of<ConvexQuad>()[i], hit.t),
                 primitive_kind<ConvexQuad>, i);
    }
    for (int i = 0; i < scene.of<AxisRect>().count; ++i)
        keep(intersect_rect(ray, scene.of<AxisRect>()[i], hit.t), primitive_kind<AxisRect>, i);
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (lane_by_lane<K>) {
            for (int i = 0; i < scene.of<K>().count; ++i)
                keep(intersect_lanes(ray, scene.of<K>()[i], hit.t, active), primitive_kind<K>, i);
        }
    });
    return hit;
}

// occluded (path_steps.h) for N rays: which lanes of `active` are blocked before their
// t_max. A lane drops out (t_max 0) once blocked; the loop ends when all of them are.
template <class F>
inline MaskOf<F> occluded(const SceneView& scene, const RayPacket<F>& ray, F t_max,
                          MaskOf<F> active) {
    auto blocked = MaskOf<F>::none();
    F limit = select(active, t_max, F(0.0f));
    // Adds the lanes that `t` blocks; true when every active lane is blocked.
    const auto block = [&](F t) {
        blocked |= t < limit;
        if (none(and_not(active, blocked))) return true;
        limit = select(blocked, F(0.0f), limit);
        return false;
    };
    for (int i = 0; i < scene.of<Sphere>().count; ++i) {
        if (block(intersect_sphere(ray, scene.of<Sphere>()[i], limit))) return blocked;
    }
    if (scene.of<Triangle>().count > 0 || scene.of<ConvexQuad>().count > 0) {
        const RayShearN<F> shear(ray);
        for (int i = 0; i < scene.of<Triangle>().count; ++i) {
            if (block(intersect_triangle(ray, shear, scene.of<Triangle>()[i], limit)))
                return blocked;
        }
        for (int i = 0; i < scene.of<ConvexQuad>().count; ++i) {
            if (block(intersect_quad(ray, shear, scene.of<ConvexQuad>()[i], limit))) return blocked;
        }
    }
    for (int i = 0; i < scene.of<AxisRect>().count; ++i) {
        if (block(intersect_rect(ray, scene.of<AxisRect>()[i], limit))) return blocked;
    }
    bool all_blocked = false;
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (lane_by_lane<K>) {
            for (int i = 0; !all_blocked && i < scene.of<K>().count; ++i)
                all_blocked = block(intersect_lanes(ray, scene.of<K>()[i], limit, active));
        }
    });
    return blocked;
}

// Gathers step through the scene's arrays in whole floats: a field of element i is
// (&field of element 0)[i * stride_of<T>()].
template <class T>
constexpr int stride_of() {
    static_assert(sizeof(T) % sizeof(float) == 0, "gathers step in whole floats");
    return static_cast<int>(sizeof(T) / sizeof(float));
}
template <class F>
inline IntOf<F> gather(const MaterialType& first, int stride, IntOf<F> index, MaskOf<F> mask) {
    static_assert(sizeof(MaterialType) == sizeof(int), "an int per material type");
    return gather(reinterpret_cast<const int&>(first), stride, index, mask);
}

// surface_at (path_state.h) for the lanes in `mask`: position, normal, extent, material.
template <class F>
struct SurfacePacket {
    Vec3xN<F> position;
    Vec3xN<F> normal;
    F extent;
    IntOf<F> material;
};

template <class F>
inline SurfacePacket<F> surface_at(const SceneView& scene, const RayPacket<F>& ray,
                                   const HitPacket<F>& hit, MaskOf<F> mask) {
    using I = IntOf<F>;
    SurfacePacket<F> s;
    s.position = ray.origin + ray.direction * hit.t;
    s.normal = Vec3xN<F>(Vec3(0.0f));
    s.extent = F(0.0f);
    s.material = I(0);
    // Each kind's lanes gather their primitive's fields; the others keep what they have.
    const auto take = [&](MaskOf<F> lanes, const Vec3xN<F>& normal, F extent, I material) {
        s.normal = select(lanes, normal, s.normal);
        s.extent = select(lanes, extent, s.extent);
        s.material = select(lanes, material, s.material);
    };
    const auto on_sphere = mask & hit.on(primitive_kind<Sphere>);
    if (any(on_sphere)) {
        constexpr int kS = stride_of<Sphere>();
        const Sphere& s0 = scene.of<Sphere>()[0];
        const Vec3xN<F> center(gather(s0.center.x, kS, hit.index, on_sphere),
                               gather(s0.center.y, kS, hit.index, on_sphere),
                               gather(s0.center.z, kS, hit.index, on_sphere));
        // sphere_extent (sphere.h), lane by lane
        take(on_sphere, normalize(s.position - center),
             max_component(abs(center)) + gather(s0.radius, kS, hit.index, on_sphere),
             gather(s0.material, kS, hit.index, on_sphere));
    }
    // A flat primitive's own normal, extent and material (Triangle and ConvexQuad alike).
    const auto take_flat = [&](auto kind, const auto* first) {
        const auto lanes = mask & hit.on(kind);
        if (none(lanes)) return;
        using T = std::remove_cv_t<std::remove_pointer_t<decltype(first)>>;
        constexpr int kT = stride_of<T>();
        take(lanes,
             {gather(first->normal.x, kT, hit.index, lanes),
              gather(first->normal.y, kT, hit.index, lanes),
              gather(first->normal.z, kT, hit.index, lanes)},
             gather(first->extent, kT, hit.index, lanes),
             gather(first->material, kT, hit.index, lanes));
    };
    take_flat(primitive_kind<Triangle>, scene.of<Triangle>().items);
    take_flat(primitive_kind<ConvexQuad>, scene.of<ConvexQuad>().items);
    const auto on_rect = mask & hit.on(primitive_kind<AxisRect>);
    if (any(on_rect)) {  // rect_normal (axis_rect.h), lane by lane
        constexpr int kR = stride_of<AxisRect>();
        const AxisRect& r0 = scene.of<AxisRect>()[0];
        const I axis_side = gather(r0.axis_side, kR, hit.index, on_rect);
        const I axis = axis_side & 3;
        const F side = select(axis_side == axis, F(1.0f), F(-1.0f));  // bit 2: faces -axis
        const F zero(0.0f);
        take(on_rect,
             {select(axis == 0, side, zero), select(axis == 1, side, zero),
              select(axis == 2, side, zero)},
             gather(r0.extent, kR, hit.index, on_rect),
             gather(r0.material, kR, hit.index, on_rect));
    }
    for_each_kind(AllPrimitives{}, [&](auto kind) {  // surface_of (path_state.h), lane by lane
        using K = typename decltype(kind)::type;
        if constexpr (lane_by_lane<K>) {
            const auto lanes = mask & hit.on(primitive_kind<K>);
            if (none(lanes)) return;
            const auto item = [&](int l) -> const K& { return scene.of<K>()[hit.index.lane(l)]; };
            alignas(64) int32_t material[F::kLanes];
            s.material.store(material);
            for (int l = 0; l < F::kLanes; ++l) {
                if (lanes.bits() >> l & 1) material[l] = item(l).material;
            }
            take(lanes,
                 vectors_from_lanes(lanes, s.normal,
                                    [&](int l) { return normal_at(item(l), s.position.lane(l)); }),
                 from_lanes(lanes, s.extent, [&](int l) { return surface_extent(item(l)); }),
                 I::load(material));
        }
    });
    return s;
}

// ---- specular exits, lane by lane (path_steps.h's bounce_step, path_state.h's step_off_hit_edges)
// A specular lane's next origin also steps off the edges of the triangle, quad or rectangle it
// hit; a sphere lane's step is zero, as the scalar code adds none.
template <class F>
inline Vec3xN<F> cross_lanes(const Vec3xN<F>& a, const Vec3xN<F>& b) {  // cross (vec3.h)
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class F>
inline void step_off_edge(const Vec3xN<F>& normal, const Vec3xN<F>& from, const Vec3xN<F>& to,
                          const Vec3xN<F>& p, F margin, Vec3xN<F>& step) {
    const Vec3xN<F> inward = cross_lanes(normal, to - from);
    const F inward_length = sqrt(dot(inward, inward));
    const F depth = dot(p - from, inward);
    const auto near = not_greater_equal(depth, margin * inward_length);
    step = select(near, step + inward * (margin / inward_length), step);
}
// The vertices of the primitives that `lanes` hit, gathered: a Triangle's or a ConvexQuad's.
template <class F, class T>
inline Vec3xN<F> gather_vertex(const T& first, const Vec3& v, const HitPacket<F>& hit,
                               MaskOf<F> lanes) {
    constexpr int kT = stride_of<T>();
    const int offset = static_cast<int>(&v.x - reinterpret_cast<const float*>(&first));
    const float* base = reinterpret_cast<const float*>(&first) + offset;
    return {gather(base[0], kT, hit.index, lanes), gather(base[1], kT, hit.index, lanes),
            gather(base[2], kT, hit.index, lanes)};
}
template <class F>
inline Vec3xN<F> specular_edge_step(const SceneView& scene, const HitPacket<F>& hit,
                                    const SurfacePacket<F>& surface, MaskOf<F> specular,
                                    const Vec3xN<F>& direction) {
    using I = IntOf<F>;
    Vec3xN<F> step(Vec3(0.0f));
    const auto on_triangle = specular & hit.on(primitive_kind<Triangle>);
    const auto on_quad = specular & hit.on(primitive_kind<ConvexQuad>);
    const auto on_rect = specular & hit.on(primitive_kind<AxisRect>);
    auto on_other = MaskOf<F>::none();  // kinds without a packet test
    for_each_kind(AllPrimitives{}, [&](auto kind) {
        if constexpr (lane_by_lane<typename decltype(kind)::type>)
            on_other |= specular & hit.on(primitive_kind<typename decltype(kind)::type>);
    });
    if (none(on_triangle | on_quad | on_rect | on_other)) return step;
    // ray_offset (ray.h), lane by lane
    const F margin =
        (max_component(abs(surface.position)) + hit.t + surface.extent) * F(1.0f / (1 << 20));
    for_each_kind(AllPrimitives{}, [&](auto kind) {  // step_off_hit_edges, lane by lane
        using K = typename decltype(kind)::type;
        if constexpr (lane_by_lane<K>) {
            const auto lanes = specular & hit.on(primitive_kind<K>);
            if (none(lanes)) return;
            step = vectors_from_lanes(lanes, step, [&](int l) {
                return step_off_edges(scene.of<K>()[hit.index.lane(l)], surface.position.lane(l),
                                      margin.lane(l));
            });
        }
    });
    if (any(on_triangle)) {
        const Triangle& t0 = scene.of<Triangle>()[0];
        const Vec3xN<F> v0 = gather_vertex(t0, t0.v0, hit, on_triangle);
        const Vec3xN<F> v1 = gather_vertex(t0, t0.v1, hit, on_triangle);
        const Vec3xN<F> v2 = gather_vertex(t0, t0.v2, hit, on_triangle);
        Vec3xN<F> s(Vec3(0.0f));
        step_off_edge(surface.normal, v0, v1, surface.position, margin, s);
        step_off_edge(surface.normal, v1, v2, surface.position, margin, s);
        step_off_edge(surface.normal, v2, v0, surface.position, margin, s);
        step = select(on_triangle, s, step);
        // A triangle with cut edges (triangle.h) steps by the arriving ray's direction: the
        // scalar step, lane by lane (the loader marks few).
        const auto cut = and_not(
            on_triangle, gather(t0.cut_edges, stride_of<Triangle>(), hit.index, on_triangle) == 0);
        if (any(cut)) {
            step = vectors_from_lanes(cut, step, [&](int l) {
                return step_off_edges(scene.of<Triangle>()[hit.index.lane(l)],
                                      surface.position.lane(l), margin.lane(l), direction.lane(l));
            });
        }
    }
    if (any(on_quad)) {
        const ConvexQuad& q0 = scene.of<ConvexQuad>()[0];
        const Vec3xN<F> v0 = gather_vertex(q0, q0.v0, hit, on_quad);
        const Vec3xN<F> v1 = gather_vertex(q0, q0.v1, hit, on_quad);
        const Vec3xN<F> v2 = gather_vertex(q0, q0.v2, hit, on_quad);
        const Vec3xN<F> v3 = gather_vertex(q0, q0.v3, hit, on_quad);
        Vec3xN<F> s(Vec3(0.0f));
        step_off_edge(surface.normal, v0, v1, surface.position, margin, s);
        step_off_edge(surface.normal, v1, v2, surface.position, margin, s);
        step_off_edge(surface.normal, v2, v3, surface.position, margin, s);
        step_off_edge(surface.normal, v3, v0, surface.position, margin, s);
        step = select(on_quad, s, step);
        const auto cut = and_not(
            on_quad, gather(q0.cut_edges, stride_of<ConvexQuad>(), hit.index, on_quad) == 0);
        if (any(cut)) {  // as the triangles'
            step = vectors_from_lanes(cut, step, [&](int l) {
                return step_off_edges(scene.of<ConvexQuad>()[hit.index.lane(l)],
                                      surface.position.lane(l), margin.lane(l), direction.lane(l));
            });
        }
    }
    if (any(on_rect)) {  // step_off_edges (axis_rect.h), lane by lane
        constexpr int kR = stride_of<AxisRect>();
        const AxisRect& r0 = scene.of<AxisRect>()[0];
        const I axis = gather(r0.axis_side, kR, hit.index, on_rect) & 3;
        const Vec3xN<F>& p = surface.position;
        const F p_u = select(axis == 0, p.y, p.x);  // rect_axis_u, rect_axis_v
        const F p_w = select(axis == 2, p.y, p.z);
        const F lo_u = gather(r0.lo_u, kR, hit.index, on_rect);
        const F hi_u = gather(r0.hi_u, kR, hit.index, on_rect);
        const F lo_w = gather(r0.lo_v, kR, hit.index, on_rect);
        const F hi_w = gather(r0.hi_v, kR, hit.index, on_rect);
        F step_u(0.0f), step_w(0.0f);
        step_u = select(not_greater_equal(p_u - lo_u, margin), step_u + margin, step_u);
        step_u = select(not_greater_equal(hi_u - p_u, margin), step_u - margin, step_u);
        step_w = select(not_greater_equal(p_w - lo_w, margin), step_w + margin, step_w);
        step_w = select(not_greater_equal(hi_w - p_w, margin), step_w - margin, step_w);
        // along_axis(u, step_u) + along_axis(w, step_w): u is y for axis x, else x; w is y for
        // axis z, else z.
        const F zero(0.0f);
        const I u = select(axis == 0, I(1), I(0));
        const I w = select(axis == 2, I(1), I(2));
        const Vec3xN<F> s(select(u == 0, step_u, zero) + select(w == 0, step_w, zero),
                          select(u == 1, step_u, zero) + select(w == 1, step_w, zero),
                          select(u == 2, step_u, zero) + select(w == 2, step_w, zero));
        step = select(on_rect, s, step);
    }
    return step;
}

// PathState (path_state.h) for the paths of a packet. All lanes are at the same bounce:
// they start together, and a lane whose path ends stays out of `alive`.
template <class F>
struct PathPacket {
    RayPacket<F> ray;
    Vec3xN<F> throughput;
    Vec3xN<F> radiance;
    int bounce;  // surface interactions so far, the same in every lane
    MaskOf<F> alive;  // lanes whose path goes on
};

// ShadowRay (path_state.h) for N lanes: the lanes that asked for one are what bounce_step
// returns.
template <class F>
struct ShadowPacket {
    RayPacket<F> ray;
    F t_max;
    Vec3xN<F> radiance;
};

// sample_light (path_steps.h) for the lanes in `mask`: the lanes whose light lies in front.
template <class F>
inline MaskOf<F> sample_light(const SceneView& scene, const Vec3xN<F>& position,
                              const Vec3xN<F>& origin, const Vec3xN<F>& facing,
                              const Vec3xN<F>& albedo, MaskOf<F> mask, ShadowPacket<F>& shadow) {
    const Vec3xN<F> to_light = Vec3xN<F>(scene.light.position) - position;
    const F distance2 = length_squared(to_light);
    const F resolved = F(2.0f * FLT_EPSILON) * max_component(abs(position));
    const F distance = sqrt(distance2);
    const Vec3xN<F> wi = to_light * (F(1.0f) / distance);
    const F cos_theta = dot(facing, wi);
    // Light in front of the surface and resolved from it, a finite falloff; NaN fails every
    // test, as in the scalar code.
    const auto lit = mask & (cos_theta > F(0.0f)) & (distance > resolved) &
                     (cos_theta < F(FLT_MAX) * (F(kPi) * distance2));
    if (none(lit)) return lit;
    shadow.ray = {origin, wi};
    shadow.t_max = distance - dot(origin - position, wi);
    // Saturated at float's largest value, as in the scalar code (no inf to meet a zero
    // channel); min(a, b) is min_float(a, b) lane by lane.
    const Vec3xN<F> radiance =
        albedo * Vec3xN<F>(scene.light.intensity) * (cos_theta / (F(kPi) * distance2));
    const F largest(FLT_MAX);
    shadow.radiance = {min(radiance.x, largest), min(radiance.y, largest),
                       min(radiance.z, largest)};
    return lit;
}

// The material kinds this file has a branch for; any other kind of AllMaterials (one added to
// the list) scatters lane by lane with its kind's hook (material.h): lab 01's bits at once.
using PacketMaterials = Kinds<Diffuse, Mirror, Glass>;
static_assert(kinds_within<PacketMaterials, AllMaterials>, "the packet materials are kinds");

// One lane of a packet's random numbers, as a scalar Rng for a scatter hook.
template <class F>
struct LaneStream {
    const SampleStreamN<F>& streams;
    int lane;
    float at(uint32_t dimension) const { return streams.at(dimension).lane(lane); }
};

// bounce_step (path_steps.h) for the alive lanes of a packet: returns the lanes that ask for
// a shadow ray. Each material is handled in turn, each for its own lanes only. Forced inline
// as the scalar step is (out of line: +7% instructions per path).
template <class F>
RT_PACKET_INLINE MaskOf<F> bounce_step(const SceneView& scene, const HitPacket<F>& hit,
                                       const SampleStreamN<F>& rng, int max_bounces,
                                       PathPacket<F>& path, ShadowPacket<F>& shadow) {
    using Mask = MaskOf<F>;
    constexpr int kM = stride_of<Material>();
    const Mask found = hit.found();
    const Mask escaped = and_not(path.alive, found);
    path.radiance = select(escaped, path.radiance + path.throughput * Vec3xN<F>(scene.background),
                           path.radiance);
    path.alive = path.alive & found;
    if (none(path.alive)) return path.alive;

    const RayPacket<F>& ray = path.ray;
    const SurfacePacket<F> surface = surface_at(scene, ray, hit, path.alive);
    const Material& m0 = scene.materials[0];  // gathers index from here
    const IntOf<F> type = gather<F>(m0.type, kM, surface.material, path.alive);
    const Vec3xN<F> albedo(gather(m0.albedo.x, kM, surface.material, path.alive),
                           gather(m0.albedo.y, kM, surface.material, path.alive),
                           gather(m0.albedo.z, kM, surface.material, path.alive));
    const Mask entering = dot(ray.direction, surface.normal) < 0.0f;
    const Vec3xN<F> facing = select(entering, surface.normal, -surface.normal);
    const Vec3xN<F> above = offset_ray_origin(surface.position, facing, hit.t, surface.extent);
    const int bounce = path.bounce++;
    const bool last = path.bounce >= max_bounces;
    const Mask diffuse = path.alive & (type == static_cast<int>(material_type<Diffuse>));
    const Mask mirror = path.alive & (type == static_cast<int>(material_type<Mirror>));
    const Mask glass = path.alive & (type == static_cast<int>(material_type<Glass>));
    Mask other = Mask::none();  // lanes of a kind without a branch here
    for_each_kind(AllMaterials{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        if constexpr (!has_kind<PacketMaterials, K>)
            other |= path.alive & (type == static_cast<int>(material_type<K>));
    });

    Mask lit = Mask::none();
    if (scene.has_light && any(diffuse)) {
        lit = sample_light(scene, surface.position, above, facing, albedo, diffuse, shadow);
        if (any(lit)) shadow.radiance = path.throughput * shadow.radiance;
    }
    if (last) {
        path.alive = Mask::none();
        return lit;
    }

    RayPacket<F> next = ray;
    if (any(diffuse)) {
        path.throughput = select(diffuse, path.throughput * albedo, path.throughput);
        const Vec3xN<F> d = sample_cosine_hemisphere(facing, rng.at(bounce_dimension(bounce, 0)),
                                                     rng.at(bounce_dimension(bounce, 1)));
        next.origin = select(diffuse, above, next.origin);
        next.direction = select(diffuse, d, next.direction);
    }
    // Specular lanes, as the scalar bounce step: the origin steps off triangle edges, and a
    // reflected direction is renormalised.
    Vec3xN<F> off_edges(Vec3(0.0f));
    if (any(mirror | glass | other))
        off_edges = specular_edge_step(scene, hit, surface, mirror | glass | other, ray.direction);
    if (any(mirror)) {
        path.throughput = select(mirror, path.throughput * albedo, path.throughput);
        next.origin = select(mirror, above + off_edges, next.origin);
        next.direction = select(mirror, normalize(reflect(ray.direction, facing)), next.direction);
    }
    if (any(glass)) {  // reflect or refract, chosen with the Fresnel reflectance
        const F ior = gather(m0.ior, kM, surface.material, glass);
        const F eta = select(entering, F(1.0f) / ior, ior);
        F cos_t;
        const F reflectance = fresnel_dielectric(-dot(ray.direction, facing), eta, cos_t);
        const Mask reflects = rng.at(bounce_dimension(bounce, 0)) < reflectance;
        const Vec3xN<F> below = offset_ray_origin(surface.position, -facing, hit.t, surface.extent);
        next.origin = select(glass, select(reflects, above, below) + off_edges, next.origin);
        next.direction = select(glass,
                                select(reflects, normalize(reflect(ray.direction, facing)),
                                       refract(ray.direction, facing, eta, cos_t)),
                                next.direction);
    }
    if (any(other)) {  // scatter_of (path_steps.h's bounce_step), lane by lane
        Vec3 throughput[F::kLanes], origin[F::kLanes], direction[F::kLanes];
        for (int l = 0; l < F::kLanes; ++l) {
            if (!(other.bits() >> l & 1)) continue;
            const int material = surface.material.lane(l);
            const SpecularHit at{
                ray.direction.lane(l), facing.lane(l),        (entering.bits() >> l & 1) != 0,
                above.lane(l),         off_edges.lane(l),     surface.position.lane(l),
                hit.t.lane(l),         surface.extent.lane(l)};
            throughput[l] = path.throughput.lane(l);
            Ray lane_next = next.lane(l);
            scatter_of(scene.materials[material], at, LaneStream<F>{rng, l}, bounce, throughput[l],
                       lane_next, without_kind<AllMaterials, Diffuse>{});
            origin[l] = lane_next.origin;
            direction[l] = lane_next.direction;
        }
        path.throughput =
            vectors_from_lanes(other, path.throughput, [&](int l) { return throughput[l]; });
        next.origin = vectors_from_lanes(other, next.origin, [&](int l) { return origin[l]; });
        next.direction =
            vectors_from_lanes(other, next.direction, [&](int l) { return direction[l]; });
    }
    path.ray = next;
    return lit;
}

// The shadow ray that bounce_step asked for in the lanes `lit`, traced: its radiance joins
// the path's where nothing blocks it (trace_path's `if (bounce_step(...) && !occluded(...))`).
template <class F>
inline void add_unblocked_light(const SceneView& scene, MaskOf<F> lit,
                                const ShadowPacket<F>& shadow, PathPacket<F>& path) {
    if (none(lit)) return;
    const auto clear = and_not(lit, occluded(scene, shadow.ray, shadow.t_max, lit));
    path.radiance = select(clear, path.radiance + shadow.radiance, path.radiance);
}

// trace_path (path_tracer.h) for the paths of a packet; lanes outside `active` stay black.
template <class F>
inline Vec3xN<F> trace_paths(const SceneView& scene, const RayPacket<F>& ray,
                             const SampleStreamN<F>& rng, int max_bounces, MaskOf<F> active) {
    PathPacket<F> path{ray, Vec3xN<F>(Vec3(1.0f)), Vec3xN<F>(Vec3(0.0f)), 0,
                       max_bounces > 0 ? active : MaskOf<F>::none()};
    while (any(path.alive)) {
        const HitPacket<F> hit = closest_hit(scene, path.ray, path.alive);
        ShadowPacket<F> shadow{};  // zeroed: lanes that make no request leave theirs unset
        const auto lit = bounce_step(scene, hit, rng, max_bounces, path, shadow);
        add_unblocked_light(scene, lit, shadow, path);
    }
    return path.radiance;
}

// Camera::ray_through, lane by lane, for the image points (px, py).
template <class F>
inline RayPacket<F> camera_rays(const Camera& camera, F px, F py) {
    const Vec3xN<F> d = Vec3xN<F>(camera.upper_left) + Vec3xN<F>(camera.pixel_right) * px +
                        Vec3xN<F>(camera.pixel_down) * py;
    return {Vec3xN<F>(camera.position), normalize(d)};
}

// render_pixel (path_steps.h) with kLanes samples per packet: the same samples, keyed by the
// same (seed, pixel, sample), summed in the same order. F = Float8 unless said otherwise.
template <class F = Float8>
inline Vec3 render_pixel_packets(const SceneView& scene, const Camera& camera,
                                 const RenderSettings& settings, int x, int y) {
    constexpr int kLanes = F::kLanes;
    const uint64_t pixel = static_cast<uint64_t>(y) * settings.width + x;
    SampleSum sum;  // in double, as render_pixel's
    for (int s = 0; s < settings.spp; s += kLanes) {
        const int count = settings.spp - s < kLanes ? settings.spp - s : kLanes;
        const SampleStreamN<F> rng(settings.seed, pixel, s);
        const F px = F(static_cast<float>(x)) + rng.at(kDimPixelX);
        const F py = F(static_cast<float>(y)) + rng.at(kDimPixelY);
        const RayPacket<F> ray = camera_rays(camera, px, py);
        const Vec3xN<F> radiance =
            trace_paths(scene, ray, rng, settings.bounces, MaskOf<F>::first(count));
        alignas(64) float r[kLanes], g[kLanes], b[kLanes];
        radiance.x.store(r);
        radiance.y.store(g);
        radiance.z.store(b);
        for (int lane = 0; lane < count; ++lane) sum.add(Vec3(r[lane], g[lane], b[lane]));
    }
    return sum.mean(settings.spp);
}
