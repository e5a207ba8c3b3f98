// tinygltf's file and image callbacks for the glTF loader: a URI may only name a regular file
// inside the scene's folder (symbolic links resolved), reads are bounded by kGltfMaxBufferBytes
// in all, nothing is written, and images stay encoded until a material needs them.
#include "api/files.h"
#include "render_api/gltf_internal.h"

#include <sys/stat.h>

namespace mcp {
namespace gltf {

namespace {

bool fs_file_exists(const std::string& path, void* user) {
    const auto* ctx = static_cast<const LoadContext*>(user);
    // tinygltf also looks in "./": only when the base folder is the current one.
    if (path.compare(0, 2, "./") == 0 && !ctx->base_dir.empty() && ctx->base_dir != ".")
        return false;
    // Existence only (never opened here: opening a FIFO blocks); fs_read_whole_file decides.
    struct stat st;
    return ::stat(path.c_str(), &st) == 0;
}

std::string fs_expand_path(const std::string& path, void*) {
    return path; // no shell expansion of names taken from the file
}

bool fs_read_whole_file(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                        void* user) {
    auto* ctx = static_cast<LoadContext*>(user);
    // A URI may only name a regular file inside the scene's folder, symbolic links resolved.
    std::string why;
    if (!file_is_inside(ctx->root, path, &why)) {
        std::string uri = path;
        if (!ctx->base_dir.empty() &&
            path.compare(0, ctx->base_dir.size() + 1, ctx->base_dir + "/") == 0)
            uri = path.substr(ctx->base_dir.size() + 1);
        *err = "'" + quoted(uri, 200) + "' " + why;
        if (ctx->path_problem.empty()) ctx->path_problem = *err;
        return false;
    }
    uint64_t left =
        kGltfMaxBufferBytes > ctx->bytes_read ? kGltfMaxBufferBytes - ctx->bytes_read : 0;
    std::string bytes;
    if (!read_regular_file(path, left, &bytes, err)) return false;
    out->assign(bytes.begin(), bytes.end());
    ctx->bytes_read += out->size();
    return true;
}

bool fs_write_whole_file(std::string* err, const std::string&, const std::vector<unsigned char>&,
                         void*) {
    *err = "writing files is disabled";
    return false;
}

/// Image callback: keeps the encoded bytes (decoded later, and only for base colour textures
/// in use). tinygltf does not check an image's bufferView against its buffer, so do it here.
bool keep_image_bytes(tinygltf::Image* image, const int index, std::string*, std::string*, int, int,
                      const unsigned char* bytes, int size, void* user) {
    auto* ctx = static_cast<LoadContext*>(user);
    image->image.clear();
    if (image->bufferView >= 0) {
        const tinygltf::Model& m = *ctx->model;
        const auto& views = m.bufferViews;
        if (size_t(image->bufferView) >= views.size() ||
            size_t(views[size_t(image->bufferView)].buffer) >= m.buffers.size()) {
            ctx->image_problem[index] = "bufferView " + num(image->bufferView) + " is invalid";
            return true;
        }
        const tinygltf::BufferView& view = views[size_t(image->bufferView)];
        uint64_t length = m.buffers[size_t(view.buffer)].data.size();
        if (view.byteOffset > length || view.byteLength > length - view.byteOffset) {
            ctx->image_problem[index] = "bufferViews[" + num(image->bufferView) +
                                        "] lies outside buffers[" + num(view.buffer) + "]";
            return true;
        }
    }
    if (!bytes || size <= 0) {
        ctx->image_problem[index] = "no image data";
        return true;
    }
    image->image.assign(bytes, bytes + size);
    image->as_is = true;
    return true;
}

} // namespace

void set_callbacks(tinygltf::TinyGLTF& loader, LoadContext& ctx) {
    tinygltf::FsCallbacks fs;
    fs.FileExists = &fs_file_exists;
    fs.ExpandFilePath = &fs_expand_path;
    fs.ReadWholeFile = &fs_read_whole_file;
    fs.WriteWholeFile = &fs_write_whole_file;
    fs.user_data = &ctx;
    loader.SetFsCallbacks(fs);
    loader.SetImageLoader(&keep_image_bytes, &ctx);
}

} // namespace gltf
} // namespace mcp
