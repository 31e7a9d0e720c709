// The scene model: what a scene file describes, in flat arrays that a GPU can copy as-is.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "camera.h"
#include "material.h"
#include "sphere.h"
#include "triangle.h"

struct PointLight {
    Vec3 position;   // world space
    Vec3 intensity;  // radiant intensity, W/sr per channel
};

// Limits that keep a typo from asking for an absurd render.
constexpr long kMaxImageSide = 16384;
constexpr long kMaxSpp = 1 << 24;
constexpr long kMaxBounces = 64;

// Render settings; a scene file may carry its own, command-line flags override them.
struct RenderSettings {
    int width = 600;    // pixels
    int height = 600;   // pixels
    int spp = 512;      // samples (camera paths) per pixel
    int bounces = 4;    // most surface interactions per path; 1 = direct lighting only
    uint64_t seed = 0;  // RNG seed
};

// The camera as the file states it; the Camera proper depends on the image size.
struct CameraSpec {
    Vec3 position{0.5f, 0.5f, 1.0f};
    Vec3 look_at{0.5f, 0.5f, 0.0f};
    Vec3 up{0.0f, 1.0f, 0.0f};
    float vfov_degrees = 55.0f;

    Camera for_image(int width, int height) const {
        return Camera::look_at(position, look_at, up, vfov_degrees, width, height);
    }
};

// Non-owning view of a scene's arrays: what render code on host or device reads.
struct SceneView {
    const Sphere* spheres;
    int num_spheres;
    const Triangle* triangles;
    int num_triangles;
    const Material* materials;
    int num_materials;
    PointLight light;
    bool has_light;
    Vec3 background;  // radiance of every ray that escapes
};

// A loaded scene: owns the arrays.
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
