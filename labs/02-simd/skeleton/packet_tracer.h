// Lab 02: your copy, yours to edit. Every place to fill in is marked TODO(lab02).
// Lab 02 Part B: the path tracer on packets of 8 paths, one path per AVX2 lane (SIMD across
// rays, as Embree's ray packets and ISPC programs do). A pixel's samples go 8 at a time: lane
// i of a packet traces sample s + i, through the same code as lab 01's trace_path (a loop of
// closest hit, bounce step, shadow ray), with each branch turned into a mask: a lane whose
// path has ended keeps computing but changes nothing.
//
// The scene stays as loaded (arrays of spheres, triangles and materials): each primitive is
// broadcast to all 8 lanes and tested against 8 rays at once, and shading fetches per-lane
// data with gathers. The structure of arrays is the packet: Vec3x8 keeps the 8 rays' x in one
// register, their y in another, their z in a third.
//
// Per lane the arithmetic is lab 01's, operation for operation (sin and cos included: both
// use the same polynomial, material.h and simd8.h), so every hit and every shading result has
// lab 01's bits and lab 02's image is lab 01's, bit for bit (tests/labs/test_lab02.py).
#pragma once

#include <cfloat>
#include <cstddef>

#include <camera.h>
#include <sample_sum.h>
#include <scene_view.h>
#include <simd8.h>

// 8 rays, one per lane.
struct RayPacket {
    Vec3x8 origin;
    Vec3x8 direction;  // unit length

    Ray lane(int i) const { return {origin.lane(i), direction.lane(i)}; }
};

// The component of v that index k (0, 1, 2 per lane) names: v[k] lane by lane.
inline Float8 component(const Vec3x8& v, Int8 k) {
    return select(k == 0, v.x, select(k == 1, v.y, v.z));
}

// RayShear (triangle.h) for 8 rays: every lane has its own axis permutation.
struct RayShear8 {
    Int8 kx, ky, kz;       // permuted axes, per lane
    Float8 sx, sy, sz;     // shear constants, per lane
    Vec3x8 origin_k;       // the ray origins permuted: (origin[kx], origin[ky], origin[kz])

    explicit RayShear8(const RayPacket& ray) {
        const Vec3x8& d = ray.direction;
        const Vec3x8 a = abs(d);
        kz = select(a.x > a.y, select(a.x > a.z, Int8(0), Int8(2)),
                    select(a.y > a.z, Int8(1), Int8(2)));
        kx = select(kz == 2, Int8(0), kz + 1);
        ky = select(kx == 2, Int8(0), kx + 1);
        const Mask8 flip = component(d, kz) < 0.0f;  // keep the winding: swap kx and ky
        const Int8 old_kx = kx;
        kx = select(flip, ky, kx);
        ky = select(flip, old_kx, ky);
        sz = Float8(1.0f) / component(d, kz);
        sx = component(d, kx) * sz;
        sy = component(d, ky) * sz;
        origin_k = {component(ray.origin, kx), component(ray.origin, ky),
                    component(ray.origin, kz)};
    }
};

// One scalar float in all 8 lanes, straight from memory.
inline Float8 broadcast(const float& f) { return _mm256_broadcast_ss(&f); }
// v[k] lane by lane for a Vec3 that is the same in every lane: one permute, no selects.
// (Reads 16 bytes at &v: the float after v must exist, as it does inside Triangle.)
static_assert(offsetof(Triangle, v2) + 4 * sizeof(float) <= sizeof(Triangle),
              "permuted() reads one float past each vertex of a Triangle");
inline Float8 permuted(const Vec3& v, Int8 k) {
    const __m256 row = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(&v.x));
    return _mm256_permutevar8x32_ps(row, k.v);
}

