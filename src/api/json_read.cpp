#include "api/json_read.h"

#include <cmath>

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
