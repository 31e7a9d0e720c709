// What every lab implements, and what the shared main (lab_main.cpp) gives it.
#pragma once

#include <functional>
#include <string>

#include <camera.h>
#include <image.h>
#include <progress.h>
#include <scene_view.h>

// One render to do: what a lab needs, and nothing of the scene file it came from.
struct RenderJob {
    SceneView scene;          // the scene's arrays, light and background
    RenderSettings settings;  // the scene's settings with the command line applied
    Camera camera;            // for settings.width x settings.height
    int threads;              // --threads, or 0 for "every core"
    Progress& progress;       // report finished rows here
};

// What a lab reports about its render.
struct RenderStats {
    double seconds = 0;  // render time only: no loading, writing or context creation
    std::string device;  // what it ran on, e.g. "AMD EPYC, 1 thread"
    std::string timing = "";  // what `seconds` covers, when more needs saying (GPU: kernel only)
    std::string layout =
        "";  // the wavefront labs: how the path pool lays items out (a JSON object)
};

// Implemented once per lab (skeleton and solution alike).
extern const char* const kLabName;  // e.g. "01-serial"
#if defined(RT_DOUBLE)
// A lab compiled in double (real.h) linked with the float driver, or the reverse, would mix
// two layouts of Vec3 without a word. In the double build render() has another symbol name,
// so such a link fails instead (undefined reference to render_double or render).
#define render render_double
#endif
RenderStats render(const RenderJob& job, Image& image);

// How a lab that runs as several processes (lab 04's MPI ranks) uses the shared main. The
// defaults describe one process, which is what every other lab is.
struct LabHooks {
    // This process opens and writes --out/--pfm and prints the summary and error lines; the
    // others render, then exit with the same status, silently.
    bool writes_output = true;
    // Called by every process once its setup (flags, scene, output files, image) has
    // succeeded or failed, before rendering: where the processes agree to go on. With
    // setup_ok it may throw InputError because another process failed; its message is the
    // error line. Empty: nobody else to agree with.
    std::function<void(bool setup_ok)> setup_done;
};

// The shared main: parse flags, load the scene, check outputs, render, write, summarise.
// Returns the process exit status.
int lab_main(int argc, char** argv, const LabHooks& hooks = {});

// The CPU's model name, for RenderStats::device.
std::string cpu_model_name();
