#include "api/json_read.h"

#include <cmath>
#include <cstring>

namespace mcp {

std::string type_of(const Json& j) {
    if (j.is_null()) return "null";
    if (j.is_boolean()) return "a boolean";
    if (j.is_number()) return "a number";
    if (j.is_string()) return "a string";
    if (j.is_array()) return "an array";
    return "an object";
}

std::string join(const std::vector<std::string>& items) {
    std::string s;
    for (size_t i = 0; i < items.size(); ++i) s += (i ? ", " : "") + items[i];
    return s;
}

// Rejects keys outside `known`, so that a typo ("n_mx") is an error, not a silent default.
bool check_keys(Ctx& c, const Json& obj, const std::string& path,
                const std::vector<std::string>& known) {
    if (!obj.is_object()) return c.fail(path, "expected an object, got " + type_of(obj));
    for (auto it = obj.begin(); it != obj.end(); ++it) {
        bool ok = false;
        for (const std::string& k : known) ok = ok || k == it.key();
        if (!ok)
            return c.fail(path, "unknown field '" + it.key() + "' (known: " + join(known) + ")");
    }
    return true;
}

const Json* find(const Json& obj, const char* key) {
    if (!obj.is_object()) return nullptr;
    auto it = obj.find(key);
    return it == obj.end() ? nullptr : &*it;
}

std::string sub(const std::string& path, const char* key) {
    return path + "." + key;
}

// Optional number: leaves *out unchanged when absent.
bool get_number(Ctx& c, const Json& obj, const char* key, const std::string& path, double* out) {
    const Json* v = find(obj, key);
    if (!v) return true;
    if (!v->is_number()) return c.fail(sub(path, key), "expected a number, got " + type_of(*v));
    double x = v->get<double>();
    if (!std::isfinite(x)) return c.fail(sub(path, key), "must be finite");
    *out = x;
    return true;
}

bool get_count(Ctx& c, const Json& obj, const char* key, const std::string& path, uint64_t* out) {
    const Json* v = find(obj, key);
    if (!v) return true;
    if (v->is_number_unsigned()) {
        *out = v->get<uint64_t>();
        return true;
    }
    if (v->is_number_integer() && v->get<int64_t>() >= 0) {
        *out = static_cast<uint64_t>(v->get<int64_t>());
        return true;
    }
    if (v->is_number_float()) {
        double x = v->get<double>();
        if (x >= 0.0 && x == std::floor(x) && x < 1.8e19) {
            *out = static_cast<uint64_t>(x);
            return true;
        }
    }
    return c.fail(sub(path, key), "expected a non-negative whole number, got " +
                                      (v->is_number() ? v->dump() : type_of(*v)));
}

bool get_string(Ctx& c, const Json& obj, const char* key, const std::string& path,
                std::string* out) {
    const Json* v = find(obj, key);
    if (!v) return true;
    if (!v->is_string()) return c.fail(sub(path, key), "expected a string, got " + type_of(*v));
    *out = v->get<std::string>();
    return true;
}

bool to_numbers(Ctx& c, const Json& v, const std::string& path, std::vector<double>* out) {
    out->clear();
    if (v.is_number()) {
        out->push_back(v.get<double>());
        return true;
    }
    if (!v.is_array()) return c.fail(path, "expected an array of numbers, got " + type_of(v));
    for (size_t i = 0; i < v.size(); ++i) {
        if (!v[i].is_number())
            return c.fail(path + "[" + std::to_string(i) + "]",
                          "expected a number, got " + type_of(v[i]));
        double x = v[i].get<double>();
        if (!std::isfinite(x))
            return c.fail(path + "[" + std::to_string(i) + "]", "must be finite");
        out->push_back(x);
    }
    return true;
}

bool get_numbers(Ctx& c, const Json& obj, const char* key, const std::string& path,
                 std::vector<double>* out) {
    const Json* v = find(obj, key);
    if (!v) return true;
    return to_numbers(c, *v, sub(path, key), out);
}

} // namespace mcp

namespace mcp {

namespace {

/// nlohmann's parse error text without the token it read ("; last read: '...'"): the text
/// may be a file that is not JSON at all, and its content is not ours to echo.
std::string parse_error_reason(const std::string& what) {
    std::string reason = what;
    size_t at = reason.find("parse error");
    if (at != std::string::npos) reason = reason.substr(at);
    if (reason.compare(0, 1, "[") == 0 && reason.find("] ") != std::string::npos)
        reason = reason.substr(reason.find("] ") + 2); // "[json.exception.out_of_range.406] ..."
    size_t last = reason.find("; last read: '");
    if (last != std::string::npos) {
        size_t expected = reason.rfind("; expected ");
        std::string tail = expected != std::string::npos && expected > last
                               ? reason.substr(expected)
                               : std::string();
        reason = reason.substr(0, last) + tail;
    }
    return reason;
}

/// SAX pass of check_json_text: tracks the JSON path, the depth and each open object's keys.
struct CheckingSax : nlohmann::json_sax<Json> {
    struct Frame {
        bool object = false;
        size_t index = 0;              ///< arrays: the next element's index
        std::string key;               ///< objects: the current key
        std::vector<std::string> keys; ///< objects: the keys seen so far
    };
    std::vector<Frame> stack;
    std::string message, root;

