// The schema `--scene-schema` prints (scene_schema.h) is the kinds' own declarations, and it
// names what the loader reads: each primitive list and material type it lists loads, with
// exactly the keys it lists.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "errors.h"
#include "material.h"
#include "primitive_kinds.h"
#include "scene_loader.h"
#include "scene_schema.h"

namespace {

using nlohmann::json;

const json& schema() {
    static const json parsed = json::parse(scene_schema_json());
    return parsed;
}

// A scene of the camera, one material of each type (named after it) and `extra` entries.
std::string scene_with(const std::string& extra) {
    std::string materials;
    for (const json& m : schema()["materials"]) {
        json entry = {{"type", m["type"]}};
        for (const json& f : m["fields"])
            entry[f["key"].get<std::string>()] =
                f["role"] == "albedo" ? json::array({0.5, 0.5, 0.5}) : f["min"];
        materials += (materials.empty() ? "" : ", ") + json(m["type"]).dump() + ": " + entry.dump();
    }
    return R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}, "materials": {)" +
           materials + "}" + extra + "}";
}

// An entry of a primitive list with each of its fields written as its role asks.
json entry_of(const json& list) {
    json entry = {{"material", "diffuse"}};
    for (const json& f : list["fields"]) {
        const std::string role = f["role"];
        const std::string key = f["key"];
        if (role == "points") {
            // A planar convex polygon of `count` corners, counter-clockwise seen from +z.
            const std::vector<std::vector<double>> corners = {
                {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
            entry[key] = json::array();
            for (int k = 0; k < f["count"].get<int>(); ++k) entry[key].push_back(corners[k]);
        } else {
            entry[key] = role == "length" ? json(0.5) : json::array({0, 1, 0});
        }
    }
    return entry;
}

}  // namespace

TEST(SceneSchema, ListsEachKindWrittenAsFieldsThenTheVertexLists) {
    std::vector<std::string> keys;
    for (const json& p : schema()["primitives"]) keys.push_back(p["key"]);
    std::vector<std::string> want;
    for_each_fields_kind([&](auto kind) { want.push_back(decltype(kind)::type::kFileKey); });
    want.push_back(kTriangleList.key);
    want.push_back(kQuadList.key);
    EXPECT_EQ(keys, want);
    const json& spheres = schema()["primitives"][0];
    EXPECT_EQ(spheres["key"], "spheres");
    EXPECT_EQ(spheres["fields"], json::parse(R"([{"key": "center", "role": "point"},
                                                 {"key": "radius", "role": "length"}])"));
    EXPECT_EQ(schema()["primitives"][keys.size() - 1]["fields"][0]["count"], 4);
}

TEST(SceneSchema, ListsEveryMaterialKindWithItsKeysAndRange) {
    std::vector<std::string> types;
    for (const json& m : schema()["materials"]) types.push_back(m["type"]);
    std::vector<std::string> want;
    for_each_kind(AllMaterials{}, [&](auto kind) { want.push_back(decltype(kind)::type::kName); });
    EXPECT_EQ(types, want);
    const json& glass = schema()["materials"][kind_index<AllMaterials, Glass>];
    EXPECT_EQ(glass["fields"], json::parse(R"([{"key": "ior", "role": "number", "min": 1.0,
        "max": 5.0, "what": "an index of refraction"}])"));
    EXPECT_EQ(schema()["materials"][0]["fields"][0]["role"], "albedo");
}

TEST(SceneSchema, TheLoaderReadsEveryListWithTheKeysListedAndNoOthers) {
    for (const json& list : schema()["primitives"]) {
        const std::string key = list["key"];
        const json entry = entry_of(list);
        const std::string one = ", " + json(key).dump() + ": [" + entry.dump() + "]";
        EXPECT_NO_THROW(parse_scene(scene_with(one), key)) << one;
        json more = entry;
        more["extra"] = 1;
        EXPECT_THROW(
            parse_scene(scene_with(", " + json(key).dump() + ": [" + more.dump() + "]"), key),
            InputError)
            << key;
        for (const json& f : list["fields"]) {  // each listed key is required
            json fewer = entry;
            fewer.erase(f["key"].get<std::string>());
            EXPECT_THROW(
                parse_scene(scene_with(", " + json(key).dump() + ": [" + fewer.dump() + "]"), key),
                InputError)
                << key << " without " << f["key"];
        }
    }
}
