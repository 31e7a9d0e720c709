#include <scene_centring.h>

#include <algorithm>
#include <limits>

namespace {

struct BoundsD {
    double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                    std::numeric_limits<double>::max()};
    double hi[3] = {-std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
                    -std::numeric_limits<double>::max()};
    bool empty = true;

    void add(Vec3 p, double margin = 0.0) {
        const double c[3] = {p.x, p.y, p.z};
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], c[i] - margin);
            hi[i] = std::max(hi[i], c[i] + margin);
        }
        empty = false;
    }
};

Vec3 moved(Vec3 p, const double offset[3]) {
    return {static_cast<real>(p.x + offset[0]), static_cast<real>(p.y + offset[1]),
            static_cast<real>(p.z + offset[2])};
}

}  // namespace

Vec3 centring_offset(const Scene& scene) {
    BoundsD box;
    for (const Sphere& s : scene.spheres) box.add(s.center, s.radius);
    for (const Triangle& t : scene.triangles) {
        box.add(t.v0);
        box.add(t.v1);
        box.add(t.v2);
    }
    if (box.empty) return Vec3(0.0f);
    return {static_cast<real>(-0.5 * (box.lo[0] + box.hi[0])),
            static_cast<real>(-0.5 * (box.lo[1] + box.hi[1])),
            static_cast<real>(-0.5 * (box.lo[2] + box.hi[2]))};
}

Scene centre_scene(Scene scene) {
    const Vec3 o = centring_offset(scene);
    if (is_black(o)) return scene;  // already centred: keep every bit as loaded
    const double offset[3] = {o.x, o.y, o.z};
    for (Sphere& s : scene.spheres) s.center = moved(s.center, offset);
    for (Triangle& t : scene.triangles) {
        t = make_triangle(moved(t.v0, offset), moved(t.v1, offset), moved(t.v2, offset),
                          t.material);
    }
    scene.camera.position = moved(scene.camera.position, offset);
    scene.camera.look_at = moved(scene.camera.look_at, offset);
    scene.light.position = moved(scene.light.position, offset);
    return scene;
}
