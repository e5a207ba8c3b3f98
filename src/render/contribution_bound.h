// Whether a render estimator's per-sample reflected radiance is bounded by its construction
// (docs/render-scenes.md, "Bounded contributions"). A bounded contribution has every moment
// finite, so a heavy-looking tail of the samples is pre-asymptotic: render studies then raise
// heavy_tail as info, as integration studies do for bounded weights (problem.h,
// weights_bounded), and keep the tail estimate's verdict for the others.
#pragma once

#include <string>

#include "render/integrator.h"

namespace mcp {

/// Where the lights meet the surfaces they light. Two triangles are in contact when they come
/// within kContactDistance of the scene's extent (the diagonal of its bounding box) of each
/// other and are not coplanar (normals within kCoplanarSine and the other triangle within
/// kPlaneDistance of the extent from the light's plane: a surface in the light's plane receives
/// nothing). A contact is inside the light when a surface comes within kPlaneDistance of a point
/// inside the light's edges (there solid-angle sampling's area fallback for solid angles within
/// 1e-12 of 2 pi can be reached).
struct LightContacts {
    bool checked = false;          ///< false: too many pairs to test (kMaxContact*)
    bool contact = false;          ///< some light touches a surface
    bool interior_contact = false; ///< ... at a point inside the light, not on its edges
    size_t pairs = 0;              ///< (light, triangle) pairs whose boxes overlap
};
/// A light closer than this (relative to the scene's extent) to a surface is taken as touching
/// it: the area form's bound, of order 1 / d^2, is then 1e8 times its typical value or more,
/// so the tail is what any feasible study sees (touching_light's 0.1 mm gap is 5e-5).
constexpr double kContactDistance = 1e-4;
constexpr double kCoplanarSine = 1e-9;
/// The rounding of transformed vertices, generously: 1e-9 of the scene's extent.
constexpr double kPlaneDistance = 1e-9;
/// Beyond these many (light, nearby triangle) box tests, or exact tests of overlapping boxes,
/// contacts are not checked (area and solid-angle sampling are left to the tail estimate).
constexpr size_t kMaxContactBoxTests = size_t(1) << 26;
constexpr size_t kMaxContactPairs = size_t(1) << 24;
LightContacts light_contacts(const RenderScene& rs);

/// Whether the estimator's per-sample reflected radiance is bounded, and why (or why not).
struct ContributionBound {
    bool bounded = false;
    std::string reason;
};
ContributionBound contribution_bound(const RenderEstimator& e, const LightContacts& contacts);

} // namespace mcp
