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
/// nothing). A contact matters only where a camera ray can reach it: the receiver reflects
/// light (a black, non-specular surface returns nothing) and the box holding the receiver's
/// points near the light meets the camera's view (`aspect` = width / height of the images);
/// the others are counted in `ignored`. A contact is inside the light when a surface comes
/// within kPlaneDistance of a point inside the light's edges (there solid-angle sampling's
/// area fallback for solid angles within 1e-12 of 2 pi can be reached). It is seen when the
/// two touch (within kPlaneDistance), face each other, and camera rays to points of the
/// receiver 1e-3 and 1e-6 of the extent from the contact reach them: area sampling's
/// variance is then infinite (docs/render-scenes.md, "Bounded contributions").
struct LightContacts {
    bool checked = false;          ///< false: too many pairs to test (kMaxContact*)
    bool contact = false;          ///< some light touches a surface it lights, in view
    bool interior_contact = false; ///< ... at a point inside the light, not on its edges
    bool seen_contact = false;     ///< ... touching, facing it, where the camera sees it
    size_t pairs = 0;              ///< (light, triangle) pairs whose boxes overlap
    size_t ignored = 0;            ///< contacts with black surfaces or out of the camera's view
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
/// Touching pairs tested for being seen (two camera rays each); beyond, a contact is not
/// called seen (the tail estimate decides).
constexpr size_t kMaxSeenChecks = 4096;
LightContacts light_contacts(const RenderScene& rs, double aspect = 1.0);

/// Whether the estimator's per-sample reflected radiance is bounded, whether its variance is
/// infinite by construction (area sampling of a light at a contact the camera sees), and why.
/// Neither: the tail estimate decides.
struct ContributionBound {
    bool bounded = false;
    bool infinite_variance = false;
    std::string reason;
};
ContributionBound contribution_bound(const RenderEstimator& e, const LightContacts& contacts);

} // namespace mcp
