#include "api/files.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>

namespace mcp {

namespace {

/// A path for messages: at most 200 bytes of it.
std::string shown(const std::string& path) {
    return path.size() > 200 ? path.substr(0, 200) + "..." : path;
}

std::string real_path(const std::string& path) {
    char buf[PATH_MAX];
    if (!::realpath(path.c_str(), buf)) return "";
    return buf;
}

bool is_within(const std::string& root_real, const std::string& path_real) {
    if (root_real == "/") return !path_real.empty() && path_real[0] == '/';
    return path_real.size() > root_real.size() &&
           path_real.compare(0, root_real.size(), root_real) == 0 &&
           path_real[root_real.size()] == '/';
}

} // namespace

bool read_regular_file(const std::string& path, uint64_t limit, std::string* out,
                       std::string* error) {
    // Refused before opening (opening a FIFO waits for a writer, and O_NONBLOCK does not
    // reach Node's file system under Emscripten), then checked again on the open file.
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) {
        *error = "cannot open '" + shown(path) + "': " + std::strerror(errno);
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        *error = "'" + shown(path) + "' is " +
                 (S_ISDIR(st.st_mode) ? "a directory"
                                      : "not a regular file (a device, FIFO or socket)") +
                 ", not a file to read";
        return false;
    }
    int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) {
        *error = "cannot open '" + shown(path) + "': " + std::strerror(errno);
        return false;
    }
    if (::fstat(fd, &st) != 0) {
        *error = "cannot read '" + shown(path) + "': " + std::strerror(errno);
        ::close(fd);
        return false;
    }
    if (S_ISDIR(st.st_mode) || !S_ISREG(st.st_mode)) {
        *error = "'" + shown(path) + "' is " +
                 (S_ISDIR(st.st_mode) ? "a directory"
                                      : "not a regular file (a device, FIFO or socket)") +
                 ", not a file to read";
        ::close(fd);
        return false;
    }
    const auto too_large = [&](uint64_t bytes) {
        *error =
            "'" + shown(path) + "' has " +
            (bytes > limit + 1 ? std::to_string(bytes) : "more than " + std::to_string(limit)) +
            " bytes, more than the limit of " + std::to_string(limit);
        ::close(fd);
        return false;
    };
    if (st.st_size < 0 || static_cast<uint64_t>(st.st_size) > limit)
        return too_large(static_cast<uint64_t>(st.st_size));
    // Read at most limit + 1 bytes: a file that grows while it is read is still bounded.
    out->clear();
    out->reserve(static_cast<size_t>(st.st_size));
    char buf[1 << 16];
    for (;;) {
        ssize_t got = ::read(fd, buf, sizeof buf);
        if (got < 0 && errno == EINTR) continue;
        if (got < 0) {
            *error = "cannot read '" + shown(path) + "': " + std::strerror(errno);
            ::close(fd);
            return false;
        }
        if (got == 0) break;
        if (out->size() + static_cast<size_t>(got) > limit) return too_large(limit + 1);
        out->append(buf, static_cast<size_t>(got));
    }
    ::close(fd);
    return true;
}

bool is_directory(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0 && S_ISDIR(st.st_mode);
}

bool is_regular_file(const std::string& path) {
    struct stat st;
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

std::string real_folder(const std::string& folder) {
    std::string r = real_path(folder.empty() ? "." : folder);
    return !r.empty() && is_directory(r) ? r : "";
}

bool file_is_inside(const std::string& root, const std::string& path, std::string* error) {
    const std::string root_real = real_folder(root);
    if (root_real.empty()) {
        *error = "the scene's folder '" + shown(root) + "' does not exist";
        return false;
    }
    const std::string path_real = real_path(path);
    if (path_real.empty()) {
        *error = "does not exist";
        return false;
    }
    if (path_real == root_real) {
        *error = "is the scene's folder itself, not a file";
        return false;
    }
    if (!is_within(root_real, path_real)) {
        *error = "lies outside the scene's folder (a scene may only name files inside its own "
                 "folder)";
        return false;
    }
    struct stat st;
    if (::stat(path_real.c_str(), &st) != 0) {
        *error = std::string("cannot be read: ") + std::strerror(errno);
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        *error = S_ISDIR(st.st_mode) ? "is a directory, not a file"
                                     : "is not a regular file (a device, FIFO or socket)";
        return false;
    }
    return true;
}

bool resolve_inside(const std::string& root, const std::string& name, std::string* resolved,
                    std::string* error) {
    if (name.empty()) {
        *error = "is empty";
        return false;
    }
    if (name.size() > 4096 || name.find('\0') != std::string::npos) {
        *error = "is not a usable file name";
        return false;
    }
    if (name[0] == '/') {
        *error = "'" + shown(name) +
                 "' is an absolute path; a scene names files relative to its own folder";
        return false;
    }
    const std::string joined = (root.empty() ? std::string(".") : root) + "/" + name;
    std::string why;
    if (!file_is_inside(root.empty() ? "." : root, joined, &why)) {
        *error = "'" + shown(name) + "' " + why;
        return false;
    }
    *resolved = real_path(joined);
    return true;
}

} // namespace mcp
