// Warps as objects: a map from the unit cube onto a domain and the density it claims, both
// run on whole blocks of points. The named warps wrap the core's sampling routines (one
// implementation each: core/warps.h, core/distributions.h, core/microfacet.h,
// core/spherical_triangle.h); expression warps are typed by a user. Either can be put to a
// chi-square test (estimators/warp_test.h) or serve as an importance proposal
// (ProposalKind::Warp, estimators/problem.h).
#pragma once

#include <atomic>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "core/made.h"
#include "core/points.h"
#include "core/warps.h"
#include "estimators/problem.h"

namespace mcp {

/// Most coordinates of a warp's unit-cube points and of its domain's points.
constexpr int kMaxWarpDim = 3;

/// A warp under test, or an importance proposal built from one. `map` takes a block of
/// unit-cube points u (sample_dim coordinates, u.n points) to domain points x (the domain's
/// point_dim coordinates; x has room for u.n points and arrives with x.n = u.n); `pdf` writes
/// the density the warp claims at the x.n points of x, per unit of the domain's measure (area,
/// volume or solid angle), 0 where it cannot land. Both run once per block, never once per
/// sample, and may be called from several threads at once.
struct Warp {
    std::string name; ///< "concentric_disk", or "expression"
    int sample_dim = 2;
    std::function<void(const PointBlock& u, PointBlock& x)> map;
    std::function<void(const PointBlock& x, double* pdf)> pdf;
    /// Typed warps only (null for the named ones): the first point the warp put outside its
    /// domain while it served as a proposal (warp_block checks each block).
    std::shared_ptr<struct WarpEscape> escape;
};

/// The first point a typed warp put outside its domain in a study, as warp-test reports one:
/// a study with such a point fails with this sentence instead of reporting a wrong number.
struct WarpEscape {
    /// Keeps point i of the block (u its unit-cube point, x where it landed) if it is the first.
    void record(const PointBlock& u, const PointBlock& x, size_t i);
    bool seen() const { return seen_.load(std::memory_order_acquire); }
    /// "u = (0.75) gave x = (1.5), outside [0, 1]" (empty when none was seen).
    std::string describe(const Domain& domain) const;

  private:
    std::atomic<bool> seen_{false};
    mutable std::mutex mutex_; // guards u_ and x_ (written once)
    std::vector<double> u_, x_;
};

/// A named warp and the domain it maps onto (set by its parameters).
struct NamedWarp {
    Warp warp;
    Domain domain;
};

/// The parameters of the named warps; each warp reads its own and ignores the rest. The
/// defaults give every warp a valid instance.
struct NamedWarpParams {
    /// uniform: the box (1 to 3 axes); tabulated_1d: [lo[0], hi[0]]; tabulated_2d: the
    /// rectangle. Empty: the unit square (uniform, tabulated_2d) or [0, 1] (tabulated_1d).
    std::vector<double> lo, hi;
    Vec2 center{0.0, 0.0}; ///< polar_disk, concentric_disk
    double radius = 1.0;   ///< polar_disk, concentric_disk
    /// triangle: the vertices (b0 = 1 - sqrt(u1) weighs v0, b1 = u2 sqrt(u1) weighs v1).
    Vec2 v0{0.0, 0.0}, v1{1.0, 0.0}, v2{0.0, 1.0};
    /// tabulated_1d: the bins' values; tabulated_2d: ny rows of nx values (row-major, y
    /// outer). Empty: the expression's values, or without one a small default table.
    std::vector<double> values;
    /// tabulated_1d: f(x); tabulated_2d: f(x, y); evaluated at the bins' (cells') centres when
    /// values is empty.
    std::string expression;
    /// tabulated_1d: the number of bins of an expression (0: 64); tabulated_2d: the table's
    /// columns and rows (0: 16 each for an expression; with values, nx x ny = values.size()).
    int nx = 0, ny = 0;
    double alpha = 0.5;     ///< ggx_visible_normals: GGX roughness alpha, in [1e-3, 10]
    Vec3 wo{0.6, 0.0, 0.8}; ///< ggx_visible_normals: direction of view (normalised), wo.z > 0
    Vec3 a{1.0, 0.0, 0.0};  ///< spherical_triangle: the planar triangle's vertices,
    Vec3 b{0.0, 1.0, 0.0};  ///< seen from `viewpoint` (the domain is the unit sphere of
    Vec3 c{0.0, 0.0, 1.0};  ///< directions around it)
    Vec3 viewpoint{0.0, 0.0, 0.0};
};

/// A named warp's name and a one-line summary of its map and density.
struct NamedWarpInfo {
    const char* name;
    const char* summary;
};

/// Every named warp, in catalog order: uniform, polar_disk, concentric_disk, uniform_sphere,
/// uniform_hemisphere, cosine_hemisphere, triangle, tabulated_1d, tabulated_2d,
/// ggx_visible_normals, spherical_triangle.
const std::vector<NamedWarpInfo>& named_warp_infos();
/// The names, comma-separated, for messages: "uniform, polar_disk, ...".
std::string named_warp_names();

/// The named warp with its domain. Errors name the parameter and its value, or list the names
/// when `name` is none of them.
Made<NamedWarp> make_named_warp(const std::string& name, const NamedWarpParams& params = {});

/// A warp typed as expressions: g holds the domain's point_dim() coordinates of x as
/// expressions in the unit-cube variables u1 .. u<k> (u = u1), k = domain.sample_dim() (the
/// warp's sample_dim); p is its density in the domain's variables x, y, z (x1 ..). The domain
/// has at most 3 coordinates. Errors name the expression: "g2: at position 5: ...", "p: ...".
Made<Warp> make_expression_warp(const Domain& domain, const std::vector<std::string>& g,
                                const std::string& p);

/// A warp typed by the library's caller: g and p each as expressions (as make_expression_warp
/// takes them) or as a caller's function (core/caller_function.h: g gets the block's unit-cube
/// points, k per point, and returns point_dim() coordinates per point; p gets domain points and
/// returns one density per point). A null function takes the expressions beside it.
Made<Warp> make_typed_warp(const Domain& domain, const std::vector<std::string>& g_texts,
                           std::shared_ptr<const CallerFunction> g_function,
                           const std::string& p_text,
                           std::shared_ptr<const CallerFunction> p_function);

/// A checked warp and its domain as an importance proposal (ProposalKind::Warp).
Proposal warp_proposal(std::shared_ptr<const Warp> warp, const Domain& domain);

} // namespace mcp
