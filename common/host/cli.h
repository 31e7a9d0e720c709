// The command line every lab shares (DESIGN.md, "Command line").
#pragma once

#include <optional>
#include <string>

#include <scene.h>

struct Options {
    std::string scene_path;  // --scene; default common/scenes/cornell.json
    std::optional<int> width, height, spp, bounces;  // override the scene's settings
    std::optional<uint64_t> seed;
    std::string ppm_path;  // --out; empty: no PPM
    std::string pfm_path;  // --pfm; empty: no PFM
    int threads = 0;       // --threads; 0: every core (labs without threads ignore it)
    bool quiet = false;    // --quiet: no progress display
    bool json = false;     // --json: one JSON object as the last line of stdout
};

// A file of the source tree the binary was built from, by its path there ("common/scenes/
// cornell.json"): the one place that tree's location is compiled in.
std::string source_tree_path(const std::string& relative);

// The default scene, found relative to the source tree the binary was built from.
std::string default_scene_path();

// Parses argv; throws InputError naming the flag and what it expects. `--help` prints
// usage and `--scene-schema` the scene file's schema (scene_schema.h), each then exiting 0
// where it stands: a bad flag before it is still an error, none after it is read.
Options parse_options(int argc, char** argv, const char* program);

// The scene's render settings with the command line's overrides applied.
RenderSettings settings_for(const Scene& scene, const Options& options);
