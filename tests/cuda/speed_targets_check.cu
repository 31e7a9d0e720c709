// The benchmarks' speed-target verdicts (bench/gpu/speed_targets.h), host code only: no
// GPU needed. Exits 0 when every case holds, else prints the first that does not and exits 1.
// Built and run by tests/labs/test_lab05.py.
#include <cstdio>
#include <cstring>
#include <string>

#include <speed_targets.h>

static int failures = 0;

static void expect(bool ok, const std::string& what, const std::string& got) {
    if (ok) return;
    std::printf("FAIL %s: %s\n", what.c_str(), got.c_str());
    ++failures;
}

static bool has(const std::string& text, const char* part) {
    return text.find(part) != std::string::npos;
}

int main() {
    cudaDeviceProp h200{}, h100{}, other{};
    std::strcpy(h200.name, "NVIDIA H200");
    std::strcpy(h100.name, "NVIDIA H100 80GB HBM3");
    std::strcpy(other.name, "NVIDIA A100-SXM4-80GB");
    const RenderSettings baseline{};  // 600x600, 512 spp, 4 bounces
    RenderSettings small = baseline;
    small.spp = 64;
    const std::string cornell = "/repo/common/scenes/cornell.json";

    expect(why_not_judged(h200, cornell, baseline).empty(), "the baseline on an H200 is judged",
           why_not_judged(h200, cornell, baseline));
    expect(why_not_judged(h100, cornell, baseline).empty(), "the baseline on an H100 is judged",
           why_not_judged(h100, cornell, baseline));
    expect(has(why_not_judged(other, cornell, baseline), "A100"), "another GPU is not judged",
           why_not_judged(other, cornell, baseline));
    expect(has(why_not_judged(h200, cornell, small), "baseline"), "other settings are not judged",
           why_not_judged(h200, cornell, small));
    expect(!why_not_judged(h200, "/repo/common/scenes/showcase.json", baseline).empty(),
           "another scene is not judged", "judged");

    constexpr SpeedTarget targets[] = {{"AoS", 60.0, nullptr}, {"SoA", 0.0, "AoS"}};
    const auto times = [](double aos, double soa) {
        return [=](const char* name) { return std::strcmp(name, "AoS") == 0 ? aos : soa; };
    };
    std::string json = targets_json(targets, times(55.0, 50.0), "", h200.name);
    expect(has(json,
               "\"config\": \"AoS\", \"bar\": \"at most 60 ms on an NVIDIA H200, the baseline\", "
               "\"best_ms\": 55.000, \"met\": true"),
           "a met bar", json);
    expect(has(json,
               "\"config\": \"SoA\", \"bar\": \"faster than AoS on an NVIDIA H200, the baseline\", "
               "\"best_ms\": 50.000, \"met\": true"),
           "a met comparison", json);
    json = targets_json(targets, times(61.0, 62.0), "", h200.name);
    expect(has(json, "\"best_ms\": 61.000, \"met\": false") &&
               has(json, "\"best_ms\": 62.000, \"met\": false"),
           "missed bars", json);
    json = targets_json(targets, times(55.0, 50.0), "not this GPU", other.name);
    expect(has(json, "\"met\": null, \"why_not\": \"not this GPU\""), "not judged", json);
    json = targets_json(targets, times(55.0, -1.0), "", h200.name);
    expect(has(json, "\"best_ms\": null, \"met\": null, \"why_not\": \"not run in this call\""),
           "not run", json);
    // A bar set for one card: on that card alone, named; a bar for every card names the one run.
    constexpr SpeedTarget per_card[] = {
        {"AoS", 60.0, nullptr, "H100"}, {"AoS", 50.0, nullptr, "H200"}, {"SoA", 0.0, "AoS"}};
    json = targets_json(per_card, times(55.0, 50.0), "", h100.name);
    expect(has(json,
               "\"bar\": \"at most 60 ms on an NVIDIA H100, the baseline\", "
               "\"best_ms\": 55.000, \"met\": true") &&
               !has(json, "at most 50 ms") && has(json, "faster than AoS on an NVIDIA H100"),
           "an H100's bars", json);
    json = targets_json(per_card, times(55.0, 50.0), "", h200.name);
    expect(has(json,
               "\"bar\": \"at most 50 ms on an NVIDIA H200, the baseline\", "
               "\"best_ms\": 55.000, \"met\": false") &&
               !has(json, "at most 60 ms"),
           "an H200's bars", json);
    if (failures == 0) std::printf("speed targets: every case holds\n");
    return failures == 0 ? 0 : 1;
}
