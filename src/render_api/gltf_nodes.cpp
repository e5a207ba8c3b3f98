// The glTF loader's walk of the default scene's node tree: each node's local transform
// checked and composed into world transforms, its mesh instances recorded, and the first
// perspective camera turned into the Scene's camera [glTF2 3.5, 3.10].
#include "render_api/gltf_internal.h"

#include <cmath>

#include <glm/geometric.hpp>

namespace mcp {
namespace gltf {

namespace {

constexpr double kPiValue = 3.14159265358979323846;

bool finite_all(const std::vector<double>& v) {
    for (double x : v)
        if (!std::isfinite(x)) return false;
    return true;
}

/// The node's local transform: its matrix, or T R S [glTF2 3.5.3].
bool local_transform(const tinygltf::Node& n, int index, Mat4* out, Log& log) {
    const std::string where = "nodes[" + num(index) + "]";
    if (!n.matrix.empty()) {
        if (n.matrix.size() != 16 || !finite_all(n.matrix))
            return log.fail(where + ": matrix must be 16 finite numbers");
        Mat4 m(1.0);
        for (int k = 0; k < 16; ++k) m[k / 4][k % 4] = n.matrix[size_t(k)]; // column-major
        if (m[0][3] != 0.0 || m[1][3] != 0.0 || m[2][3] != 0.0 || m[3][3] != 1.0)
            return log.fail(where + ": matrix is not affine (its last row must be 0 0 0 1)");
        *out = m;
        return true;
    }
    if ((!n.translation.empty() && n.translation.size() != 3) || !finite_all(n.translation))
        return log.fail(where + ": translation must be 3 finite numbers");
    if ((!n.scale.empty() && n.scale.size() != 3) || !finite_all(n.scale))
        return log.fail(where + ": scale must be 3 finite numbers");
    if ((!n.rotation.empty() && n.rotation.size() != 4) || !finite_all(n.rotation))
        return log.fail(where + ": rotation must be 4 finite numbers (a quaternion x, y, z, w)");
    Vec3 t = n.translation.empty() ? Vec3(0.0)
                                   : Vec3(n.translation[0], n.translation[1], n.translation[2]);
    Vec3 s = n.scale.empty() ? Vec3(1.0) : Vec3(n.scale[0], n.scale[1], n.scale[2]);
    double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
    if (!n.rotation.empty()) {
        x = n.rotation[0], y = n.rotation[1], z = n.rotation[2], w = n.rotation[3];
        double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (!(len > 0.0) || !std::isfinite(len))
            return log.fail(where + ": rotation is not a unit quaternion");
        x /= len, y /= len, z /= len, w /= len;
    }
    // Rotation matrix of the unit quaternion (x, y, z, w), r[row][col].
    const double r[3][3] = {
        {1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y - w * z), 2.0 * (x * z + w * y)},
        {2.0 * (x * y + w * z), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z - w * x)},
        {2.0 * (x * z - w * y), 2.0 * (y * z + w * x), 1.0 - 2.0 * (x * x + y * y)}};
    Mat4 m(1.0);
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) m[col][row] = r[row][col] * s[col];
    m[3] = glm::dvec4(t, 1.0);
    *out = m;
    return true;
}

} // namespace

