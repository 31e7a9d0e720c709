// What every lab implements, and what the shared main (lab_main.cpp) gives it.
#pragma once

#include <string>

#include "image.h"
#include "progress.h"
#include "scene.h"

// One render to do.
struct RenderJob {
    const Scene& scene;
    RenderSettings settings;  // the scene's settings with the command line applied
    Camera camera;            // for settings.width x settings.height
    int threads;              // --threads, or 0 for "every core"
    Progress& progress;       // report finished rows here
};

// What a lab reports about its render.
struct RenderStats {
    double seconds = 0;  // render time only: no loading, writing or context creation
    std::string device;  // what it ran on, e.g. "AMD EPYC, 1 thread"
};

// Implemented once per lab (skeleton and solution alike).
extern const char* const kLabName;  // e.g. "01-serial"
RenderStats render(const RenderJob& job, Image& image);

// The shared main: parse flags, load the scene, check outputs, render, write, summarise.
// Returns the process exit status.
int lab_main(int argc, char** argv);

// The CPU's model name, for RenderStats::device.
std::string cpu_model_name();
