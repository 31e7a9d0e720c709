// Strict JSON scene loading: every mistake is an InputError that names the file, the line
// and column, and what was expected.
#pragma once

#include <string>

#include <scene.h>

// Loads a scene file (format: DESIGN.md, "Scene file").
Scene load_scene(const std::string& path);

// Loads a scene from text; `name` stands in for the file name in messages.
Scene parse_scene(const std::string& text, const std::string& name);
