// Experiment behind reference/timings/README.md ("Quads with shared vertex transforms"): how
// much faster lab 01's closest hit gets when each quad is tested as one primitive, and whether
// it stays bit-identical. An experiment, not part of the kit; from the repository root:
//
//   make build/quad_experiment
//   build/quad_experiment common/scenes/cornell.json 300 128     # scene, image side, spp
//
// It renders the scene with lab 01's SceneView loops and with QuadGeometry below, interleaved,
// best of 5, through the same trace_path, and prints both times and how many pixels differ.
// Scenes made of quads only (the Cornell box): it refuses anything else.
//
// What QuadGeometry changes, per quad (triangles v0 v1 v2 and v0 v2 v3, one plane):
//  - one plane cull instead of two;
//  - the four vertices moved into ray space once (the shared v0 and v2 are not redone), read
//    straight from the quad by axis index instead of through a Vec3 built on the stack;
//  - five edge functions instead of six (the diagonal's, negated, serves both triangles);
//  - shadow rays first run the plane culls alone (in the Cornell box they rarely need more).
// Its arithmetic is lab 01's, so the hits are lab 01's, except that a ray exactly on a quad's
// diagonal takes the first triangle (lab 01 takes the second if its t is an ulp smaller), and
// that an edge function of exactly zero redoes all five in double (lab 01: that triangle's
// three), which can change the last bits of t. The renders in README.md differed in no pixel.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>
#include <path_tracer.h>
#include <scene_loader.h>

struct Quad {            // triangles (v0 v1 v2) and (v0 v2 v3), one plane
    float v[4][3];       // vertices, indexable by axis
    Vec3 normal;         // both triangles' normal
    float offset;        // both triangles' plane_offset
    int first_triangle;  // index of (v0 v1 v2) in the scene; (v0 v2 v3) is the next one
};

// What trace_path's closest_hit and occluded overloads below take in place of a SceneView.
struct QuadGeometry {
    SceneView scene;          // for the spheres
    std::vector<Quad> quads;  // every triangle of the scene, in pairs
};

