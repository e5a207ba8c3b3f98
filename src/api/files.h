// Reading the files a user or a scene names. Only regular files are read (never a device, a
// FIFO or a directory, so nothing blocks or grows without end), each kind of file has a size
// limit checked before reading, and every path a scene file names must resolve, symbolic
// links included, to a regular file inside the scene's own folder (docs/scene-format.md,
// "Limits and paths").
#pragma once

#include <cstdint>
#include <string>

namespace mcp {

/// Size limits per kind of file, checked before reading.
constexpr uint64_t kMaxSceneFileBytes = 64ull << 20;     ///< scene JSON
constexpr uint64_t kMaxReferenceFileBytes = 64ull << 20; ///< Radiance .hdr references
constexpr uint64_t kMaxCacheFileBytes = 256ull << 20;    ///< cached reference images

/// Reads `path` whole if it is a regular file of at most `limit` bytes. On failure `error`
/// says why ("cannot open '...': No such file or directory", "'...' is a directory, not a
/// file", "'...' has N bytes, more than the limit of L"); it never quotes the file's content.
bool read_regular_file(const std::string& path, uint64_t limit, std::string* out,
                       std::string* error);

/// Is `path` an existing directory? An existing regular file (symbolic links followed)?
bool is_directory(const std::string& path);
bool is_regular_file(const std::string& path);

/// The real path of a folder (symbolic links resolved), or "" when it does not exist.
std::string real_folder(const std::string& folder);

/// Resolves `name`, a path a scene file gives, against `root` (the scene's folder): it must
/// be relative, and resolve, symbolic links included, to a regular file inside `root`. On
/// success `resolved` is that file's real path; on failure `error` says why, without the
/// field name (the caller prefixes it).
bool resolve_inside(const std::string& root, const std::string& name, std::string* resolved,
                    std::string* error);

/// Is `path` (any path, e.g. one tinygltf joined) a regular file inside `root` once every
/// symbolic link is resolved? `error` says why not.
bool file_is_inside(const std::string& root, const std::string& path, std::string* error);

} // namespace mcp