    std::string path() const {
        std::string p = root;
        for (const Frame& f : stack) {
            if (p.size() > 200) return p + "...";
            p += f.object ? "." + f.key : "[" + std::to_string(f.index) + "]";
        }
        return p;
    }
    bool value() {
        if (!stack.empty() && !stack.back().object) ++stack.back().index;
        return true;
    }
    bool open(bool object) {
        if (stack.size() >= static_cast<size_t>(kMaxJsonDepth)) {
            message = "objects and arrays are nested more than " + std::to_string(kMaxJsonDepth) +
                      " levels deep";
            return false;
        }
        stack.push_back(Frame{object, 0, {}, {}});
        return true;
    }
    bool close() {
        stack.pop_back();
        return value();
    }
    bool null() override { return value(); }
    bool boolean(bool) override { return value(); }
    bool number_integer(number_integer_t) override { return value(); }
    bool number_unsigned(number_unsigned_t) override { return value(); }
    bool number_float(number_float_t, const string_t&) override { return value(); }
    bool string(string_t&) override { return value(); }
    bool binary(binary_t&) override { return value(); }
    bool start_object(std::size_t) override { return open(true); }
    bool end_object() override { return close(); }
    bool start_array(std::size_t) override { return open(false); }
    bool end_array() override { return close(); }
    bool key(string_t& k) override {
        Frame& f = stack.back();
        for (const std::string& seen : f.keys)
            if (seen == k) {
                f.key = k;
                message = "the key \"" + k.substr(0, 40) + "\" appears twice in one object (at " +
                          path() + "); JSON objects need unique keys";
                return false;
            }
        f.keys.push_back(k);
        f.key = k;
        return true;
    }
    bool parse_error(std::size_t, const std::string&,
                     const nlohmann::detail::exception& ex) override {
        message = parse_error_reason(ex.what()) + " (in " + path() + ")";
        return false;
    }
};

} // namespace

std::string check_json_text(const char* text, size_t size, const char* root) {
    if (size > kMaxJsonBytes)
        return "the text has " + std::to_string(size) + " bytes, more than the limit of " +
               std::to_string(kMaxJsonBytes);
    CheckingSax sax;
    sax.root = root;
    const bool ok = Json::sax_parse(text, text + size, &sax, nlohmann::detail::input_format_t::json,
                                    /*strict=*/true);
    if (ok) return "";
    return sax.message.empty() ? "could not parse" : sax.message;
}

Made<Json> parse_json(const char* text, const char* what) {
    if (!text) return made_error<Json>(std::string(what) + ": no text (null pointer)");
    return parse_json(text, std::strlen(text), what);
}

Made<Json> parse_json(const char* text, size_t size, const char* what) {
    if (!text) return made_error<Json>(std::string(what) + ": no text (null pointer)");
    std::string problem = check_json_text(text, size, what);
    if (!problem.empty()) return made_error<Json>(std::string(what) + ": invalid JSON: " + problem);
    Json j = Json::parse(text, text + size, nullptr, /*allow_exceptions=*/false);
    if (j.is_discarded()) return made_error<Json>(std::string(what) + ": invalid JSON");
    return {j, {}};
}

std::string first_difference(const Json& a, const Json& b, const std::string& path) {
    if (a == b) return "";
    if (a.is_object() && b.is_object()) {
        for (auto it = a.begin(); it != a.end(); ++it) {
            const std::string p = sub(path, it.key().c_str());
            if (!b.contains(it.key())) return p;
            const std::string d = first_difference(it.value(), b[it.key()], p);
            if (!d.empty()) return d;
        }
        for (auto it = b.begin(); it != b.end(); ++it)
            if (!a.contains(it.key())) return sub(path, it.key().c_str());
    }
    if (a.is_array() && b.is_array() && a.size() == b.size())
        for (size_t i = 0; i < a.size(); ++i) {
            const std::string d =
                first_difference(a[i], b[i], path + "[" + std::to_string(i) + "]");
            if (!d.empty()) return d;
        }
    return path;
}

} // namespace mcp
