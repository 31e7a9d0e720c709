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

// The camera as the file states it; the Camera proper depends on the image size.
struct CameraSpec {
    Vec3 position{0.5f, 0.5f, 1.0f};
    Vec3 look_at{0.5f, 0.5f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    real vfov_degrees = 55.0f;
    // look_at - position as the file writes them, in double (the loader sets it): the view's
    // direction, which rounding the two points to `real` first could turn by degrees when
    // they lie close together far from the origin. Zero: look_at - position is used.
    double forward[3] = {0.0, 0.0, 0.0};

    Camera for_image(int width, int height) const {
        if (forward[0] == 0.0 && forward[1] == 0.0 && forward[2] == 0.0)
            return Camera::look_at(position, look_at, up, vfov_degrees, width, height);
        return Camera::looking_along(position, forward, up, vfov_degrees, width, height);
    }
};

// A point as the scene file writes it: the JSON numbers as doubles, before rounding to `real`.
struct WrittenPoint {
    double x = 0.0, y = 0.0, z = 0.0;
};

// The scene's points as the file writes them, parallel to the Scene's own rounded ones.
// centre_scene (scene_centring.h) moves the scene by differences of these and rounds once,
// after the move: rounded first, every point of a scene moved 1e4 of its sizes away kept an
// error of ulp(1e4) ~ 1e-3 of its size through the move (a lamp 1e-2 above a floor rendered it
// 4.9% too bright). A scene built in code has none (`present` false) and is moved by its own.
struct WrittenCoordinates {
    bool present = false;
    WrittenPoint camera_position, camera_look_at, light_position;
    std::vector<WrittenPoint> sphere_centres;          // parallel to Scene::spheres
    std::vector<WrittenPoint> triangle_vertices;       // 3 per entry of Scene::triangles
};

struct Scene {
    std::string name;  // file stem, for messages
    CameraSpec camera;
    Vec3 background{0.0f};
    bool has_light = false;
    PointLight light{};
    std::vector<Material> materials;
    std::vector<std::string> material_names;  // parallel to materials
    std::vector<Sphere> spheres;
    std::vector<Triangle> triangles;  // quads arrive here as two triangles
    RenderSettings render;            // the file's settings, or the defaults
    WrittenCoordinates written;       // the file's points in double, for centre_scene

    SceneView view() const {
        return {spheres.data(),   static_cast<int>(spheres.size()),
                triangles.data(), static_cast<int>(triangles.size()),
                materials.data(), static_cast<int>(materials.size()),
                light,            has_light,
                background};
    }
};
