// Lab 02's reference at full speed: packets that stay full. packet_tracer.h traces a packet's
// paths from camera to end together, so a lane whose path ended idles until the last lane
// is done: on the Cornell box the packets are 100, 99, 73 and 61% full at bounces 0-3, on the
// showcase at 8 bounces 38% by the last (handouts/02-simd.md, section 8, measures it).
//
// Here the paths of a group (up to kGroupPaths consecutive samples of a run of pixels) advance
// bounce by bounce instead: every path of the group takes bounce b, packet after packet, then
// every survivor takes bounce b + 1. After each packet's bounce its surviving lanes are moved
// together (Compress8 / Compress16) and written back behind the survivors found so far, so
// the next bounce again runs on full packets, and only the group's last packet is partly
// empty. A path's bounce is packet_tracer.h's bounce_step and shadow ray, lane by lane, on
// the path's own numbers and random stream, so each path computes lab 01's bits wherever its
// lane is; a finished path leaves its radiance in its sample's slot, and each pixel adds its
// slots in sample order, as lab 01 does. So the image is lab 01's, bit for bit.
//
// Why not refill an emptied lane with the next camera ray ("regeneration") instead: that keeps
// packets as full, but mixes rays of every bounce in one packet. Camera rays of neighbouring
// samples are coherent (they pass the same triangles' plane cull); scattered late bounces are
// not, and a packet pays the full triangle test when any lane needs it. Compaction packs
// rays of one bounce together (handouts/02-simd.md, section 8).
//
// Memory per group is bounded: kGroupPaths paths of 15 words, plus one packet of slack, on
// the stack (about 17 KB with 16 lanes), whatever the image or spp.
#pragma once

#include <cstdint>

#include <lane_use.h>
#include <packet_tracer.h>

// Paths per group: 16 full packets of 16 lanes at bounce 0, so that the survivors of later
// bounces still fill most packets, and few enough (15 KB) for the group to stay in the L1
// data cache.
constexpr int kGroupPaths = 256;

// The paths of a group in structure-of-arrays form: entries [0, count) are alive, in any
// order. Every entry up to the last packet's end holds a real path's numbers (the camera
// rays fill whole packets, and compaction moves whole packets), so no lane ever computes on
// uninitialised memory.
template <class F>
struct PathGroup {
    static constexpr int kLanes = F::kLanes;
    static constexpr int kCapacity = kGroupPaths + kLanes;

    alignas(64) float origin[3][kCapacity];
    alignas(64) float direction[3][kCapacity];
    alignas(64) float throughput[3][kCapacity];
    alignas(64) float radiance[3][kCapacity];
    alignas(64) uint32_t key_low[kCapacity];   // SampleStream's key, low and high words
    alignas(64) uint32_t key_high[kCapacity];
    alignas(64) int32_t slot[kCapacity];       // the path's sample within the group
    int count = 0;

    PathPacket<F> load(int i, int bounce, MaskOf<F> active) const {
        const auto v = [i](const float(&a)[3][kCapacity]) {
            return Vec3xN<F>(F::load(a[0] + i), F::load(a[1] + i), F::load(a[2] + i));
        };
        return {{v(origin), v(direction)}, v(throughput), v(radiance), bounce, active};
    }

    // Writes the lanes of `keep` at entries at, at+1, ...; returns how many. Writes a whole
    // packet from `at`: the caller's `at` is at most the packet's own first entry.
    template <class Compress>
    int store(int at, const Compress& keep, const PathPacket<F>& path, IntOf<F> slots, IntOf<F> low,
              IntOf<F> high) {
        const auto put = [&](float(&a)[3][kCapacity], const Vec3xN<F>& value) {
            keep(value.x).store(a[0] + at);
            keep(value.y).store(a[1] + at);
            keep(value.z).store(a[2] + at);
        };
        put(origin, path.ray.origin);
        put(direction, path.ray.direction);
        put(throughput, path.throughput);
        put(radiance, path.radiance);
        keep(slots).store(slot + at);
        keep(low).store(reinterpret_cast<int32_t*>(key_low + at));
        keep(high).store(reinterpret_cast<int32_t*>(key_high + at));
        return keep.count();
    }
};

// Traces every path of `group` to its end, bounce by bounce, and leaves each path's radiance
// in out[channel][its slot]. Counts the packets and paths of each bounce in `use`, if given.
template <class F>
inline void trace_group(const SceneView& scene, int max_bounces, PathGroup<F>& group,
                        float (&out)[3][kGroupPaths], LaneUse* use = nullptr) {
    constexpr int kLanes = F::kLanes;
    using I = IntOf<F>;
    if (max_bounces <= 0) group.count = 0;  // trace_path: no interaction, no light
    for (int bounce = 0; group.count > 0; ++bounce) {
        if (use != nullptr) use->add(bounce, (group.count + kLanes - 1) / kLanes, group.count);
        int kept = 0;
        for (int i = 0; i < group.count; i += kLanes) {
            const auto active = MaskOf<F>::first(group.count - i);
            PathPacket<F> path = group.load(i, bounce, active);
            const I low = I::load(reinterpret_cast<const int32_t*>(group.key_low + i));
            const I high = I::load(reinterpret_cast<const int32_t*>(group.key_high + i));
            const SampleStreamN<F> rng(group.key_low + i, group.key_high + i);
            // One bounce of trace_paths' loop.
            const HitPacket<F> hit = closest_hit(scene, path.ray, path.alive);
            ShadowPacket<F> shadow{};
            const auto lit = bounce_step(scene, hit, rng, max_bounces, path, shadow);
            add_unblocked_light(scene, lit, shadow, path);
            // Paths that ended leave their radiance; the others move up behind the survivors.
            const I slots = I::load(group.slot + i);
            const auto ended = and_not(active, path.alive);
            if (any(ended)) {
                alignas(64) float r[3][kLanes];
                alignas(64) int32_t s[kLanes];
                path.radiance.x.store(r[0]);
                path.radiance.y.store(r[1]);
                path.radiance.z.store(r[2]);
                slots.store(s);
                for (unsigned bits = ended.bits(); bits != 0; bits &= bits - 1) {
                    const int lane = __builtin_ctz(bits);
                    for (int c = 0; c < 3; ++c) out[c][s[lane]] = r[c][lane];
                }
            }
            kept += group.store(kept, typename F::Compress(path.alive), path, slots, low, high);
        }
        group.count = kept;
    }
}

