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

    Camera for_image(int width, int height) const {
        return Camera::look_at(position, look_at, up, vfov_degrees, width, height);
    }
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

    SceneView view() const {
        return {spheres.data(),   static_cast<int>(spheres.size()),
                triangles.data(), static_cast<int>(triangles.size()),
                materials.data(), static_cast<int>(materials.size()),
                light,            has_light,
                background};
    }
};