// intersect_sphere (sphere.h) for 8 rays against one sphere: per lane the distance in
// (0, t_max), or t_max for a miss. A worked example of the pattern: the scalar code line for
// line; a branch becomes a mask; the early exit happens only when all 8 lanes miss.
inline Float8 intersect_sphere(const RayPacket& ray, const Sphere& s, Float8 t_max) {
    const Vec3x8 f = ray.origin - Vec3x8(s.center);
    const Float8 b = -dot(f, ray.direction);
    const Vec3x8 perpendicular = f + ray.direction * b;
    const Float8 r2 = s.radius * s.radius;
    const Float8 disc = r2 - length_squared(perpendicular);
    const Mask8 crosses = disc >= 0.0f;  // false for NaN, as !(disc >= 0) in the scalar code
    if (none(crosses)) return t_max;
    // Lanes with disc < 0 compute NaN from here on; `crosses` masks them out at the end.
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

// intersect_triangle (triangle.h) for 8 rays against one triangle: per lane the distance in
// (0, t_max), or t_max for a miss. Watertight in every lane, as the scalar test.
inline Float8 intersect_triangle(const RayPacket& ray, const RayShear8& shear,
                                 const Triangle& tri, Float8 t_max) {
    // The plane cull, as in the scalar test; it only rejects. The negated predicates (_UQ)
    // are true for NaN, as !(x <= 0) is in the scalar code.
    const Vec3x8 normal(tri.normal);
    const Float8 denom = dot(normal, ray.direction);
    const Float8 num = broadcast(tri.plane_offset) - dot(normal, ray.origin);
    const Mask8 not_behind{_mm256_cmp_ps((num * denom).v, _mm256_setzero_ps(), _CMP_NLE_UQ)};
    const Mask8 not_beyond{
        _mm256_cmp_ps(abs(num).v, (t_max * 1.00001f * abs(denom)).v, _CMP_NGE_UQ)};
    const Mask8 candidates = not_behind & not_beyond;
    // All 8 lanes rejected: a third of the Cornell box's closest-hit tests end here, half of
    // its shadow-ray tests.
    if (none(candidates)) return t_max;

    // TODO(lab02): the watertight test of intersect_triangle (common/core/triangle.h) in all 8
    // lanes at once: the vertices relative to the origin in each lane's own axis order
    // (permuted(tri.v0, shear.kx) - shear.origin_k.x, ...), the shear (shear.sx ...),
    // the three edge functions as a product minus a product (never fused), the
    // double-precision redo for lanes where one of them is zero, the sign tests, det,
    // and t_scaled / det in the lanes that hit. Every other lane returns its t_max.
    // Until then: lane 0 only, with the scalar test, so 7 of every 8 samples miss
    // every triangle.
    (void)candidates;
    (void)shear;
    const Ray ray0 = ray.lane(0);
    const float t0 = intersect_triangle(ray0, RayShear(ray0.direction), tri, t_max.lane(0));
    return select(Mask8::first(1), t0, t_max);
}

// The nearest surface of each lane's ray.
struct HitPacket {
    Float8 t;         // distance; t_max where nothing was hit
    Int8 sphere;      // index of the sphere hit, or -1
    Int8 triangle;    // index of the triangle hit, or -1

    Mask8 found() const { return ~((sphere == -1) & (triangle == -1)); }
};

// closest_hit (path_tracer.h) for 8 rays: every primitive against all lanes, keeping each
// lane's nearest hit with a masked update. Lanes outside `active` find nothing (their t_max
// is 0, which every test rejects).
inline HitPacket closest_hit(const SceneView& scene, const RayPacket& ray, Mask8 active) {
    HitPacket hit{select(active, Float8(FLT_MAX), Float8(0.0f)), Int8(-1), Int8(-1)};
    for (int i = 0; i < scene.num_spheres; ++i) {
        const Float8 t = intersect_sphere(ray, scene.spheres[i], hit.t);
        const Mask8 nearer = t < hit.t;
        hit.t = select(nearer, t, hit.t);
        hit.sphere = select(nearer, Int8(i), hit.sphere);
    }
    const RayShear8 shear(ray);
    for (int i = 0; i < scene.num_triangles; ++i) {
        const Float8 t = intersect_triangle(ray, shear, scene.triangles[i], hit.t);
        const Mask8 nearer = t < hit.t;
        hit.t = select(nearer, t, hit.t);
        hit.sphere = select(nearer, Int8(-1), hit.sphere);
        hit.triangle = select(nearer, Int8(i), hit.triangle);
    }
    return hit;
}

// occluded (path_tracer.h) for 8 rays: which lanes of `active` are blocked before their
// t_max. A lane drops out (t_max 0) once blocked; the loop ends when all of them are.
inline Mask8 occluded(const SceneView& scene, const RayPacket& ray, Float8 t_max, Mask8 active) {
    Mask8 blocked = Mask8::none();
    Float8 limit = select(active, t_max, Float8(0.0f));
    for (int i = 0; i < scene.num_spheres; ++i) {
        blocked |= intersect_sphere(ray, scene.spheres[i], limit) < limit;
        if (none(and_not(active, blocked))) return blocked;
        limit = select(blocked, Float8(0.0f), limit);
    }
    const RayShear8 shear(ray);
    for (int i = 0; i < scene.num_triangles; ++i) {
        blocked |= intersect_triangle(ray, shear, scene.triangles[i], limit) < limit;
        if (none(and_not(active, blocked))) return blocked;
        limit = select(blocked, Float8(0.0f), limit);
    }
    return blocked;
}

// Per-lane fields of the scene's arrays, by index: gathers with the struct's stride.
template <class T>
constexpr int stride_of() {
    static_assert(sizeof(T) % sizeof(float) == 0, "gathers step in whole floats");
    return static_cast<int>(sizeof(T) / sizeof(float));
}
inline Float8 gather(const float& first, int stride, Int8 index, Mask8 mask) {
    return _mm256_mask_i32gather_ps(_mm256_setzero_ps(), &first,
                                    _mm256_mullo_epi32(index.v, _mm256_set1_epi32(stride)),
                                    mask.m, 4);
}
inline Int8 gather(const int& first, int stride, Int8 index, Mask8 mask) {
    return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), &first,
                                       _mm256_mullo_epi32(index.v, _mm256_set1_epi32(stride)),
                                       _mm256_castps_si256(mask.m), 4);
}
inline Int8 gather(const MaterialType& first, int stride, Int8 index, Mask8 mask) {
    static_assert(sizeof(MaterialType) == sizeof(int), "an int per material type");
    return _mm256_mask_i32gather_epi32(_mm256_setzero_si256(),
                                       reinterpret_cast<const int*>(&first),
                                       _mm256_mullo_epi32(index.v, _mm256_set1_epi32(stride)),
                                       _mm256_castps_si256(mask.m), 4);
}

