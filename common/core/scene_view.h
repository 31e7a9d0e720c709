// What render code on host or device reads of a scene: flat arrays that a GPU can copy as-is,
// the light, the background, and the render settings.
#pragma once

#include <cstdint>

#include <material.h>
#include <primitive_kinds.h>

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

// One kind's primitives in a scene: where they lie and how many.
template <class K>
struct KindSpan {
    const K* items = nullptr;
    int count = 0;

    RT_HD const K& operator[](int i) const { return items[i]; }
};

// Non-owning view of a scene's arrays: one per kind of AllPrimitives (of<Sphere>(), ...).
struct SceneView {
    PerKind<KindSpan, AllPrimitives> primitives;
    const Material* materials;
    int num_materials;
    PointLight light;
    bool has_light;
    Vec3 background;  // radiance of every ray that escapes

    template <class K>
    RT_HD const KindSpan<K>& of() const {
        return primitives.of<K>();
    }
    template <class K>
    RT_HD KindSpan<K>& of() {
        return primitives.of<K>();
    }
};