// render_pixel for `pixel_count` consecutive pixels (row-major, from pixel index
// first_pixel = y * width + x), each mean written to out[0 .. pixel_count - 1]: the run's
// samples in groups of kGroupPaths, each group traced by trace_group, then each pixel's
// samples added in sample order.
template <class F>
inline void render_pixels_compacted(const SceneView& scene, const Camera& camera,
                                    const RenderSettings& settings, long first_pixel,
                                    int pixel_count, Vec3* out, LaneUse* use = nullptr) {
    constexpr int kLanes = F::kLanes;
    using Stream = SampleStreamN<F>;
    const int spp = settings.spp;
    const long paths = static_cast<long>(pixel_count) * spp;
    PathGroup<F> group;
    alignas(64) float radiance[3][kGroupPaths];
    alignas(64) float px[PathGroup<F>::kCapacity], py[PathGroup<F>::kCapacity];
    // The next path to start: sample `sample` of pixel first_pixel + pixel.
    int pixel = 0, sample = 0;
    uint64_t pixel_key = Stream::pixel_key(settings.seed, static_cast<uint64_t>(first_pixel));
    int x = static_cast<int>(first_pixel % settings.width);  // its column and row
    int y = static_cast<int>(first_pixel / settings.width);
    // The next pixel to sum: its sum so far and its samples so far.
    int sum_pixel = 0, summed = 0;
    SampleSum sum;
    for (long start = 0; start < paths; start += kGroupPaths) {
        const int n = static_cast<int>(paths - start < kGroupPaths ? paths - start : kGroupPaths);
        // Camera rays: slot i is path start + i. The last packet's spare lanes repeat the
        // last path (their results go nowhere), so every lane holds a real ray.
        const int filled = (n + kLanes - 1) / kLanes * kLanes;
        for (int i = 0; i < filled; ++i) {
            if (i >= n) {
                group.slot[i] = group.slot[n - 1];
                group.key_low[i] = group.key_low[n - 1];
                group.key_high[i] = group.key_high[n - 1];
                px[i] = px[n - 1];
                py[i] = py[n - 1];
                continue;
            }
            const uint64_t key = Stream::path_key(pixel_key, static_cast<uint64_t>(sample));
            group.slot[i] = i;
            group.key_low[i] = static_cast<uint32_t>(key);
            group.key_high[i] = static_cast<uint32_t>(key >> 32);
            px[i] = static_cast<float>(x);
            py[i] = static_cast<float>(y);
            if (++sample == spp) {
                sample = 0;
                if (++x == settings.width) {
                    x = 0;
                    ++y;
                }
                if (++pixel < pixel_count) {
                    pixel_key = Stream::pixel_key(settings.seed,
                                                  static_cast<uint64_t>(first_pixel + pixel));
                }
            }
        }
        for (int i = 0; i < filled; i += kLanes) {
            const Stream rng(group.key_low + i, group.key_high + i);
            // Camera::ray_through at x + jitter, y + jitter, as render_pixel.
            const RayPacket<F> ray = camera_rays(camera, F::load(px + i) + rng.at(kDimPixelX),
                                                 F::load(py + i) + rng.at(kDimPixelY));
            const PathPacket<F> path{ray, Vec3xN<F>(Vec3(1.0f)), Vec3xN<F>(Vec3(0.0f)), 0,
                                     MaskOf<F>::all()};
            group.store(i, typename F::Compress(MaskOf<F>::all()), path,
                        IntOf<F>::load(group.slot + i),
                        IntOf<F>::load(reinterpret_cast<const int32_t*>(group.key_low + i)),
                        IntOf<F>::load(reinterpret_cast<const int32_t*>(group.key_high + i)));
        }
        group.count = n;
        for (int c = 0; c < 3; ++c) {
            for (int i = 0; i < n; ++i) radiance[c][i] = 0.0f;  // a path of no bounce
        }
        trace_group(scene, settings.bounces, group, radiance, use);
        for (int i = 0; i < n; ++i) {
            sum.add(Vec3(radiance[0][i], radiance[1][i], radiance[2][i]));
            if (++summed == spp) {
                out[sum_pixel++] = sum.mean(spp);
                sum = SampleSum();
                summed = 0;
            }
        }
    }
}