/// Walks the scene's node tree depth first (children in order), composing transforms;
/// records mesh instances and the first camera.
bool Converter::collect_instances() {
    const auto& nodes = m_.nodes;
    std::vector<int> roots;
    std::string roots_ref;
    if (!m_.scenes.empty()) {
        int s = m_.defaultScene == -1 ? 0 : m_.defaultScene;
        if (s < 0 || size_t(s) >= m_.scenes.size())
            return log_.fail("scene: scene " + num(s) + " does not exist (the file has " +
                             num(uint64_t(m_.scenes.size())) + " scenes)");
        scene_index_ = s;
        roots = m_.scenes[size_t(s)].nodes;
        roots_ref = "scenes[" + num(s) + "].nodes";
    } else {
        // No scenes: every node that is nobody's child is a root.
        std::vector<char> is_child(nodes.size(), 0);
        for (size_t i = 0; i < nodes.size(); ++i)
            for (size_t k = 0; k < nodes[i].children.size(); ++k) {
                int c = nodes[i].children[k];
                if (c < 0 || size_t(c) >= nodes.size())
                    return log_.fail("nodes[" + num(uint64_t(i)) + "].children[" +
                                     num(uint64_t(k)) + "]: node " + num(c) + " does not exist");
                is_child[size_t(c)] = 1;
            }
        for (size_t i = 0; i < nodes.size(); ++i)
            if (!is_child[i]) roots.push_back(int(i));
        roots_ref = "root nodes";
    }

    struct Item {
        int node, parent; ///< parent -1: a root
        size_t slot;      ///< position in the parent's children (or in the roots)
        Mat4 parent_world;
    };
    std::vector<Item> stack;
    for (size_t k = roots.size(); k-- > 0;) stack.push_back({roots[k], -1, k, Mat4(1.0)});
    std::vector<char> visited(nodes.size(), 0);
    int camera_node = -1;
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        if (it.node < 0 || size_t(it.node) >= nodes.size()) {
            std::string ref = it.parent < 0 ? roots_ref + "[" + num(uint64_t(it.slot)) + "]"
                                            : "nodes[" + num(it.parent) + "].children[" +
                                                  num(uint64_t(it.slot)) + "]";
            return log_.fail(ref + ": node " + num(it.node) + " does not exist");
        }
        const std::string where = "nodes[" + num(it.node) + "]";
        if (visited[size_t(it.node)])
            return log_.fail(where + " is reached twice from " + roots_ref +
                             " (the node hierarchy must be a tree)");
        visited[size_t(it.node)] = 1;
        const tinygltf::Node& n = nodes[size_t(it.node)];
        Mat4 local;
        if (!local_transform(n, it.node, &local, log_)) return false;
        Mat4 world = it.parent_world * local;
        if (n.skin != -1) log_.warn(where + ": skin is ignored (the mesh is used unskinned)");
        if (n.extensions.count("KHR_lights_punctual"))
            log_.warn(where + ": KHR_lights_punctual light is ignored");
        if (n.camera != -1) {
            if (n.camera < 0 || size_t(n.camera) >= m_.cameras.size())
                return log_.fail(where + ": camera " + num(n.camera) + " does not exist");
            if (camera_node < 0) {
                if (!set_camera(n.camera, it.node, world)) return false;
                camera_node = it.node;
            } else {
                log_.warn(where + ": cameras[" + num(n.camera) +
                          "] is ignored; the first camera in the scene, on nodes[" +
                          num(camera_node) + "], is used");
            }
        }
        if (n.mesh != -1) {
            if (n.mesh < 0 || size_t(n.mesh) >= m_.meshes.size())
                return log_.fail(where + ": mesh " + num(n.mesh) + " does not exist");
            instances_.push_back({world, it.node, n.mesh});
        }
        for (size_t k = n.children.size(); k-- > 0;)
            stack.push_back({n.children[k], it.node, k, world});
    }
    return true;
}

/// Camera of glTF 3.10: looks along the node's -z with y up; the frame is orthonormalised
/// (scale and shear of the node are dropped).
bool Converter::set_camera(int index, int node, const Mat4& world) {
    const tinygltf::Camera& c = m_.cameras[size_t(index)];
    const std::string where = "cameras[" + num(index) + "] (used by nodes[" + num(node) + "])";
    if (c.type == "orthographic")
        return log_.fail(where + ": orthographic cameras are not supported; only perspective");
    if (c.type != "perspective")
        return log_.fail(where + ": type '" + quoted(c.type) + "' is not perspective");
    double yfov = c.perspective.yfov;
    if (!(yfov > 0.0 && yfov < kPiValue))
        return log_.fail(where + ": yfov " + num(yfov) + " is not in (0, pi)");
    Vec3 back(world[2]), up(world[1]);
    double lb = glm::length(back), lu = glm::length(up);
    Vec3 forward = -back / lb;
    Vec3 right = glm::cross(forward, up / lu);
    double lr = glm::length(right);
    if (!(lb > 0.0 && lu > 0.0 && lr > 1e-9) || !std::isfinite(lb + lu + lr))
        return log_.fail("nodes[" + num(node) + "]: the camera's transform is singular");
    right /= lr;
    const Vec3 position(world[3]);
    const double largest =
        std::fmax(std::fabs(position.x), std::fmax(std::fabs(position.y), std::fabs(position.z)));
    if (!(largest <= kGltfMaxCoordinate))
        return log_.fail("nodes[" + num(node) + "]: the camera is at a coordinate of " +
                         num(largest) +
                         ", beyond 1e9, the largest rendered right in double "
                         "precision (hit points carry about 2e-15 of the coordinates in error): "
                         "rescale the scene");
    Camera& cam = r_.scene.camera;
    cam.position = position;
    cam.forward = forward;
    cam.right = right;
    cam.up = glm::cross(right, forward);
    cam.yfov = yfov;
    const double aspect = c.perspective.aspectRatio;
    if (aspect != 0.0 && !(aspect > 0.0 && std::isfinite(aspect)))
        return log_.fail(where + ": aspectRatio " + num(aspect) + " is not positive");
    cam.aspect_ratio = aspect;
    r_.has_camera = true;
    return true;
}

} // namespace gltf
} // namespace mcp
