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

    void add(WrittenPoint p, double margin = 0.0) {
        const double c[3] = {p.x, p.y, p.z};
        for (int i = 0; i < 3; ++i) {
            lo[i] = std::min(lo[i], c[i] - margin);
            hi[i] = std::max(hi[i], c[i] + margin);
        }
        empty = false;
    }
};

WrittenPoint exact(Vec3 p) { return {p.x, p.y, p.z}; }

// The scene's points in double: as the file writes them, or, for a scene built in code (or
// one whose arrays were changed after loading), its own.
struct ExactPoints {
    const Scene& scene;
    bool written() const {
        return scene.written.present &&
               scene.written.sphere_centres.size() == scene.spheres.size() &&
               scene.written.triangle_vertices.size() == 3 * scene.triangles.size();
    }
    WrittenPoint sphere(size_t i) const {
        return written() ? scene.written.sphere_centres[i] : exact(scene.spheres[i].center);
    }
    WrittenPoint vertex(size_t i, int k) const {
        if (written()) return scene.written.triangle_vertices[3 * i + k];
        const Triangle& t = scene.triangles[i];
        return exact(k == 0 ? t.v0 : (k == 1 ? t.v1 : t.v2));
    }
    WrittenPoint camera_position() const {
        return written() ? scene.written.camera_position : exact(scene.camera.position);
    }
    WrittenPoint camera_look_at() const {
        return written() ? scene.written.camera_look_at : exact(scene.camera.look_at);
    }
    WrittenPoint light() const {
        return written() ? scene.written.light_position : exact(scene.light.position);
    }
};

void centre_of_bounds(const Scene& scene, double centre[3]) {
    const ExactPoints points{scene};
    BoundsD box;
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        box.add(points.sphere(i), scene.spheres[i].radius);
    for (size_t i = 0; i < scene.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k) box.add(points.vertex(i, k));
    }
    for (int axis = 0; axis < 3; ++axis)
        centre[axis] = box.empty ? 0.0 : 0.5 * (box.lo[axis] + box.hi[axis]);
}

// p - centre, in double, rounded once.
WrittenPoint minus(WrittenPoint p, const double centre[3]) {
    return {p.x - centre[0], p.y - centre[1], p.z - centre[2]};
}
Vec3 rounded(WrittenPoint p) {
    return {static_cast<real>(p.x), static_cast<real>(p.y), static_cast<real>(p.z)};
}

}  // namespace

Vec3 centring_offset(const Scene& scene) {
    double centre[3];
    centre_of_bounds(scene, centre);
    return {static_cast<real>(-centre[0]), static_cast<real>(-centre[1]),
            static_cast<real>(-centre[2])};
}

Scene centre_scene(Scene scene) {
    double centre[3];
    centre_of_bounds(scene, centre);
    if (centre[0] == 0.0 && centre[1] == 0.0 && centre[2] == 0.0)
        return scene;  // already centred: keep every bit as loaded
    const ExactPoints points{scene};
    WrittenCoordinates moved;
    moved.present = true;
    for (size_t i = 0; i < scene.spheres.size(); ++i)
        moved.sphere_centres.push_back(minus(points.sphere(i), centre));
    for (size_t i = 0; i < scene.triangles.size(); ++i) {
        for (int k = 0; k < 3; ++k)
            moved.triangle_vertices.push_back(minus(points.vertex(i, k), centre));
    }
    moved.camera_position = minus(points.camera_position(), centre);
    moved.camera_look_at = minus(points.camera_look_at(), centre);
    moved.light_position = minus(points.light(), centre);

    for (size_t i = 0; i < scene.spheres.size(); ++i)
        scene.spheres[i].center = rounded(moved.sphere_centres[i]);
    for (size_t i = 0; i < scene.triangles.size(); ++i) {
        const WrittenPoint* v = &moved.triangle_vertices[3 * i];
        scene.triangles[i] = make_triangle(rounded(v[0]), rounded(v[1]), rounded(v[2]),
                                           scene.triangles[i].material);
    }
    scene.camera.position = rounded(moved.camera_position);
    scene.camera.look_at = rounded(moved.camera_look_at);
    scene.light.position = rounded(moved.light_position);
    scene.written = moved;  // the camera's forward is a difference: the move keeps it
    return scene;
}
