// How a primitive kind of a few numbers is written in a scene file: a list under its file key
// ("spheres"), each entry its fields and a "material". The loader, the centring, the scene
// limits and the report handle every kind declared this way alike (host/scene_loader.cpp,
// scene_centring.cpp, scene_limits.cpp, scene_report.cpp), and `--scene-schema` prints its
// fields' roles (host/scene_schema.cpp), by which labkit/scenes.py moves and scales scenes;
// triangles and quads, written as lists of vertices, have their own (host/scene_schema.h). A
// kind written as fields declares
//   kFileKey                 its list's key in a scene file;
//   kFields                  its fields (FileField), in order;
//   from_fields(KindTag<K>{}, values, material)  the primitive of its fields' values (3 numbers
//                            a point or direction, 1 a length), in kFields' order;
//   fields_of(k, values)     its values, as from_fields reads them.
//
// Header-only and free of the C++ library, so nvcc compiles it for the device (core/'s rule).
#pragma once

enum class FieldRole {
    Point,      // a position: moved when the scene is centred, judged by the scene limits
    Length,     // a size > 0, judged against the scene's extent
    Direction,  // a unit direction: normalised when read, the same wherever the scene is
};

struct FileField {
    const char* key;
    FieldRole role;
};

constexpr int field_size(FieldRole role) { return role == FieldRole::Length ? 1 : 3; }

// Whether K is written as fields: whether it declares kFields.
template <class K, class = void>
struct WrittenAsFields {
    static constexpr bool value = false;
};
template <class K>
struct WrittenAsFields<K, decltype(void(K::kFields))> {
    static constexpr bool value = true;
};
template <class K>
constexpr bool written_as_fields = WrittenAsFields<K>::value;

// The numbers of one entry of K.
template <class K>
constexpr int field_values() {
    int count = 0;
    for (const FileField& field : K::kFields) count += field_size(field.role);
    return count;
}

// Calls f(field, at) for each field of K in order, `at` where its values start (host code).
template <class K, class F>
void for_each_field(F&& f) {
    int at = 0;
    for (const FileField& field : K::kFields) {
        f(field, at);
        at += field_size(field.role);
    }
}
