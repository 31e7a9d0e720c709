// The shared command line: defaults, overrides, and InputErrors that name the flag.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <string>
#include <vector>

#include "cli.h"
#include "errors.h"
#include "scene_schema.h"

namespace {

// parse_options over a list of arguments (argv[0] is added).
Options parse(std::initializer_list<const char*> args) {
    std::vector<std::string> storage{"labXX"};
    for (const char* a : args) storage.emplace_back(a);
    std::vector<char*> argv;
    for (std::string& s : storage) argv.push_back(&s[0]);
    argv.push_back(nullptr);
    return parse_options(static_cast<int>(storage.size()), argv.data(), "labXX");
}

// Expects an InputError whose message names `flag` and contains `words`.
void expect_bad(std::initializer_list<const char*> args, const std::string& flag,
                const std::string& words = "") {
    try {
        parse(args);
        ADD_FAILURE() << "no error for " << flag;
    } catch (const InputError& e) {
        const std::string m = e.what();
        EXPECT_NE(m.find(flag), std::string::npos) << m;
        EXPECT_NE(m.find(words), std::string::npos) << m;
        EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
}

}  // namespace

TEST(Cli, Defaults) {
    const Options o = parse({});
    EXPECT_EQ(o.scene_path, source_tree_path("common/scenes/cornell.json"));
    EXPECT_EQ(o.scene_path, default_scene_path());
    EXPECT_FALSE(o.width);
    EXPECT_FALSE(o.height);
    EXPECT_FALSE(o.spp);
    EXPECT_FALSE(o.bounces);
    EXPECT_FALSE(o.seed);
    EXPECT_TRUE(o.ppm_path.empty());
    EXPECT_TRUE(o.pfm_path.empty());
    EXPECT_EQ(o.threads, 0);
    EXPECT_FALSE(o.quiet);
    EXPECT_FALSE(o.json);
}

TEST(Cli, EveryFlag) {
    const Options o =
        parse({"--scene", "a.json",    "--width",   "320",    "--height", "200",   "--spp",
               "7",       "--bounces", "3",         "--seed", "42",       "--out", "x.ppm",
               "--pfm",   "y.pfm",     "--threads", "5",      "--quiet",  "--json"});
    EXPECT_EQ(o.scene_path, "a.json");
    EXPECT_EQ(o.width.value_or(0), 320);
    EXPECT_EQ(o.height.value_or(0), 200);
    EXPECT_EQ(o.spp.value_or(0), 7);
    EXPECT_EQ(o.bounces.value_or(0), 3);
    EXPECT_EQ(o.seed.value_or(0), 42u);
    EXPECT_EQ(o.ppm_path, "x.ppm");
    EXPECT_EQ(o.pfm_path, "y.pfm");
    EXPECT_EQ(o.threads, 5);
    EXPECT_TRUE(o.quiet);
    EXPECT_TRUE(o.json);
}

TEST(Cli, LaterFlagWins) {
    const Options o = parse({"--spp", "4", "--spp", "9"});
    EXPECT_EQ(o.spp.value_or(0), 9);
}

TEST(Cli, LimitsAreInclusive) {
    const Options o = parse({"--width", "16384", "--height", "1", "--bounces", "64", "--seed",
                             std::to_string(kMaxSeed).c_str(), "--spp", "16777216"});
    EXPECT_EQ(*o.width, 16384);
    EXPECT_EQ(*o.height, 1);
    EXPECT_EQ(*o.bounces, 64);
    EXPECT_EQ(*o.seed, static_cast<uint64_t>(kMaxSeed));  // the scene files' range too
    EXPECT_EQ(*o.spp, 1 << 24);
    EXPECT_EQ(parse({"--seed", "0"}).seed.value_or(1), 0u);
}

TEST(Cli, BadValuesNameTheFlag) {
    expect_bad({"--width", "0"}, "--width", "'0'");
    expect_bad({"--width", "abc"}, "--width", "expected an integer");
    expect_bad({"--width", "16385"}, "--width", "16384");
    expect_bad({"--width", "12px"}, "--width", "'12px'");
    expect_bad({"--width", ""}, "--width");
    expect_bad({"--width", "1.5"}, "--width");
    expect_bad({"--height", "-3"}, "--height");
    expect_bad({"--spp", "-1"}, "--spp", "'-1'");
    expect_bad({"--spp", "0"}, "--spp");
    expect_bad({"--bounces", "0"}, "--bounces");
    expect_bad({"--bounces", "65"}, "--bounces");
    expect_bad({"--seed", "-1"}, "--seed");
    expect_bad({"--seed", "99999999999999999999999"}, "--seed");  // overflows long long
    expect_bad({"--threads", "0"}, "--threads");
    expect_bad({"--width", "99999999999999999999"}, "--width");
}

TEST(Cli, UnknownFlag) {
    expect_bad({"--widht", "600"}, "--widht", "unknown option");
    expect_bad({"-w"}, "-w", "unknown option");
    expect_bad({"scene.json"}, "scene.json");  // no positional arguments
}

TEST(Cli, MissingValue) {
    expect_bad({"--width"}, "--width", "expected a value");
    expect_bad({"--spp", "4", "--scene"}, "--scene", "expected a value");
    expect_bad({"--out"}, "--out");
    expect_bad({"--pfm"}, "--pfm");
}

TEST(Cli, HelpPrintsUsageAndExitsZero) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const std::string out = ::testing::TempDir() + "rt-unit-help.txt";
    std::remove(out.c_str());
    // The child sends its stdout to a file, so the usage text can be checked here.
    EXPECT_EXIT(
        {
            if (!std::freopen(out.c_str(), "w", stdout)) std::exit(3);
            parse({"--help"});
        },
        ::testing::ExitedWithCode(0), "");
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("usage: labXX"), std::string::npos) << text;
    EXPECT_NE(text.find("--spp"), std::string::npos) << text;
    std::remove(out.c_str());
}

