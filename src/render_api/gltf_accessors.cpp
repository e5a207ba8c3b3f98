// glTF accessors for the loader: each checked against its bufferView and buffer (type,
// component type, count, offsets, stride) before a byte is read, then read as doubles or as
// vertex indices [glTF2 3.6].
#include "render_api/gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace mcp {
namespace gltf {

namespace {

int component_size(int type) {
    switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0; // INT (5124) and DOUBLE (5130) are not glTF 2.0 accessor types
    }
}

std::string component_name(int type) {
    const char* name = "invalid";
    switch (type) {
    case kByte: name = "BYTE"; break;
    case kUnsignedByte: name = "UNSIGNED_BYTE"; break;
    case kShort: name = "SHORT"; break;
    case kUnsignedShort: name = "UNSIGNED_SHORT"; break;
    case kUnsignedInt: name = "UNSIGNED_INT"; break;
    case kFloat: name = "FLOAT"; break;
    default: break;
    }
    return std::string(name) + " (" + num(type) + ")";
}

const char* type_name(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "invalid";
    }
}

int type_components(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR: return 1;
    case TINYGLTF_TYPE_VEC2: return 2;
    case TINYGLTF_TYPE_VEC3: return 3;
    case TINYGLTF_TYPE_VEC4: return 4;
    case TINYGLTF_TYPE_MAT2: return 4;
    case TINYGLTF_TYPE_MAT3: return 9;
    case TINYGLTF_TYPE_MAT4: return 16;
    default: return 0;
    }
}

/// One component of type `type` at p, as a double (normalized integers mapped to [0, 1] or
/// [-1, 1] [glTF2]).
double read_component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
    case kFloat: {
        float f;
        std::memcpy(&f, p, 4);
        return f;
    }
    case kUnsignedByte: return normalized ? p[0] / 255.0 : p[0];
    case kUnsignedShort: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case kByte: {
        int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::fmax(v / 127.0, -1.0) : v;
    }
    case kShort: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::fmax(v / 32767.0, -1.0) : v;
    }
    case kUnsignedInt: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    default: return 0.0;
    }
}

} // namespace

bool view_accessor(const tinygltf::Model& m, int index, const std::string& role, int type,
                   const std::vector<int>& component_types, AccessorView* out, Log& log) {
    if (index < 0 || size_t(index) >= m.accessors.size())
        return log.fail(role + ": accessor " + num(index) + " does not exist (the file has " +
                        num(uint64_t(m.accessors.size())) + " accessors)");
    const tinygltf::Accessor& a = m.accessors[size_t(index)];
    out->name = "accessors[" + num(index) + "] (" + role + ")";
    const std::string& name = out->name;
    if (a.sparse.isSparse) return log.fail(name + ": sparse accessors are not supported");
    if (a.type != type)
        return log.fail(name + ": type " + type_name(a.type) + " is not the expected " +
                        type_name(type));
    if (std::find(component_types.begin(), component_types.end(), a.componentType) ==
        component_types.end()) {
        std::string allowed;
        for (size_t k = 0; k < component_types.size(); ++k)
            allowed += (k ? " or " : "") + component_name(component_types[k]);
        return log.fail(name + ": component type " + component_name(a.componentType) +
                        " is not allowed here; expected " + allowed);
    }
    uint64_t count = a.count;
    if (count > kMaxElements)
        return log.fail(name + ": count " + num(count) + " exceeds the limit of " +
                        num(kMaxElements));
    out->count = count;
    out->component_type = a.componentType;
    out->components = type_components(a.type);
    out->normalized = a.normalized;
    uint64_t element_size = uint64_t(component_size(a.componentType)) * out->components;
    out->stride = element_size;
    if (a.bufferView == -1) {
        out->data = nullptr; // glTF: an accessor without a bufferView is all zeros
        return true;
    }
    if (a.bufferView < 0 || size_t(a.bufferView) >= m.bufferViews.size())
        return log.fail(name + ": bufferView " + num(a.bufferView) + " does not exist");
    const tinygltf::BufferView& view = m.bufferViews[size_t(a.bufferView)];
    std::string view_name = "bufferViews[" + num(a.bufferView) + "]";
    if (view.buffer < 0 || size_t(view.buffer) >= m.buffers.size())
        return log.fail(view_name + ": buffer " + num(view.buffer) + " does not exist");
    const std::vector<unsigned char>& buffer = m.buffers[size_t(view.buffer)].data;
    uint64_t buffer_size = buffer.size();
    if (view.byteOffset > buffer_size || view.byteLength > buffer_size - view.byteOffset)
        return log.fail(view_name + ": byteOffset " + num(uint64_t(view.byteOffset)) +
                        " + byteLength " + num(uint64_t(view.byteLength)) + " exceeds the length " +
                        num(buffer_size) + " of buffers[" + num(view.buffer) + "]");
    if (view.byteStride != 0) {
        if (view.byteStride < element_size ||
            view.byteStride % uint64_t(component_size(a.componentType)) != 0)
            return log.fail(view_name + ": byteStride " + num(uint64_t(view.byteStride)) +
                            " does not fit the " + num(element_size) + "-byte elements of " + name);
        out->stride = view.byteStride;
    }
    if (a.byteOffset > view.byteLength)
        return log.fail(name + ": byteOffset " + num(uint64_t(a.byteOffset)) +
                        " lies past the end of " + view_name + " (" +
                        num(uint64_t(view.byteLength)) + " bytes)");
    if (count > 0) {
        // count <= 3e7 and stride <= 2^32: no overflow in 64 bits.
        uint64_t need = (count - 1) * out->stride + element_size;
        if (need > view.byteLength - a.byteOffset)
            return log.fail(name + ": " + num(count) + " elements (stride " + num(out->stride) +
                            ") from byteOffset " + num(uint64_t(a.byteOffset)) + " need " +
                            num(need + a.byteOffset) + " bytes, but " + view_name + " has " +
                            num(uint64_t(view.byteLength)));
    }
    out->data = buffer.data() + view.byteOffset + a.byteOffset;
    return true;
}

bool read_doubles(const AccessorView& v, std::vector<double>* out, Log& log) {
    const int n = v.components;
    const uint64_t size = uint64_t(component_size(v.component_type));
    out->assign(size_t(v.count * n), 0.0);
    if (!v.data) return true;
    for (uint64_t i = 0; i < v.count; ++i) {
        const unsigned char* e = v.element(i);
        for (int c = 0; c < n; ++c) {
            double x = read_component(e + c * size, v.component_type, v.normalized);
            if (!std::isfinite(x))
                return log.fail(v.name + ": element " + num(i) + " is not finite (NaN or Inf)");
            (*out)[size_t(i * n + c)] = x;
        }
    }
    return true;
}

bool read_indices(const AccessorView& v, uint64_t vertex_count, std::vector<uint32_t>* out,
                  Log& log) {
    out->assign(size_t(v.count), 0u);
    if (!v.data) return true;
    for (uint64_t i = 0; i < v.count; ++i) {
        double x = read_component(v.element(i), v.component_type, false);
        if (x >= double(vertex_count))
            return log.fail(v.name + ": index " + num(uint64_t(x)) + " at element " + num(i) +
                            " is out of range (the primitive has " + num(vertex_count) +
                            " vertices)");
        (*out)[size_t(i)] = uint32_t(x);
    }
    return true;
}

} // namespace gltf
} // namespace mcp
