// A problem (domain, integrand, quantity, exact value) and the proposals that sample its
// domain: uniform warps of the unit square/cube, or importance distributions.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/distributions.h"
#include "core/made.h"
#include "core/mis.h"
#include "core/points.h"
#include "core/samplers.h"
#include "core/warps.h"
#include "estimators/vegas.h"
#include "integrands/integrand.h"

namespace mcp {

struct EstimatorKind; // estimators/estimator_kind.h
struct Warp;          // estimators/named_warps.h

enum class DomainKind { Box, Disk, Triangle, Sphere, Hemisphere };

const char* domain_kind_name(DomainKind kind);

/// The integration domain. Points handed to integrands live in its embedding space:
/// box: R^d; disk and triangle: R^2; sphere and hemisphere: unit directions in R^3 (z up).
struct Domain {
    DomainKind kind = DomainKind::Box;
    std::vector<double> lo{0.0}, hi{1.0}; ///< box bounds
    Vec2 center{0.0, 0.0};                ///< disk centre
    double radius = 1.0;                  ///< disk radius
    Vec2 v0{0, 0}, v1{1, 0}, v2{0, 1};    ///< triangle vertices

    /// Dimension of the points given to the integrand.
    int point_dim() const;
    /// Dimension of the unit cube the warps start from.
    int sample_dim() const;
    /// Lebesgue measure: volume, area, or solid angle.
    double measure() const;
    std::string describe() const;
};

Made<Domain> make_box(std::vector<double> lo, std::vector<double> hi);
Made<Domain> make_disk(Vec2 center, double radius);
Made<Domain> make_triangle(Vec2 a, Vec2 b, Vec2 c);
Domain make_sphere();
Domain make_hemisphere();

/// What a run estimates: the integral of f over the domain, or its mean (the integral
/// divided by the domain's measure, i.e. E[f(X)] for X uniform on the domain).
enum class Quantity { Integral, Mean };

struct Problem {
    std::string name;
    std::string description;
    Domain domain;
    Integrand integrand;
    Quantity quantity = Quantity::Integral;
    std::optional<double> exact;
    /// The call's control when the problem (its integrand, or a warp it samples with) calls the
    /// library caller's functions: runs stop within a block once it says stop. Null otherwise.
    std::shared_ptr<CallControl> control;
};

/// Whether the call running the problem has been stopped (a caller's function failed, or the
/// caller cancelled): runs then end early and their numbers are discarded.
inline bool problem_stopped(const Problem& p) {
    return call_stopped(p.control);
}

/// The factor from the integral to the reported quantity: 1, or 1 / measure for a mean.
inline double quantity_scale(const Problem& p) {
    return p.quantity == Quantity::Mean ? 1.0 / p.domain.measure() : 1.0;
}

enum class ProposalKind {
    UniformBox,       ///< x = lo + (hi - lo) u
    DiskPolar,        ///< course-notes polar map
    DiskConcentric,   ///< Shirley-Chiu concentric map
    Triangle,         ///< uniform barycentrics
    Sphere,           ///< uniform on the sphere
    Hemisphere,       ///< uniform on the hemisphere
    CosineHemisphere, ///< cos(theta)/pi on the hemisphere
    Product1D,        ///< independent 1D distributions per box axis
    Tabulated2D,      ///< piecewise-constant table over a 2D box
    Warp,             ///< a warp object (named or typed; estimators/named_warps.h)
};

const char* proposal_kind_name(ProposalKind kind);

/// The density the points are drawn from, with respect to the domain's measure.
struct Proposal {
    ProposalKind kind = ProposalKind::UniformBox;
    std::vector<Distribution1D> marginals; ///< Product1D: one per axis
    TabulatedDistribution2D table;         ///< Tabulated2D
    std::shared_ptr<const Warp> warp;      ///< Warp: its map and density
    Domain warp_domain;                    ///< Warp: the domain it maps onto
    bool importance = false;               ///< true for a non-uniform density
    std::string describe() const;
    /// In words for people, on `domain` (the one the proposal samples): "uniform on [0, 1]^2",
    /// "power-law density proportional to x on [0, 1]"; no "=" and no "_".
    std::string describe_text(const Domain& domain) const;
};

/// The uniform proposal of a domain; for disks, concentric unless polar is asked for.
Proposal uniform_proposal(const Domain& domain, bool disk_polar = false);

/// Checks that a proposal can sample a domain (kinds and dimensions match, the 1D
/// distributions cover exactly the box axes, a warp maps onto this very domain from its
/// unit cube). Returns an error message or "".
std::string check_proposal(const Proposal& proposal, const Domain& domain);

/// Warps a block of unit-cube points u (domain.sample_dim() coordinates) to domain points x
/// (domain.point_dim() coordinates) and writes each point's density into pdf.
void warp_block(const Proposal& proposal, const Domain& domain, const PointBlock& u, PointBlock& x,
                double* pdf);

/// The index of the first of the x.n points outside the domain (beyond round-off, 1e-9 of its
/// size: kWarpDomainTolerance; NaN is outside), or x.n when every point is inside.
size_t first_outside(const Domain& domain, const PointBlock& x);

/// pdf[i] = density of the proposal at the domain points x (0 outside its support): the
/// scalar-free form of the densities warp_block returns, for points from anywhere.
void proposal_pdf_block(const Proposal& proposal, const Domain& domain, const PointBlock& x,
                        double* pdf);

/// An estimator: how the unit-cube points are placed, and which density warps them.
/// MISER's options [PressFarrar90] (scene field "miser"; docs/scene-format.md); the defaults
/// are GSL's.
struct MiserOptions {
    double estimate_fraction = 0.1;       ///< share of a region's calls that probe it
    uint64_t min_calls = 0;               ///< least calls per probe and per half; 0: 16 d
    uint64_t min_calls_per_bisection = 0; ///< fewer calls: plain Monte Carlo; 0: 32 min_calls
    double alpha = 2.0;                   ///< calls split as sigma^(2/(1+alpha)) between the halves
    double dither = 0.0; ///< the cut moves by +-dither of the width (breaks symmetry)
};

/// Multiple importance sampling [Veach97, ch. 9] (scene fields "proposals", "heuristic", ...;
/// docs/scene-format.md): technique k draws from proposals[k], the techniques' samples are
/// combined by a heuristic's weights or by the optimal weights of [Kondapaneni19].
struct MisOptions {
    std::vector<Proposal> proposals;
    /// Multi-sample: the shares of N each technique draws (rounded to whole counts); one-sample:
    /// the probabilities of choosing each technique. Positive, summing to 1.
    std::vector<double> fractions;
    MisWeighting weighting;
    bool optimal = false;    ///< weights solved from the samples' regression [Kondapaneni19]
    bool one_sample = false; ///< each sample picks its technique at random [Veach97, 9.2.4]
};

/// Control variates: f - c . (g - G), with g functions of known integrals G and c fitted by
/// least squares on the same samples (or given) [Owen13, 8.9].
struct ControlVariate {
    Integrand g;
    double integral = 0.0; ///< G: the integral of g over the domain
    std::string text;      ///< how the scene named g (for reports)
};
constexpr int kMaxControlVariates = 16;
struct ControlVariateOptions {
    std::vector<ControlVariate> variates;
    std::vector<double> coefficients; ///< given c (one per variate); empty: fitted
};

/// Resampled importance sampling [Talbot05] (estimators/ris.cpp; scene field "ris"): M candidates
/// from the proposal, one kept with probability proportional to g/p for a target g: the scene's
/// pdf (`target`, a cheap proxy of |f|; the proposal is then uniform) or |f| at the candidates.
struct RisOptions {
    static constexpr int kMaxCandidates = static_cast<int>(kBlockSize); ///< fit in one block
    int candidates = 1;                                                 ///< M
    bool target_pdf = false; ///< g = target's density; false: g = |f|
    Proposal target;
};

struct EstimatorSpec {
    std::string name;
    /// What the estimator is (its algorithm, method and error method; estimators/registry.h):
    /// set by the scene parser; null is the fixed kind (a sampler and one proposal).
    const EstimatorKind* kind = nullptr;
    SamplerKind sampler = SamplerKind::Independent;
    uint64_t per_stratum = 1; ///< stratified: points per cell; 2 gives an unbiased error bar
    QmcRandomization randomization = QmcRandomization::Owen; ///< quasi-Monte Carlo samplers
    int randomizations = kDefaultRandomizations; ///< quasi-Monte Carlo: K batches per run
    /// Sobol' with a linear scramble or digital shift and one randomization: the error bar from
    /// the run's own Walsh coefficients (core/walsh_bound.h) instead of K randomizations.
    bool walsh_bound = false;
    Proposal proposal;
    /// The options of the kinds that have them (each read by its kind only). VEGAS and VEGAS+:
    /// the map of the unit cube composed before the proposal's warp (estimators/vegas.h).
    VegasOptions vegas_options;
    MiserOptions miser_options; ///< MISER (estimators/miser.cpp)
    /// Multiple importance sampling (estimators/mis.cpp): its techniques; `proposal` is then the
    /// first technique's. Empty for every other kind.
    MisOptions mis_options;
    /// Control variates (estimators/control_variates.cpp); empty for every other kind.
    ControlVariateOptions control_variate_options;
    RisOptions ris_options; ///< RIS (estimators/ris.cpp); M = 1 and g = |f| for other kinds