static QuadGeometry group_into_quads(const SceneView& s) {
    QuadGeometry g{s, {}};
    auto same = [](Vec3 p, Vec3 q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
    for (int i = 0; i < s.num_triangles; i += 2) {
        const Triangle& a = s.triangles[i];
        const Triangle& b = s.triangles[i + 1 < s.num_triangles ? i + 1 : i];
        if (i + 1 >= s.num_triangles || !same(a.v0, b.v0) || !same(a.v2, b.v1) ||
            !same(a.normal, b.normal) || a.plane_offset != b.plane_offset) {
            fprintf(stderr, "quad_experiment: triangle %d does not start a planar quad\n", i);
            exit(2);
        }
        Quad q;
        Vec3 vs[4] = {a.v0, a.v1, a.v2, b.v2};
        for (int k = 0; k < 4; ++k) {
            q.v[k][0] = vs[k].x;
            q.v[k][1] = vs[k].y;
            q.v[k][2] = vs[k].z;
        }
        q.normal = a.normal;
        q.offset = a.plane_offset;
        q.first_triangle = i;
        g.quads.push_back(q);
    }
    return g;
}

// RayShear (triangle.h) with the ray origin's components in the permuted order.
struct PermutedRay {
    int kx, ky, kz;
    float sx, sy, sz;
    float ox, oy, oz;  // origin[kx], origin[ky], origin[kz]
};

static inline PermutedRay permute_ray(const Ray& ray) {
    const RayShear s(ray.direction);
    return {s.kx, s.ky, s.kz, s.sx, s.sy, s.sz,
            ray.origin[s.kx], ray.origin[s.ky], ray.origin[s.kz]};
}

// The end of intersect_triangle (triangle.h): t from the edge functions u, v, w of a
// triangle whose vertices lie at depths za, zb, zc, in (0, t_max), or t_max.
static inline float woop_distance(float u, float v, float w, float za, float zb, float zc,
                                  float sz, float t_max) {
    const float det = u + v + w;
    if (det == 0.0f) return t_max;
    const float t_scaled = u * (sz * za) + v * (sz * zb) + w * (sz * zc);
    const float sign = copysignf(1.0f, det);
    if (!(t_scaled * sign > 0.0f) || !(t_scaled * sign < t_max * det * sign)) return t_max;
    return t_scaled / det;
}

// The watertight test of both triangles of a quad: t in (0, t_max), with `which` set to 0 or 1
// for the triangle hit, or t_max.
static inline float intersect_quad(const PermutedRay& sh, const Quad& q, float t_max, int& which) {
    float px[4], py[4], pz[4];
    for (int k = 0; k < 4; ++k) {
        const float az = q.v[k][sh.kz] - sh.oz;
        px[k] = (q.v[k][sh.kx] - sh.ox) - sh.sx * az;
        py[k] = (q.v[k][sh.ky] - sh.oy) - sh.sy * az;
        pz[k] = az;
    }
    // Triangle 0 (v0 v1 v2) has u = E(2,1), v = E(0,2), w = E(1,0); triangle 1 (v0 v2 v3) has
    // u = E(3,2), v = E(0,3), w = E(2,0), which is exactly -E(0,2) (edge_function, triangle.h).
    float e21 = edge_function(px[2], py[2], px[1], py[1]);
    float e02 = edge_function(px[0], py[0], px[2], py[2]);
    float e10 = edge_function(px[1], py[1], px[0], py[0]);
    float e32 = edge_function(px[3], py[3], px[2], py[2]);
    float e03 = edge_function(px[0], py[0], px[3], py[3]);
    if (e21 == 0.0f || e02 == 0.0f || e10 == 0.0f || e32 == 0.0f || e03 == 0.0f) {
        e21 = (float)edge_function_exact(px[2], py[2], px[1], py[1]);
        e02 = (float)edge_function_exact(px[0], py[0], px[2], py[2]);
        e10 = (float)edge_function_exact(px[1], py[1], px[0], py[0]);
        e32 = (float)edge_function_exact(px[3], py[3], px[2], py[2]);
        e03 = (float)edge_function_exact(px[0], py[0], px[3], py[3]);
    }
    // Which side of the diagonal 0-2 the ray passes decides the triangle.
    const bool outside_first =
        ((e21 < 0) | (e02 < 0) | (e10 < 0)) & ((e21 > 0) | (e02 > 0) | (e10 > 0));
    if (!outside_first) {
        which = 0;
        return woop_distance(e21, e02, e10, pz[0], pz[1], pz[2], sh.sz, t_max);
    }
    const float e20 = -e02;
    const bool outside_second =
        ((e32 < 0) | (e03 < 0) | (e20 < 0)) & ((e32 > 0) | (e03 > 0) | (e20 > 0));
    if (outside_second) return t_max;
    which = 1;
    return woop_distance(e32, e03, e20, pz[0], pz[2], pz[3], sh.sz, t_max);
}

// The plane cull of intersect_triangle (triangle.h), once for both triangles.
static inline bool plane_culled(const Ray& ray, const Quad& q, float t_max) {
    const float denom = dot(q.normal, ray.direction);
    const float num = q.offset - dot(q.normal, ray.origin);
    const bool behind = num * denom <= 0.0f;
    const bool beyond = fabsf(num) >= t_max * 1.00001f * fabsf(denom);
    return behind | beyond;
}

RT_HD inline Hit closest_hit(const QuadGeometry& g, const Ray& ray) {
    Hit hit;
    for (int i = 0; i < g.scene.num_spheres; ++i) {
        const float t = intersect_sphere(ray, g.scene.spheres[i], hit.t);
        if (t < hit.t) {
            hit.t = t;
            hit.sphere = i;
        }
    }
    const PermutedRay sh = permute_ray(ray);
    const int n = (int)g.quads.size();
    for (int i = 0; i < n; ++i) {
        const Quad& q = g.quads[i];
        if (plane_culled(ray, q, hit.t)) continue;
        int which = 0;
        const float t = intersect_quad(sh, q, hit.t, which);
        if (t < hit.t) {
            hit.t = t;
            hit.sphere = -1;
            hit.triangle = q.first_triangle + which;
        }
    }
    return hit;
}

RT_HD inline bool occluded(const QuadGeometry& g, const Ray& ray, float t_max) {
    for (int i = 0; i < g.scene.num_spheres; ++i)
        if (intersect_sphere(ray, g.scene.spheres[i], t_max) < t_max) return true;
    const int n = (int)g.quads.size();
    bool any_candidate = false;
    for (int i = 0; i < n; ++i) any_candidate |= !plane_culled(ray, g.quads[i], t_max);
    if (!any_candidate) return false;
    const PermutedRay sh = permute_ray(ray);
    for (int i = 0; i < n; ++i) {
        const Quad& q = g.quads[i];
        if (plane_culled(ray, q, t_max)) continue;
        int which;
        if (intersect_quad(sh, q, t_max, which) < t_max) return true;
    }
    return false;
}

// Lab 01's pixel loop over `geometry`; returns the seconds it took.
template <class Geometry>
__attribute__((noinline)) double render_seconds(const SceneView& scene, const Geometry& geometry,
                                                const Camera& camera, const RenderSettings& st,
                                                std::vector<Vec3>& image) {
    const auto start = std::chrono::steady_clock::now();
    for (int y = 0; y < st.height; ++y) {
        for (int x = 0; x < st.width; ++x) {
            image[y * st.width + x] = render_pixel(scene, geometry, camera, st, x, y);
        }
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

int main(int argc, char** argv) {
    if (argc != 4) {
        fprintf(stderr, "usage: quad_experiment SCENE.json SIDE SPP\n");
        return 2;
    }
    const Scene scene = load_scene(argv[1]);
    RenderSettings st = scene.render;
    st.width = st.height = atoi(argv[2]);
    st.spp = atoi(argv[3]);
    const Camera camera = scene.camera.for_image(st.width, st.height);
    const SceneView view = scene.view();
    const QuadGeometry quads = group_into_quads(view);
    std::vector<Vec3> a(st.width * st.height), b(a.size());
    double best_a = 1e9, best_b = 1e9;
    for (int round = 0; round < 5; ++round) {  // interleaved, best of 5
        best_a = std::min(best_a, render_seconds(view, view, camera, st, a));
        best_b = std::min(best_b, render_seconds(view, quads, camera, st, b));
    }
    int differ = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        differ += !(a[i].x == b[i].x && a[i].y == b[i].y && a[i].z == b[i].z);
    }
    printf("lab 01 loops %.3f s  quad loops %.3f s  speedup %.3f  pixels that differ %d\n",
           best_a, best_b, best_a / best_b, differ);
}