TEST(Cli, SettingsForAppliesOverridesOnly) {
    Scene scene;
    scene.render.width = 100;
    scene.render.height = 50;
    scene.render.spp = 8;
    scene.render.bounces = 2;
    scene.render.seed = 3;
    const RenderSettings kept = settings_for(scene, parse({}));
    EXPECT_EQ(kept.width, 100);
    EXPECT_EQ(kept.height, 50);
    EXPECT_EQ(kept.spp, 8);
    EXPECT_EQ(kept.bounces, 2);
    EXPECT_EQ(kept.seed, 3u);
    const RenderSettings over =
        settings_for(scene, parse({"--height", "70", "--bounces", "6", "--seed", "0"}));
    EXPECT_EQ(over.width, 100);
    EXPECT_EQ(over.height, 70);
    EXPECT_EQ(over.spp, 8);
    EXPECT_EQ(over.bounces, 6);
    EXPECT_EQ(over.seed, 0u);  // an explicit 0 overrides too
    const RenderSettings all = settings_for(scene, parse({"--width", "1", "--height", "2", "--spp",
                                                          "3", "--bounces", "4", "--seed", "5"}));
    EXPECT_EQ(all.width, 1);
    EXPECT_EQ(all.height, 2);
    EXPECT_EQ(all.spp, 3);
    EXPECT_EQ(all.bounces, 4);
    EXPECT_EQ(all.seed, 5u);
}

TEST(Cli, SceneSchemaPrintsJsonAndExitsZero) {
    GTEST_FLAG_SET(death_test_style, "threadsafe");
    const std::string out = ::testing::TempDir() + "rt-unit-scene-schema.txt";
    std::remove(out.c_str());
    EXPECT_EXIT(
        {
            if (!std::freopen(out.c_str(), "w", stdout)) std::exit(3);
            parse({"--spp", "4", "--scene-schema", "--width", "0"});  // read no further
        },
        ::testing::ExitedWithCode(0), "");
    std::ifstream in(out);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, scene_schema_json() + "\n");
    std::remove(out.c_str());
    // A bad flag before it is an error, as before --help.
    expect_bad({"--width", "0", "--scene-schema"}, "--width");
}
