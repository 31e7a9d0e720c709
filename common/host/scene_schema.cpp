#include <scene_schema.h>

#include <nlohmann/json.hpp>

#include <material.h>
#include <primitive_kinds.h>

namespace {

using Json = nlohmann::ordered_json;  // keys in the order written, as the comment shows them

const char* role_name(FieldRole role) {
    switch (role) {
        case FieldRole::Point: return "point";
        case FieldRole::Length: return "length";
        case FieldRole::Direction: return "direction";
    }
    return "unknown";
}

Json vertex_list(const VertexList& list) {
    return {{"key", list.key},
            {"fields",
             Json::array({{{"key", "vertices"}, {"role", "points"}, {"count", list.vertices}}})}};
}

}  // namespace

std::string scene_schema_json() {
    Json primitives = Json::array();
    for_each_fields_kind([&](auto kind) {
        using K = typename decltype(kind)::type;
        Json fields = Json::array();
        for (const FileField& field : K::kFields)
            fields.push_back({{"key", field.key}, {"role", role_name(field.role)}});
        primitives.push_back({{"key", K::kFileKey}, {"fields", fields}});
    });
    primitives.push_back(vertex_list(kTriangleList));
    primitives.push_back(vertex_list(kQuadList));

    Json materials = Json::array();
    for_each_kind(AllMaterials{}, [&](auto kind) {
        using K = typename decltype(kind)::type;
        Json fields = Json::array();
        if (K::kAlbedo) fields.push_back({{"key", "albedo"}, {"role", "albedo"}});
        if (K::kNumber.key) {
            fields.push_back({{"key", K::kNumber.key},
                              {"role", "number"},
                              {"min", K::kNumber.lo},
                              {"max", K::kNumber.hi},
                              {"what", K::kNumber.what}});
        }
        materials.push_back({{"type", K::kName}, {"fields", fields}});
    });
    return Json{{"primitives", primitives}, {"materials", materials}}.dump();
}