    SamplerOptions sampler_options() const { return {per_stratum, randomization, randomizations}; }
    /// Whether it samples a mixture of techniques (MIS) rather than one proposal.
    bool has_techniques() const { return !mis_options.proposals.empty(); }
};

/// Whether the weights f/p of an estimator are bounded by what the problem and the estimator
/// say: f bounded (integrand_bounded) and the sampling density bounded below on the domain (a
/// uniform density, MISER's uniform boxes, a VEGAS map's piecewise-constant density over the
/// uniform one, or MIS with a uniform technique among its mixture). Control variates and the
/// other importance densities (which may vanish where f does not) are not known to be.
/// Bounded weights have every moment finite: a heavy-looking tail is pre-asymptotic.
bool weights_bounded(const Problem& problem, const EstimatorSpec& spec);

/// Whether the variance of the estimator's weights is finite exactly when int f^2 is: its
/// sampling density is bounded above and below on the domain (uniform points, stratified,
/// Latin hypercube or randomized QMC, MISER's boxes, a VEGAS map's bins), with neither MIS nor
/// control variates (whose weights mix other functions in).
bool variance_follows_integrand(const EstimatorSpec& spec);

/// The proposals an estimator draws from: its one proposal, or its MIS techniques; for RIS with
/// a pdf as its target, that target (its points keep to where the target is positive).
std::vector<const Proposal*> proposals_of(const EstimatorSpec& spec);

/// pdf[i] = the density of the estimator's points at x, on average over its techniques: its
/// proposal's (RIS with a pdf target: the target's, which its points approach as M grows), or
/// for MIS the mixture sum_k c_k p_k(x) with the techniques' shares c_k (zero exactly where
/// every technique's density is).
void sampling_density_block(const EstimatorSpec& spec, const Domain& domain, const PointBlock& x,
                            double* pdf);

/// The density as a report names it: the proposal's, or "mis(balance: a 0.5, b 0.5)".
std::string describe_sampling(const EstimatorSpec& spec);
/// The same in words (results' "pdf_text"): Proposal::describe_text, a mixture's shares and
/// heuristic, and for the adaptive kinds what reshapes the density during a run.
std::string describe_sampling_text(const EstimatorSpec& spec, const Domain& domain);

} // namespace mcp
