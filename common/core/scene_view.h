// What render code on host or device reads of a scene: flat arrays that a GPU can copy as-is,
// the light, the background, and the render settings.
#pragma once

#include <cstdint>

#include <axis_rect.h>
#include <convex_quad.h>
#include <material.h>
#include <sphere.h>
#include <triangle.h>

struct PointLight {
    Vec3 position;   // world space
    Vec3 intensity;  // radiant intensity, W/sr per channel
};

// Render settings; a scene file may carry its own, command-line flags override them.
struct RenderSettings {
    int width = 600;    // pixels
    int height = 600;   // pixels
    int spp = 512;      // samples (camera paths) per pixel
    int bounces = 4;    // most surface interactions per path; 1 = direct lighting only
    uint64_t seed = 0;  // RNG seed
};

// Non-owning view of a scene's arrays.
struct SceneView {
    const Sphere* spheres;
    int num_spheres;
    const Triangle* triangles;
    int num_triangles;
    const ConvexQuad* quads;  // planar convex quads of the scene file
    int num_quads;
    const AxisRect* rects;  // its axis-aligned rectangles
    int num_rects;
    const Material* materials;
    int num_materials;
    PointLight light;
    bool has_light;
    Vec3 background;  // radiance of every ray that escapes
};
