// JSON parsing that remembers where each value is, for error messages that point at the
// line and column of the offending value.
#include <json_with_positions.h>

#include <cctype>
#include <cstring>
#include <iterator>
#include <set>
#include <utility>
#include <vector>

#include <errors.h>

using nlohmann::json;

namespace {

// A char iterator that publishes how far the parser has read, so SAX events can be tied to
// a place in the text (nlohmann's SAX interface reports no positions of its own).
struct CountingIterator {
    using iterator_category = std::forward_iterator_tag;
    using value_type = char;
    using difference_type = std::ptrdiff_t;
    using pointer = const char*;
    using reference = const char&;

    const char* p;
    const char* begin;
    size_t* consumed;  // shared with the handler: characters read so far

    reference operator*() const { return *p; }
    CountingIterator& operator++() {
        ++p;
        *consumed = static_cast<size_t>(p - begin);
        return *this;
    }
    CountingIterator operator++(int) {
        CountingIterator old = *this;
        ++*this;
        return old;
    }
    bool operator==(const CountingIterator& o) const { return p == o.p; }
    bool operator!=(const CountingIterator& o) const { return p != o.p; }
};

// The DOM under construction: each SAX event adds a value where the parser stands (the
// root, the end of the open array, or the open object's current key). A duplicate key
// overwrites (the last one wins, as in nlohmann's own parser); PositionRecorder reports it.
class DomBuilder {
public:
    explicit DomBuilder(json& root) : root_(root) {}

    bool null() { return put(nullptr); }
    bool boolean(bool v) { return put(v); }
    bool number_integer(json::number_integer_t v) { return put(v); }
    bool number_unsigned(json::number_unsigned_t v) { return put(v); }
    bool number_float(json::number_float_t v, const json::string_t&) { return put(v); }
    bool string(json::string_t& v) { return put(std::move(v)); }
    bool binary(json::binary_t& v) { return put(json::binary(std::move(v))); }
    bool key(json::string_t& k) {
        key_ = k;
        return true;
    }
    bool start_object(std::size_t) { return open(json::object()); }
    bool start_array(std::size_t) { return open(json::array()); }
    bool end_object() { return close(); }
    bool end_array() { return close(); }

private:
    // Where the next value goes. Pointers to open containers stay valid: nothing is added
    // to a container's parent while the container is open.
    json& slot() {
        if (open_.empty()) return root_;
        json& parent = *open_.back();
        if (parent.is_array()) {
            parent.push_back(nullptr);
            return parent.back();
        }
        return parent[key_];
    }
    template <class V>
    bool put(V&& v) {
        slot() = json(std::forward<V>(v));
        return true;
    }
    bool open(json container) {
        json& s = slot();
        s = std::move(container);
        open_.push_back(&s);
        return true;
    }
    bool close() {
        open_.pop_back();
        return true;
    }

    json& root_;
    std::vector<json*> open_;  // the containers being filled, innermost last
    std::string key_;          // the open object's current key
};

// Builds the DOM from nlohmann's SAX events (its public interface) and records, for every
// value, the offset in the text where it starts, keyed by its JSON pointer.
class PositionRecorder : public nlohmann::json_sax<json> {
public:
    PositionRecorder(json& root, const std::string& text, const size_t* consumed)
        : dom_(root), text_(text), consumed_(consumed) {}

    std::map<std::string, size_t> offsets;  // JSON pointer -> offset of the value's first char
    std::string duplicate_key_pointer;      // first key that appeared twice in one object
    std::string duplicate_key;              // that key, unescaped
    size_t error_offset = 0;                // where the syntax error is
    std::string error_message;              // nlohmann's explanation

    bool null() override { return value_done(dom_.null()); }
    bool boolean(bool v) override { return value_done(dom_.boolean(v)); }
    bool number_integer(number_integer_t v) override { return value_done(dom_.number_integer(v)); }
    bool number_unsigned(number_unsigned_t v) override {
        return value_done(dom_.number_unsigned(v));
    }
    bool number_float(number_float_t v, const string_t& s) override {
        return value_done(dom_.number_float(v, s));
    }
    bool string(string_t& v) override { return value_done(dom_.string(v)); }
    bool binary(binary_t& v) override { return value_done(dom_.binary(v)); }

    bool start_object(std::size_t n) override {
        record_start('{');
        frames_.push_back({true, 0, "", {}});
        return dom_.start_object(n);
    }
    bool key(string_t& k) override {
        Frame& f = frames_.back();
        f.key = k;
        if (!f.keys.insert(k).second && duplicate_key_pointer.empty()) {
            duplicate_key_pointer = child_pointer();
            duplicate_key = k;
        }
        offsets[child_pointer() + "#key"] = token_start('"');
        return dom_.key(k);
    }
    bool end_object() override {
        frames_.pop_back();
        return container_done(dom_.end_object());
    }
    bool start_array(std::size_t n) override {
        record_start('[');
        frames_.push_back({false, 0, "", {}});
        return dom_.start_array(n);
    }
    bool end_array() override {
        frames_.pop_back();
        return container_done(dom_.end_array());
    }
    bool parse_error(std::size_t position, const std::string&, const json::exception& ex) override {
        error_offset = position == 0 ? 0 : position - 1;
        error_message = ex.what();
        // nlohmann points at the last character it read. When a whole token came where it
        // is not allowed ("unexpected string literal"), point at the token's first character;
        // a malformed token ("invalid literal") stays at the character that broke it.
        if (error_message.find("unexpected") != std::string::npos && error_offset < text_.size()) {
            size_t i = error_offset;
            auto in_word = [&](size_t k) {
                return std::isalnum(static_cast<unsigned char>(text_[k])) ||
                       std::strchr("+-.", text_[k]) != nullptr;
            };
            if (text_[i] == '"') {
                while (i > 0 && !(text_[i - 1] == '"' && (i < 2 || text_[i - 2] != '\\'))) --i;
                if (i > 0) --i;
            } else if (in_word(i)) {
                while (i > 0 && in_word(i - 1)) --i;
            }
            error_offset = i;
        }
        return false;
    }

private:
    struct Frame {
        bool is_object;
        size_t index;  // next array index
        std::string key;  // current object key
        std::set<std::string> keys;  // keys seen, to catch duplicates
    };

