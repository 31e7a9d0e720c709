// A loaded scene: what a scene file describes, owning the arrays that SceneView (core) views.
#pragma once

#include <string>
#include <vector>

#include <camera.h>
#include <scene_view.h>

// Limits that keep a typo from asking for an absurd render.
constexpr long kMaxImageSide = 16384;
constexpr long kMaxSpp = 1 << 24;
constexpr long kMaxBounces = 64;
// Seeds, in scene files and on the command line alike: 0 .. 2^53 - 1, the integers that every
// JSON reader (and a double) holds exactly.
constexpr long long kMaxSeed = (1LL << 53) - 1;

// A point as the scene file writes it: the JSON numbers as doubles, before rounding to `real`.
struct WrittenPoint {
    double x = 0.0, y = 0.0, z = 0.0;

    void store(double* v) const {  // as three numbers
        v[0] = x;
        v[1] = y;
        v[2] = z;
    }

    // Whether this point, rounded, is `p`: whether p still stands for it.
    bool rounds_to(Vec3 p) const {
        return static_cast<real>(x) == p.x && static_cast<real>(y) == p.y &&
               static_cast<real>(z) == p.z;
    }
};

// The camera as the file states it; the Camera proper depends on the image size.
struct CameraSpec {
    Vec3 position{0.5f, 0.5f, 1.0f};
    Vec3 look_at{0.5f, 0.5f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    real vfov_degrees = 55.0f;
    // position and look_at as the file writes them (the loader sets them, centre_scene moves
    // them): the view's direction is their difference in double. Rounding the two points
    // first could turn it by degrees when they lie close together far from the origin. Used
    // while position and look_at are still these points rounded.
    bool written = false;
    WrittenPoint written_position, written_look_at;

    Camera for_image(int width, int height) const {
        if (!(written && written_position.rounds_to(position) &&
              written_look_at.rounds_to(look_at)))
            return Camera::look_at(position, look_at, up, vfov_degrees, width, height);
        const double forward[3] = {written_look_at.x - written_position.x,
                                   written_look_at.y - written_position.y,
                                   written_look_at.z - written_position.z};
        return Camera::looking_along(position, forward, up, vfov_degrees, width, height);
    }
};

// The scene's points as the file writes them, parallel to the Scene's own rounded ones.
// centre_scene (scene_centring.h) moves the scene by differences of these and rounds once,
// after the move: rounded first, every point of a scene moved 1e4 of its sizes away kept an
// error of ulp(1e4) ~ 1e-3 of its size through the move (a lamp 1e-2 above a floor rendered it
// 4.9% too bright). A point the scene no longer holds (changed after loading, or a scene built
// in code) is moved from the scene's own.
// The numbers of a kind written as fields (file_fields.h), in double: field_values<K>() per
// entry of Scene::of<K>(), in its kFields' order (unused by the other kinds).
template <class K>
struct WrittenFields {
    std::vector<double> values;

    // Field value `offset` of entry i, as a point (the three numbers there).
    WrittenPoint point(size_t i, int offset) const {
        const double* v = &values[i * field_values<K>() + offset];
        return {v[0], v[1], v[2]};
    }
};

struct WrittenCoordinates {
    bool present = false;
    WrittenPoint light_position;
    PerKind<WrittenFields, AllPrimitives> fields;  // the kinds written as fields: of<Sphere>()
    std::vector<WrittenPoint> triangle_vertices;  // 3 per entry of Scene::of<Triangle>()
    std::vector<WrittenPoint> quad_vertices;      // 4 per entry of Scene::of<ConvexQuad>()
    std::vector<WrittenPoint> rect_vertices;  // 4 per entry of Scene::of<AxisRect>(), as written
};

template <class K>
using KindVector = std::vector<K>;

struct Scene {
    std::string name;  // file stem, for messages
    CameraSpec camera;
    Vec3 background{0.0f};
    bool has_light = false;
    PointLight light{};
    std::vector<Material> materials;
    std::vector<std::string> material_names;  // parallel to materials
    // One array per kind of AllPrimitives (of<Sphere>(), ...). of<Triangle>(): the file's
    // triangles, then the two triangles (v0 v1 v2), (v0 v2 v3) of each quad that is not planar
    // and convex; the other quads are one primitive each, a convex quad (ConvexQuad) or an
    // axis-aligned rectangle (AxisRect) (scene_loader.h).
    PerKind<KindVector, AllPrimitives> primitives;
    RenderSettings render;  // the file's settings, or the defaults
    WrittenCoordinates written;  // the file's points in double, for centre_scene
    // Why float cannot place this scene (scene_limits.h), "/pointer: what"; empty when it can
    // or when the scene was not loaded from a file. Set in both builds: the double build says
    // why it was needed (lab_main.cpp).
    std::string float_refusal;
    int t_junction_pieces = 0;  // primitives added by splitting at T-junctions (t_junctions.h)
    // Triangles of the file whose points lie on a line (scene_limits.h, on_a_line): left out
    // in every build; how many, and where the first is written ("/triangles/3").
    int line_triangles = 0;
    std::string first_line_triangle;

    template <class K>
    std::vector<K>& of() {
        return primitives.of<K>();
    }
    template <class K>
    const std::vector<K>& of() const {
        return primitives.of<K>();
    }

    SceneView view() const {
        SceneView v{{},    materials.data(), static_cast<int>(materials.size()),
                    light, has_light,        background};
        for_each_kind(AllPrimitives{}, [&](auto kind) {
            using K = typename decltype(kind)::type;
            v.primitives.of<K>() = {of<K>().data(), static_cast<int>(of<K>().size())};
        });
        return v;
    }
};
