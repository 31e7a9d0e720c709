#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>

#include <cli.h>
#include <double_twin.h>
#include <errors.h>
#include <lab.h>
#include <scene_centring.h>
#include <scene_loader.h>
#include <scene_report.h>

std::string cpu_model_name() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            const size_t colon = line.find(':');
            if (colon != std::string::npos) return line.substr(colon + 2);
        }
    }
    return "unknown CPU";
}

static std::string json_escape(const std::string& s) {
    std::string out;
    for (char c : s) {
        if (c == '"' || c == '\\') out += '\\';
        if (static_cast<unsigned char>(c) >= 0x20) out += c;
    }
    return out;
}

struct Loaded {
    Scene scene;
    RenderSettings settings;
};

// The scene, centred on its geometry (where a scene sits in the world does not change its
// image), and the settings it renders with. One that float cannot place, or cannot render
// with those settings (a view too narrow, a light too bright: check_render_limits), goes to
// the double build where this binary carries one (a reference): this process becomes it,
// with the same command line. The double build reads the scene again, so a scene this
// process drained (a pipe, /dev/stdin) is refused instead.
static Loaded load_centred(const Options& options, char** argv) {
    try {
        Scene scene = centre_scene(load_scene(options.scene_path));
        const RenderSettings settings = settings_for(scene, options);
        check_render_limits(scene, settings.height, settings.bounces);
        return {std::move(scene), settings};
    } catch (const PrecisionError&) {
        if (!has_double_twin()) throw;
        struct stat st {};
        if (stat(options.scene_path.c_str(), &st) != 0 || !S_ISREG(st.st_mode)) {
            throw InputError(options.scene_path + " is no regular file, and only this " +
                             "reference's double build places its scene, which it would read " +
                             "again: save the scene to a file and pass that");
        }
        const char* why = run_double_twin(argv);
        throw InputError(std::string("cannot start this reference's double build: ") + why);
    }
}

// Which precision renders the scene, and why: the stderr summary and --json say it.
static std::string precision_reason(const Scene& scene) {
    if (std::string(kPrecisionName) == "float") return "float places every detail once centred";
    if (scene.float_refusal.empty()) return "a double build, asked for by name";
    return "float cannot place " + scene.float_refusal;
}

// `setup_reported` tells lab_main whether hooks.setup_done has been called already.
static int run(int argc, char** argv, const LabHooks& hooks, bool& setup_reported) {
    const Options options = parse_options(argc, argv, argv[0]);
    const Loaded loaded = load_centred(options, argv);
    const Scene& scene = loaded.scene;
    const RenderSettings& settings = loaded.settings;
    const std::string precision = precision_reason(scene);
    // What the scene uses before the render starts, and the triangles left out (not with
    // --quiet, which the grader and the tests use; --json carries it too).
    const SceneUse use = scene_use(scene);
    if (hooks.writes_output && !options.quiet) {
        std::fprintf(stderr, "%s; in %s: %s\n", describe(use).c_str(), kPrecisionName,
                     precision.c_str());
        const std::string lines = lines_left_out(use);
        if (!lines.empty()) std::fprintf(stderr, "%s\n", lines.c_str());
    }

    // Open the outputs before rendering: a bad path fails in a millisecond, not after the
    // render, and neither file appears until its bytes are complete.
    std::unique_ptr<AtomicFile> ppm, pfm;
    if (hooks.writes_output) {
        if (!options.ppm_path.empty()) ppm = std::make_unique<AtomicFile>(options.ppm_path);
        if (!options.pfm_path.empty()) pfm = std::make_unique<AtomicFile>(options.pfm_path);
    }

    Image image(settings.width, settings.height);
    Progress progress(settings.height, hooks.writes_output && progress_wanted(options.quiet));
    const RenderJob job{scene.view(), settings,
                        scene.camera.for_image(settings.width, settings.height), options.threads,
                        progress};
    if (hooks.setup_done) {
        setup_reported = true;
        hooks.setup_done(true);
    }
    const RenderStats stats = render(job, image);
    progress.finish();  // the bar's last line before anything else is printed
    if (!hooks.writes_output) return 0;

    if (ppm) ppm->commit(ppm_bytes(image));
    if (pfm) pfm->commit(pfm_bytes(image));

    const double paths = static_cast<double>(settings.width) * settings.height * settings.spp;
    const double paths_per_second = stats.seconds > 0 ? paths / stats.seconds : 0.0;
    if (options.json) {
        std::printf(
            "{\"lab\": \"%s\", \"scene\": \"%s\", \"width\": %d, \"height\": %d, \"spp\": %d, "
            "\"bounces\": %d, \"seed\": %llu, \"seconds\": %.6f, \"paths_per_second\": %.1f, "
            "\"device\": \"%s\", \"precision\": \"%s\", \"precision_reason\": \"%s\", "
            "\"scene_uses\": %s%s%s}\n",
            kLabName, json_escape(options.scene_path).c_str(), settings.width, settings.height,
            settings.spp, settings.bounces, static_cast<unsigned long long>(settings.seed),
            stats.seconds, paths_per_second, json_escape(stats.device).c_str(), kPrecisionName,
            json_escape(precision).c_str(), to_json(use).c_str(),
            stats.timing.empty() ? ""
                                 : (", \"timing\": \"" + json_escape(stats.timing) + "\"").c_str(),
            stats.layout.empty() ? "" : (", \"layout\": " + stats.layout).c_str());
    } else {
        std::printf("%s: %dx%d, %d spp, %d bounces: %.3f s render, %.2f Mpaths/s on %s\n", kLabName,
                    settings.width, settings.height, settings.spp, settings.bounces, stats.seconds,
                    paths_per_second / 1e6, stats.device.c_str());
    }
    return 0;
}

int lab_main(int argc, char** argv, const LabHooks& hooks) {
    bool setup_reported = false;
    // A process that fails before setup_done still tells the others, so none waits forever.
    const auto fail = [&](const char* message, int status) {
        if (hooks.writes_output) std::fprintf(stderr, "error: %s\n", message);
        if (hooks.setup_done && !setup_reported) hooks.setup_done(false);
        return status;
    };
    try {
        return run(argc, argv, hooks, setup_reported);
    } catch (const InputError& e) {
        return fail(e.what(), kExitBadInput);
    } catch (const DeviceError& e) {
        return fail(e.what(), kExitDeviceError);
    } catch (const std::bad_alloc&) {
        return fail("out of memory (is the image size or spp absurd?)", kExitBadInput);
    }
}
