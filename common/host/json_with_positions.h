// JSON parsing that remembers where each value starts, so that a scene file's errors can name
// the line and column of the offending value (nlohmann's DOM keeps no positions).
#pragma once

#include <cstddef>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

struct JsonWithPositions {
    nlohmann::json root;
    // JSON pointer -> offset of the value's first character; "<pointer>#key" -> of its key.
    std::map<std::string, size_t> offsets;
    std::string duplicate_key_pointer;  // the first key that appeared twice in one object
    std::string duplicate_key;          // that key, unescaped
};

// The deepest nesting of arrays and objects a file may have: a scene file needs 5 (the root,
// "quads", a quad, its "vertices", a point); anything deeper is refused before parsing.
constexpr size_t kMaxJsonDepth = 32;

// Parses `text`; a syntax error throws InputError "<name>:line L, column C: invalid JSON: ...",
// nesting deeper than kMaxJsonDepth one naming the bracket that goes past it.
JsonWithPositions parse_json_with_positions(const std::string& text, const std::string& name);

// "line L, column C" (both from 1) of an offset into `text`.
std::string line_column(const std::string& text, size_t offset);

// One JSON pointer token (RFC 6901): '~' becomes "~0" and '/' becomes "~1".
std::string pointer_token(const std::string& key);