    std::string pointer() const {
        std::string p;
        for (const std::string& token : path_) p += "/" + token;
        return p;
    }
    std::string child_pointer() const {
        const Frame& f = frames_.back();
        return pointer() + "/" + (f.is_object ? pointer_token(f.key) : std::to_string(f.index));
    }
    // Offset of the token the parser has just finished: scan back from what it has read to
    // the token's first character (the opening quote for strings).
    size_t token_start(char opening_quote_or_zero) const {
        size_t end = std::min(*consumed_, text_.size());
        if (opening_quote_or_zero == '"') {
            size_t i = end;
            while (i > 0 && text_[i - 1] != '"') --i;  // closing quote
            if (i > 0) --i;
            while (i > 0) {
                --i;
                if (text_[i] == '"' && (i == 0 || text_[i - 1] != '\\')) return i;
            }
            return 0;
        }
        size_t i = end;
        while (i > 0 && std::strchr(",]}: \t\r\n", text_[i - 1]) != nullptr) --i;
        while (i > 0 && std::strchr(",[{: \t\r\n", text_[i - 1]) == nullptr) --i;
        return i;
    }
    void record_start(char bracket) {
        size_t i = std::min(*consumed_, text_.size());
        while (i > 0 && text_[i - 1] != bracket) --i;
        offsets[frames_.empty() ? "" : child_pointer()] = i == 0 ? 0 : i - 1;
        if (!frames_.empty()) path_.push_back(current_token());
    }
    std::string current_token() const {
        const Frame& f = frames_.back();
        return f.is_object ? pointer_token(f.key) : std::to_string(f.index);
    }
    bool value_done(bool ok) {
        if (!frames_.empty()) {
            offsets[child_pointer()] = token_start(text_.empty() ? 0 : peek_is_string());
            if (!frames_.back().is_object) ++frames_.back().index;
        }
        return ok;
    }
    char peek_is_string() const {
        size_t i = std::min(*consumed_, text_.size());
        while (i > 0 && std::strchr(",]}: \t\r\n", text_[i - 1]) != nullptr) --i;
        return (i > 0 && text_[i - 1] == '"') ? '"' : 0;
    }
    bool container_done(bool ok) {
        if (!path_.empty()) path_.pop_back();
        if (!frames_.empty() && !frames_.back().is_object) ++frames_.back().index;
        return ok;
    }

    DomBuilder dom_;
    const std::string& text_;
    const size_t* consumed_;
    std::vector<Frame> frames_;
    std::vector<std::string> path_;  // pointer tokens of the open containers (not the root)
};

// The offset of the first bracket that opens a container deeper than kMaxJsonDepth, or npos.
// Read before parsing, in one pass: the recorder keeps every value's JSON pointer, whose
// length grows with the depth, so time and memory grew as the depth squared (DESIGN.md,
// section 5). Brackets inside strings do not count.
size_t too_deep(const std::string& text) {
    size_t depth = 0;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '"') {
            for (++i; i < text.size() && text[i] != '"'; ++i)
                if (text[i] == '\\') ++i;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) return i;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return std::string::npos;
}

}  // namespace

std::string pointer_token(const std::string& key) {
    std::string out;
    for (char c : key) out += c == '~' ? "~0" : (c == '/' ? "~1" : std::string(1, c));
    return out;
}

JsonWithPositions parse_json_with_positions(const std::string& text, const std::string& name) {
    if (const size_t at = too_deep(text); at != std::string::npos)
        throw InputError(name + ":" + line_column(text, at) + ": nesting deeper than " +
                         std::to_string(kMaxJsonDepth) +
                         " levels of brackets (a scene file needs 5 at most)");
    JsonWithPositions parsed;
    size_t consumed = 0;
    PositionRecorder recorder(parsed.root, text, &consumed);
    CountingIterator first{text.data(), text.data(), &consumed};
    CountingIterator last{text.data() + text.size(), text.data(), &consumed};
    if (!json::sax_parse(first, last, &recorder)) {
        // nlohmann's message reads "[json.exception.parse_error.101] parse error at line L,
        // column C: syntax error while parsing ..."; keep the part after the position.
        std::string why = recorder.error_message;
        const size_t colon = why.find(": ");
        if (colon != std::string::npos) why = why.substr(colon + 2);
        throw InputError(name + ":" + line_column(text, recorder.error_offset) +
                         ": invalid JSON: " + why);
    }
    parsed.offsets = std::move(recorder.offsets);
    parsed.duplicate_key_pointer = recorder.duplicate_key_pointer;
    parsed.duplicate_key = recorder.duplicate_key;
    return parsed;
}

std::string line_column(const std::string& text, size_t offset) {
    size_t line = 1, column = 1;
    for (size_t i = 0; i < offset && i < text.size(); ++i) {
        if (text[i] == '\n') {
            ++line;
            column = 1;
        } else {
            ++column;
        }
    }
    return "line " + std::to_string(line) + ", column " + std::to_string(column);
}