// surface_at (path_tracer.h) for the lanes in `mask`: position, normal, extent, material.
struct SurfacePacket {
    Vec3x8 position;
    Vec3x8 normal;
    Float8 extent;
    Int8 material;
};

inline SurfacePacket surface_at(const SceneView& scene, const RayPacket& ray,
                                const HitPacket& hit, Mask8 mask) {
    SurfacePacket s;
    s.position = ray.origin + ray.direction * hit.t;
    const Mask8 on_sphere = and_not(mask, hit.sphere == -1);
    const Mask8 on_triangle = and_not(mask, on_sphere);
    Vec3x8 sphere_normal(Vec3(0.0f));
    Float8 sphere_extent(0.0f);
    Int8 sphere_material(0);
    if (any(on_sphere)) {
        constexpr int kS = stride_of<Sphere>();
        const Sphere& s0 = scene.spheres[0];
        const Vec3x8 center(gather(s0.center.x, kS, hit.sphere, on_sphere),
                            gather(s0.center.y, kS, hit.sphere, on_sphere),
                            gather(s0.center.z, kS, hit.sphere, on_sphere));
        sphere_normal = normalize(s.position - center);
        // sphere_extent (sphere.h), lane by lane
        sphere_extent = max_component(abs(center)) + gather(s0.radius, kS, hit.sphere, on_sphere);
        sphere_material = gather(s0.material, kS, hit.sphere, on_sphere);
    }
    Vec3x8 triangle_normal(Vec3(0.0f));
    Float8 triangle_extent(0.0f);
    Int8 triangle_material(0);
    if (any(on_triangle)) {
        constexpr int kT = stride_of<Triangle>();
        const Triangle& t0 = scene.triangles[0];
        triangle_normal = {gather(t0.normal.x, kT, hit.triangle, on_triangle),
                           gather(t0.normal.y, kT, hit.triangle, on_triangle),
                           gather(t0.normal.z, kT, hit.triangle, on_triangle)};
        triangle_extent = gather(t0.extent, kT, hit.triangle, on_triangle);
        triangle_material = gather(t0.material, kT, hit.triangle, on_triangle);
    }
    s.normal = select(on_sphere, sphere_normal, triangle_normal);
    s.extent = select(on_sphere, sphere_extent, triangle_extent);
    s.material = select(on_sphere, sphere_material, triangle_material);
    return s;
}

