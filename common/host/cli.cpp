#include <cli.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include <errors.h>
#include <scene_schema.h>

#ifndef RT_SOURCE_DIR
#define RT_SOURCE_DIR "."
#endif

std::string source_tree_path(const std::string& relative) {
    return std::string(RT_SOURCE_DIR) + "/" + relative;
}

std::string default_scene_path() { return source_tree_path("common/scenes/cornell.json"); }

static void print_usage(const char* program) {
    std::printf(
        "usage: %s [--scene FILE.json] [--width W] [--height H] [--spp S] [--bounces B]\n"
        "          [--seed N] [--out IMAGE.ppm] [--pfm IMAGE.pfm] [--threads T]\n"
        "          [--quiet] [--json] [--scene-schema] [--help]\n"
        "Renders a scene with a Monte Carlo path tracer. Defaults: common/scenes/cornell.json,\n"
        "the scene's own render settings (else 600x600, 512 spp, 4 bounces), seed 0.\n"
        "--scene-schema prints the scene file's primitive lists and material types (JSON)\n"
        "and exits, rendering nothing.\n",
        program);
}

static long long parse_integer(const std::string& flag, const char* text, long long lo,
                               long long hi) {
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || v < lo || v > hi)
        throw InputError(flag + ": expected an integer in " + std::to_string(lo) + ".." +
                         std::to_string(hi) + ", found '" + text + "'");
    return v;
}

Options parse_options(int argc, char** argv, const char* program) {
    Options o;
    o.scene_path = default_scene_path();
    for (int i = 1; i < argc; ++i) {
        const std::string flag = argv[i];
        auto value = [&]() -> const char* {
            if (i + 1 >= argc) throw InputError(flag + ": expected a value after the flag");
            return argv[++i];
        };
        if (flag == "--help" || flag == "-h") {
            print_usage(program);
            std::exit(0);
        } else if (flag == "--scene-schema") {  // exits as --help does, at its place
            std::printf("%s\n", scene_schema_json().c_str());
            std::exit(0);
        } else if (flag == "--scene") {
            o.scene_path = value();
        } else if (flag == "--width") {
            o.width = static_cast<int>(parse_integer(flag, value(), 1, kMaxImageSide));
        } else if (flag == "--height") {
            o.height = static_cast<int>(parse_integer(flag, value(), 1, kMaxImageSide));
        } else if (flag == "--spp") {
            o.spp = static_cast<int>(parse_integer(flag, value(), 1, kMaxSpp));
        } else if (flag == "--bounces") {
            o.bounces = static_cast<int>(parse_integer(flag, value(), 1, kMaxBounces));
        } else if (flag == "--seed") {
            o.seed = static_cast<uint64_t>(parse_integer(flag, value(), 0, kMaxSeed));
        } else if (flag == "--out") {
            o.ppm_path = value();
        } else if (flag == "--pfm") {
            o.pfm_path = value();
        } else if (flag == "--threads") {
            o.threads = static_cast<int>(parse_integer(flag, value(), 1, 4096));
        } else if (flag == "--quiet") {
            o.quiet = true;
        } else if (flag == "--json") {
            o.json = true;
        } else {
            throw InputError(flag + ": unknown option (see --help)");
        }
    }
    return o;
}

RenderSettings settings_for(const Scene& scene, const Options& options) {
    RenderSettings s = scene.render;
    if (options.width) s.width = *options.width;
    if (options.height) s.height = *options.height;
    if (options.spp) s.spp = *options.spp;
    if (options.bounces) s.bounces = *options.bounces;
    if (options.seed) s.seed = *options.seed;
    return s;
}
