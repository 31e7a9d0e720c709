// Strict JSON scene loading: every mistake is an InputError that names the file, the line
// and column, and what was expected.
#pragma once

#include <string>

#include <scene.h>

// Loads a scene file (format: DESIGN.md, "Scene file").
Scene load_scene(const std::string& path);

// Loads a scene from text; `name` stands in for the file name in messages.
Scene parse_scene(const std::string& text, const std::string& name);

// What the build's precision cannot render once the image's height and bounce count are
// known (scene_limits.h, render_problem), refused as the loader refuses what it cannot place:
// in the float build, what double renders is a PrecisionError (a reference hands the scene to
// its double build); the double build keeps float's reason in scene.float_refusal.
void check_render_limits(Scene& scene, int image_height, int bounces);