// ---- specular exits, lane by lane (path_tracer.h's bounce_step, triangle.h's step_off_edges)
// A specular lane's next origin also steps off the edges of the triangle it hit; a sphere
// lane's step is zero, as the scalar code adds none.
inline Vec3x8 cross_lanes(const Vec3x8& a, const Vec3x8& b) {  // cross (vec3.h)
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline void step_off_edge(const Vec3x8& normal, const Vec3x8& from, const Vec3x8& to,
                          const Vec3x8& p, Float8 margin, Vec3x8& step) {
    const Vec3x8 inward = cross_lanes(normal, to - from);
    const Float8 inward_length = sqrt(dot(inward, inward));
    const Float8 depth = dot(p - from, inward);
    const Mask8 near{_mm256_cmp_ps(depth.v, (margin * inward_length).v, _CMP_NGE_UQ)};
    step = select(near, step + inward * (margin / inward_length), step);
}
inline Vec3x8 specular_edge_step(const SceneView& scene, const HitPacket& hit,
                                 const SurfacePacket& surface, Mask8 specular) {
    const Mask8 on_triangle = and_not(specular, hit.triangle == -1);
    Vec3x8 step(Vec3(0.0f));
    if (none(on_triangle)) return step;
    constexpr int kT = stride_of<Triangle>();
    const Triangle& t0 = scene.triangles[0];
    const auto vertex = [&](const Vec3& v) {
        return Vec3x8(gather(v.x, kT, hit.triangle, on_triangle),
                      gather(v.y, kT, hit.triangle, on_triangle),
                      gather(v.z, kT, hit.triangle, on_triangle));
    };
    const Vec3x8 v0 = vertex(t0.v0), v1 = vertex(t0.v1), v2 = vertex(t0.v2);
    // ray_offset (ray.h), lane by lane
    const Float8 margin = (max_component(abs(surface.position)) + hit.t + surface.extent) *
                          Float8(1.0f / (1 << 20));
    step_off_edge(surface.normal, v0, v1, surface.position, margin, step);
    step_off_edge(surface.normal, v1, v2, surface.position, margin, step);
    step_off_edge(surface.normal, v2, v0, surface.position, margin, step);
    return select(on_triangle, step, Vec3x8(Vec3(0.0f)));
}

// PathState (path_tracer.h) for the 8 paths of a packet. All lanes are at the same bounce:
// they start together, and a lane whose path ends stays out of `alive`.
struct PathPacket {
    RayPacket ray;
    Vec3x8 throughput;
    Vec3x8 radiance;
    int bounce;    // surface interactions so far, the same in every lane
    Mask8 alive;   // lanes whose path goes on
};

// ShadowRay (path_tracer.h) for 8 lanes: the lanes that asked for one are what bounce_step
// returns.
struct ShadowPacket {
    RayPacket ray;
    Float8 t_max;
    Vec3x8 radiance;
};

// sample_light (path_tracer.h) for the lanes in `mask`: the lanes whose light lies in front.
inline Mask8 sample_light(const SceneView& scene, const Vec3x8& position, const Vec3x8& origin,
                          const Vec3x8& facing, const Vec3x8& albedo, Mask8 mask,
                          ShadowPacket& shadow) {
    const Vec3x8 to_light = Vec3x8(scene.light.position) - position;
    const Float8 distance2 = length_squared(to_light);
    const Float8 resolved = Float8(2.0f * FLT_EPSILON) * max_component(abs(position));
    const Float8 distance = sqrt(distance2);
    const Vec3x8 wi = to_light * (Float8(1.0f) / distance);
    const Float8 cos_theta = dot(facing, wi);
    // Light in front of the surface and resolved from it, a finite falloff; NaN fails every
    // test, as in the scalar code.
    const Mask8 lit = mask & (cos_theta > 0.0f) & (distance > resolved) &
                      (cos_theta < Float8(FLT_MAX) * (Float8(kPi) * distance2));
    if (none(lit)) return lit;
    shadow.ray = {origin, wi};
    shadow.t_max = distance - dot(origin - position, wi);
    shadow.radiance =
        albedo * Vec3x8(scene.light.intensity) * (cos_theta / (Float8(kPi) * distance2));
    return lit;
}

// bounce_step (path_tracer.h) for the alive lanes of a packet: returns the lanes that ask for
// a shadow ray. Each material is handled in turn, each for its own lanes only. Forced inline
// as the scalar step is (out of line: +7% instructions per path).
inline __attribute__((always_inline)) Mask8 bounce_step(const SceneView& scene, const HitPacket& hit, const SampleStream8& rng,
                         int max_bounces, PathPacket& path, ShadowPacket& shadow) {
    constexpr int kM = stride_of<Material>();
    const Mask8 found = hit.found();
    const Mask8 escaped = and_not(path.alive, found);
    path.radiance =
        select(escaped, path.radiance + path.throughput * Vec3x8(scene.background), path.radiance);
    path.alive = found;
    if (none(path.alive)) return path.alive;

    const RayPacket& ray = path.ray;
    const SurfacePacket surface = surface_at(scene, ray, hit, path.alive);
    const Material& m0 = scene.materials[0];  // gathers index from here
    const Int8 type = gather(m0.type, kM, surface.material, path.alive);
    const Vec3x8 albedo(gather(m0.albedo.x, kM, surface.material, path.alive),
                        gather(m0.albedo.y, kM, surface.material, path.alive),
                        gather(m0.albedo.z, kM, surface.material, path.alive));
    const Mask8 entering = dot(ray.direction, surface.normal) < 0.0f;
    const Vec3x8 facing = select(entering, surface.normal, -surface.normal);
    const Vec3x8 above = offset_ray_origin(surface.position, facing, hit.t, surface.extent);
    const int bounce = path.bounce++;
    const bool last = path.bounce >= max_bounces;
    const Mask8 diffuse = path.alive & (type == static_cast<int>(MaterialType::Diffuse));
    const Mask8 mirror = path.alive & (type == static_cast<int>(MaterialType::Mirror));
    const Mask8 glass = path.alive & (type == static_cast<int>(MaterialType::Glass));

    Mask8 lit = Mask8::none();
    if (scene.has_light && any(diffuse)) {
        lit = sample_light(scene, surface.position, above, facing, albedo, diffuse, shadow);
        if (any(lit)) shadow.radiance = path.throughput * shadow.radiance;
    }
    if (last) {
        path.alive = Mask8::none();
        return lit;
    }

    RayPacket next = ray;
    if (any(diffuse)) {
        path.throughput = select(diffuse, path.throughput * albedo, path.throughput);
        const Vec3x8 d = sample_cosine_hemisphere(facing, rng.at(bounce_dimension(bounce, 0)),
                                                  rng.at(bounce_dimension(bounce, 1)));
        next.origin = select(diffuse, above, next.origin);
        next.direction = select(diffuse, d, next.direction);
    }
    // Specular lanes, as the scalar bounce step: the origin steps off triangle edges, and a
    // reflected direction is renormalised.
    Vec3x8 off_edges(Vec3(0.0f));
    if (any(mirror | glass)) off_edges = specular_edge_step(scene, hit, surface, mirror | glass);
    if (any(mirror)) {
        path.throughput = select(mirror, path.throughput * albedo, path.throughput);
        next.origin = select(mirror, above + off_edges, next.origin);
        next.direction = select(mirror, normalize(reflect(ray.direction, facing)), next.direction);
    }
    if (any(glass)) {  // reflect or refract, chosen with the Fresnel reflectance
        const Float8 ior = gather(m0.ior, kM, surface.material, glass);
        const Float8 eta = select(entering, Float8(1.0f) / ior, ior);
        Float8 cos_t;
        const Float8 reflectance = fresnel_dielectric(-dot(ray.direction, facing), eta, cos_t);
        const Mask8 reflects = rng.at(bounce_dimension(bounce, 0)) < reflectance;
        const Vec3x8 below = offset_ray_origin(surface.position, -facing, hit.t, surface.extent);
        next.origin = select(glass, select(reflects, above, below) + off_edges, next.origin);
        next.direction =
            select(glass,
                   select(reflects, normalize(reflect(ray.direction, facing)),
                          refract(ray.direction, facing, eta, cos_t)),
                   next.direction);
    }
    path.ray = next;
    return lit;
}

// trace_path (path_tracer.h) for the 8 paths of a packet; lanes outside `active` stay black.
inline Vec3x8 trace_paths(const SceneView& scene, const RayPacket& ray, const SampleStream8& rng,
                          int max_bounces, Mask8 active) {
    PathPacket path{ray, Vec3x8(Vec3(1.0f)), Vec3x8(Vec3(0.0f)), 0,
                    max_bounces > 0 ? active : Mask8::none()};
    while (any(path.alive)) {
        const HitPacket hit = closest_hit(scene, path.ray, path.alive);
        ShadowPacket shadow{};  // zeroed: lanes that make no request leave theirs unset
        const Mask8 lit = bounce_step(scene, hit, rng, max_bounces, path, shadow);
        if (any(lit)) {
            const Mask8 clear = and_not(lit, occluded(scene, shadow.ray, shadow.t_max, lit));
            path.radiance = select(clear, path.radiance + shadow.radiance, path.radiance);
        }
    }
    return path.radiance;
}

// render_pixel (path_tracer.h) with 8 samples per packet: the same samples, keyed by the same
// (seed, pixel, sample), summed in the same order.
inline Vec3 render_pixel_packets(const SceneView& scene, const Camera& camera,
                                 const RenderSettings& settings, int x, int y) {
    const uint64_t pixel = static_cast<uint64_t>(y) * settings.width + x;
    SampleSum sum;  // in double, as render_pixel's
    for (int s = 0; s < settings.spp; s += kLanes) {
        const int count = settings.spp - s < kLanes ? settings.spp - s : kLanes;
        const SampleStream8 rng(settings.seed, pixel, s);
        const Float8 px = Float8(static_cast<float>(x)) + rng.at(kDimPixelX);
        const Float8 py = Float8(static_cast<float>(y)) + rng.at(kDimPixelY);
        // Camera::ray_through, lane by lane.
        const Vec3x8 d = Vec3x8(camera.upper_left) + Vec3x8(camera.pixel_right) * px +
                         Vec3x8(camera.pixel_down) * py;
        const RayPacket ray{Vec3x8(camera.position), normalize(d)};
        const Vec3x8 radiance = trace_paths(scene, ray, rng, settings.bounces, Mask8::first(count));
        alignas(32) float r[kLanes], g[kLanes], b[kLanes];
        radiance.x.store(r);
        radiance.y.store(g);
        radiance.z.store(b);
        for (int lane = 0; lane < count; ++lane) sum.add(Vec3(r[lane], g[lane], b[lane]));
    }
    return sum.mean(settings.spp);
}
