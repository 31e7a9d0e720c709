// The stage loop: the order in which one wave's kernels run and which queue feeds which.
// `stages` launches each kernel (WaveStages in wavefront_renderer.cuh); stages.active(b) is
// the queue of the paths about to make their surface interaction number b, stages.shadows(b)
// the queue of the shadow rays that interaction asks for. The host only queues the launches;
// the GPU runs them in order, each reading its queue's size itself, so a queue that the
// previous stage left empty costs its kernel next to nothing.
//!
//! Lab 06 students write run_wave (the region between BEGIN/END SOLUTION); labkit/skeletons.py
//! turns this file into labs/06-cuda-split/skeleton/stage_loop.cuh.
//! It stands in for this file in the lab's own build (first on the include path).
#pragma once

template <class Stages>
void run_wave(Stages& stages, int bounces) {
    // BEGIN SOLUTION
    stages.generate_camera_paths(stages.active(0));
    for (int bounce = 0; bounce < bounces; ++bounce) {
        stages.find_closest_hits(stages.active(bounce));
        stages.shade_hits(stages.active(bounce), stages.active(bounce + 1), stages.shadows(bounce));
        stages.trace_shadow_rays(stages.shadows(bounce));
    }
    stages.accumulate_samples();
    // SKELETON
    //> // TODO(lab06): the wave's stages. Camera paths onto the first active queue; then, for
    //> // each of the `bounces` interactions, closest hits, shading (which fills the next
    //> // bounce's active queue and this bounce's shadow queue) and shadow rays; last, the
    //> // samples into their pixels. Until then: the first interaction only (direct light of
    //> // the surfaces the camera sees, nothing reflected), whatever `bounces` says.
    //> (void)bounces;
    //> stages.generate_camera_paths(stages.active(0));
    //> stages.find_closest_hits(stages.active(0));
    //> stages.shade_hits(stages.active(0), stages.active(1), stages.shadows(0));
    //> stages.trace_shadow_rays(stages.shadows(0));
    //> stages.accumulate_samples();
    // END SOLUTION
}
