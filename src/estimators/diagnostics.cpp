#include "estimators/diagnostics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

#include "core/special.h"
#include "core/stats.h"

namespace mcp {

const char* flag_code_name(FlagCode code) {
    switch (code) {
    case FlagCode::NoEstimate: return "no_estimate";
    case FlagCode::NonfiniteEstimate: return "nonfinite_estimate";
    case FlagCode::NonfiniteVariance: return "nonfinite_variance";
    case FlagCode::ZeroErrorBar: return "zero_error_bar";
    case FlagCode::NonfiniteSamples: return "nonfinite";
    case FlagCode::ZeroPdfSamples: return "zero_pdf_samples";
    case FlagCode::SkewedWeights: return "skewed_weights";
    case FlagCode::LowEss: return "low_ess";
    case FlagCode::ExactOutsideCi: return "exact_outside_ci";
    case FlagCode::HeavyTail: return "heavy_tail";
    case FlagCode::HeavyTail4: return "heavy_tail_4";
    case FlagCode::PdfSupport: return "pdf_support";
    case FlagCode::LevelDrift: return "level_drift";
    case FlagCode::IterationsDisagree: return "iterations_disagree";
    case FlagCode::ErrorBarsUnderstate: return "error_bars_understate";
    case FlagCode::ErrorBarsUnstable: return "error_bars_unstable";
    case FlagCode::BiasDominates: return "bias_dominates";
    case FlagCode::ConservativeErrorBars: return "conservative_error_bars";
    case FlagCode::Float32Accumulator: return "float32_accumulator";
    case FlagCode::BelowReferenceNoise: return "below_reference_noise";
    case FlagCode::ReferenceNoise: return "reference_noise";
    case FlagCode::SlowConvergence: return "slow_convergence";
    case FlagCode::PixelErrorBars: return "pixel_error_bars";
    case FlagCode::FewPixelErrors: return "few_pixel_errors";
    case FlagCode::RareLargeErrors: return "rare_large_errors";
    case FlagCode::ValuesUnderflow: return "values_underflow";
    case FlagCode::ReplicateFarOff: return "replicate_far_off";
    }
    return "?";
}

const char* severity_name(Severity severity) {
    switch (severity) {
    case Severity::Error: return "error";
    case Severity::Warning: return "warning";
    case Severity::Info: return "info";
    }
    return "?";
}

Severity default_severity(FlagCode code) {
    switch (code) {
    case FlagCode::NoEstimate:
    case FlagCode::NonfiniteEstimate:
    case FlagCode::NonfiniteVariance:
    case FlagCode::ZeroErrorBar:
    case FlagCode::NonfiniteSamples:
    case FlagCode::ZeroPdfSamples:
    case FlagCode::ExactOutsideCi:
    case FlagCode::ValuesUnderflow:
    case FlagCode::PdfSupport:
    case FlagCode::IterationsDisagree:
    case FlagCode::ErrorBarsUnderstate:
    case FlagCode::PixelErrorBars: return Severity::Error;
    case FlagCode::SkewedWeights:
    case FlagCode::ErrorBarsUnstable:
    case FlagCode::LowEss:
    case FlagCode::HeavyTail:
    case FlagCode::LevelDrift:
    case FlagCode::FewPixelErrors:
    case FlagCode::RareLargeErrors:
    case FlagCode::ReplicateFarOff:
    case FlagCode::SlowConvergence: return Severity::Warning;
    case FlagCode::HeavyTail4:
    case FlagCode::BiasDominates:
    case FlagCode::ConservativeErrorBars:
    case FlagCode::Float32Accumulator:
    case FlagCode::BelowReferenceNoise:
    case FlagCode::ReferenceNoise: return Severity::Info;
    }
    return Severity::Warning;
}

namespace {
/// Cochran's Q p-value from which replicates judged without the exact value show no sign of
/// scattering beyond their error bars (see level_flags' record_evidence).
constexpr double kNoScatterP = 0.05;
// max se / min se over the runs with a finite, positive error bar (NaN with fewer than two).
double error_bar_spread(const std::vector<double>& se) {
    double lo = std::numeric_limits<double>::infinity(), hi = 0.0;
    int count = 0;
    for (double s : se)
        if (std::isfinite(s) && s > 0.0) {
            lo = std::min(lo, s);
            hi = std::max(hi, s);
            ++count;
        }
    return count >= 2 ? hi / lo : std::numeric_limits<double>::quiet_NaN();
}
// Bartlett's test that the runs' error bars estimate one variance: each run's se^2 with its
// degrees of freedom nu_i; T = [(sum nu) ln(pooled) - sum nu_i ln se_i^2] / C is chi^2 with
// k - 1 degrees of freedom for normal data, C = 1 + (sum 1/nu_i - 1/sum nu) / (3 (k - 1))
// [Bartlett37]. Its p-value (NaN with fewer than two usable runs).
double bartlett_p(const std::vector<double>& se, const std::vector<int>& dofs) {
    double nu_sum = 0.0, pooled = 0.0, log_sum = 0.0, inv_sum = 0.0;
    int k = 0;
    for (size_t i = 0; i < se.size() && i < dofs.size(); ++i) {
        const double s = se[i], nu = static_cast<double>(dofs[i]);
        if (!(std::isfinite(s) && s > 0.0 && nu >= 1.0)) continue;
        nu_sum += nu;
        pooled += nu * s * s;
        log_sum += nu * std::log(s * s);
        inv_sum += 1.0 / nu;
        ++k;
    }
    if (k < 2) return std::numeric_limits<double>::quiet_NaN();
    const double c = 1.0 + (inv_sum - 1.0 / nu_sum) / (3.0 * (k - 1));
    const double t = (nu_sum * std::log(pooled / nu_sum) - log_sum) / c;
    return chi_square_sf(std::max(t, 0.0), static_cast<double>(k - 1));
}
// The most misses of their 95% interval that n honest replicates exceed with probability below
// kMissAllowanceP: the largest k with P(Bin(n, 0.05) >= k) >= that, where
// P(Bin(n, p) >= k) = I_p(k, n - k + 1) [AbramowitzStegun, 26.5.24].
int miss_allowance(int n) {
    int k = 0;
    while (k < n && beta_regularized(k + 1.0, n - k, 0.05) >= kMissAllowanceP) ++k;
    return k;
}
} // namespace

namespace {
/// The finite estimates' standard deviation (n - 1), computed on them over their largest
/// magnitude and scaled back, so that it survives estimates whose squares underflow; and
/// their range.
struct Spread {
    double deviation = 0.0, lowest = 0.0, highest = 0.0;
};
Spread spread_of(const std::vector<double>& estimates) {
    Spread s;
    double largest = 0.0;
    bool any = false;
    for (double x : estimates)
        if (std::isfinite(x)) {
            s.lowest = any ? std::min(s.lowest, x) : x;
            s.highest = any ? std::max(s.highest, x) : x;
            largest = std::max(largest, std::fabs(x));
            any = true;
        }
    if (!(largest > 0.0) || !std::isfinite(largest)) return s;
    RunningMoments scaled;
    for (double x : estimates)
        if (std::isfinite(x)) scaled.add(x / largest);
    s.deviation = largest * std::sqrt(scaled.variance());
    return s;
}
} // namespace

ScatterTest replicate_scatter(const LevelStats& l) {
    ScatterTest t;
    const size_t reps = std::min({l.estimates.size(), l.run_std_errors.size(), l.run_dofs.size()});
    std::vector<size_t> usable;
    for (size_t i = 0; i < reps; ++i)
        if (std::isfinite(l.estimates[i]) && std::isfinite(l.run_std_errors[i]) &&
            l.run_std_errors[i] > 0.0 && l.run_dofs[i] >= 1)
            usable.push_back(i);
    if (usable.size() < 4) return t;
    const bool against_exact = l.has_exact && std::isfinite(l.exact);
    const double r = static_cast<double>(usable.size());
    double mean = 0.0, mean_variance = 0.0; // the plain mean and its variance, sum se_j^2 / R^2
    for (size_t i : usable) {
        mean += l.estimates[i] / r;
        mean_variance += l.run_std_errors[i] * l.run_std_errors[i] / (r * r);
    }
    double q = 0.0;
    for (size_t i : usable) {
        const double se = l.run_std_errors[i];
        // Var(x_i - mean) = se_i^2 (1 - 2 / R) + sum se_j^2 / R^2 for independent replicates.
        const double var = against_exact ? se * se : se * se * (1.0 - 2.0 / r) + mean_variance;
        const double centre = against_exact ? l.exact : mean;
        const double z = std::fabs(l.estimates[i] - centre) / std::sqrt(var);
        // z is Student t with the run's dof (its se is an estimate): the normal quantile of the
        // same tail probability.
        const double tail = student_t_sf(z, static_cast<double>(l.run_dofs[i]));
        const double normal = tail > 1e-300 ? -normal_quantile(std::min(tail, 0.5)) : z;
        q += normal * normal;
    }
    t.judged = static_cast<int>(usable.size());
    t.q = q;
    t.p_value = chi_square_sf(q, r);
    return t;
}

ReplicateCheck check_replicates(const LevelStats& l) {
    ReplicateCheck c;
    const size_t reps = std::min({l.estimates.size(), l.run_std_errors.size(), l.run_dofs.size()});
    // Leave-one-out needs the others' mean and spread: their squared deviations about the
    // whole mean, less replicate i's share, S_-i = S - (x_i - m)^2 R / (R - 1).
    double mean = 0.0, squares = 0.0;
    size_t finite = 0;
    for (size_t i = 0; i < reps; ++i)
        if (std::isfinite(l.estimates[i])) {
            ++finite;
            const double delta = l.estimates[i] - mean;
            mean += delta / static_cast<double>(finite);
            squares += delta * (l.estimates[i] - mean);
        }
    const bool against_exact = l.has_exact && std::isfinite(l.exact);
    if (!against_exact && finite < 3) return c;
    const double r = static_cast<double>(finite);
    std::vector<double> studentized, limits; // t_i against the others' mean, and its far limit
    // The limits per degrees of freedom, computed once: replicates mostly share theirs.
    std::map<int, double> far_limits, skewed_limits;
    auto limit_at = [](double z, std::map<int, double>& memo, int dof) {
        auto [it, fresh] = memo.try_emplace(dof, 0.0);
        if (fresh) it->second = widened_limit(z, static_cast<double>(dof));
        return it->second;
    };
    std::vector<int> index;
    for (size_t i = 0; i < reps; ++i) {
        const double x = l.estimates[i], se = l.run_std_errors[i];
        if (!std::isfinite(x) || !(std::isfinite(se) && se > 0.0) || l.run_dofs[i] < 1) continue;
        if (!against_exact && finite >= 3) {
            studentized.push_back((x - (r * mean - x) / (r - 1.0)) / se);
            limits.push_back(limit_at(kSkewedFarZ, skewed_limits, l.run_dofs[i]));
            index.push_back(static_cast<int>(i));
        }
        double centre = l.exact, spread = se;
        if (!against_exact) {
            centre = (r * mean - x) / (r - 1.0);
            const double others = std::max(0.0, squares - (x - mean) * (x - mean) * r / (r - 1.0));
            spread = std::sqrt(se * se + others / ((r - 2.0) * (r - 1.0)));
        }
        const double t = student_t_quantile(0.975, static_cast<double>(l.run_dofs[i]));
        const double z = std::fabs(x - centre) / spread;
        const double far_limit = limit_at(kFarOffZ, far_limits, l.run_dofs[i]);
        ++c.judged;
        if (z > t) ++c.misses;
        if (z > far_limit) ++c.far;
        if (c.worst_index < 0 || z / far_limit > c.worst_z / c.worst_limit) {
            c.worst_index = static_cast<int>(i);
            c.worst_z = z;
            c.worst_limit = far_limit;
        }
    }
    c.allowance = miss_allowance(c.judged);
    // The skew's signature, without the exact value: the studentized deviations skew, and the
    // farthest of them on that side lies beyond kSkewedFarZ of its own error bar. Blind, the
    // others' mean sits on the skewed runs' side of the integral (most runs miss the rare large
    // weights), so their distance from it understates their error.
    const size_t m = studentized.size();
    if (m >= 8) {
        double mt = 0.0, m2 = 0.0, m3 = 0.0;
        for (double t : studentized) mt += t / static_cast<double>(m);
        for (double t : studentized) {
            m2 += (t - mt) * (t - mt) / static_cast<double>(m);
            m3 += (t - mt) * (t - mt) * (t - mt) / static_cast<double>(m);
        }
        if (m2 > 0.0) c.skewness = m3 / std::pow(m2, 1.5);
        if (std::fabs(c.skewness) > kSkewSignature) {
            const double side = c.skewness > 0.0 ? 1.0 : -1.0;
            size_t far = 0;
            for (size_t j = 1; j < m; ++j)
                if (side * studentized[j] / limits[j] > side * studentized[far] / limits[far])
                    far = j;
            if (side * studentized[far] > limits[far]) {
                c.skewed_index = index[far];
                c.skewed_z = std::fabs(studentized[far]);
                c.skewed_limit = limits[far];
            }
        }
    }
    return c;
}

std::vector<Flag> level_flags(const LevelStats& l) {
    std::vector<Flag> flags;
    auto raise = [&](FlagCode code) -> Flag& {
        flags.push_back(Flag(code));
        flags.back().n = l.n;
        return flags.back();
    };
    const uint64_t reps = static_cast<uint64_t>(l.reps);
    // No estimate: one flag, and none of the diagnostics computed from dropped samples.
    if (l.no_estimate_runs > 0) {
        Flag& f = raise(FlagCode::NoEstimate);
        f.count = static_cast<uint64_t>(l.no_estimate_runs);
        f.of = reps;
        return flags;
    }
    if (!std::isfinite(l.mean))
        raise(FlagCode::NonfiniteEstimate);
    else if (!std::isfinite(l.variance) || l.variance < 0.0)
        raise(FlagCode::NonfiniteVariance).value = l.variance;
    // Values whose squares underflow: every variance, error bar and test below is 0 or wrong.
    if (l.values_underflow) {
        Flag& f = raise(FlagCode::ValuesUnderflow);
        f.value = std::fabs(l.mean);
        f.threshold = kUnderflowScale;
    }
    // The replicates against their own intervals: the evidence that warnings resting on the
    // weights alone (skewed_weights, error_bars_unstable) must agree with once there is enough
    // of it, and a replicate far outside its interval is itself an alarm.
    const ReplicateCheck replicates =
        l.exact_to_roundoff || l.values_underflow ? ReplicateCheck() : check_replicates(l);
    // Each replicate in its own error bars (Cochran's Q): runs with tiny error bars that scatter
    // far beyond them are evidence against every warning's demotion below.
    const ScatterTest scatter =
        l.exact_to_roundoff || l.values_underflow ? ScatterTest() : replicate_scatter(l);
    const bool scattered = scatter.judged > 0 && scatter.p_value < kLevelDriftP;
    const bool replicates_cover = replicates.judged >= kEvidenceReplicates &&
                                  replicates.misses <= replicates.allowance &&
                                  replicates.far == 0 && replicates.skewed_index < 0 && !scattered;
    // `blind_ok`: whether replicates judged without the exact value may demote the flag. For
    // error_bars_unstable only when Cochran's Q shows no sign of scatter (p >= 0.05, not merely
    // no proof of it): without the exact value each replicate is judged against the others'
    // spread, which the few runs with large error bars inflate, the very thing that flag reports
    // (sobol, halton and vegas_sobol on Genz's corner peak in d = 7 and 10 at N = 8192 had runs
    // 5.5 of their own error bars off, error bars 5-16 times apart, and passed that check).
    const bool no_scatter = scatter.judged > 0 && scatter.p_value >= kNoScatterP;
    auto record_evidence = [&](Flag& f, bool blind_ok) {
        f.replicates_judged = replicates.judged;
        f.replicate_misses = replicates.misses;
        f.miss_allowance = replicates.allowance;
        const bool judged = l.has_exact || blind_ok;
        if (replicates_cover && judged && f.severity == Severity::Warning)
            f.severity = Severity::Info;
    };
    if (replicates.far > 0) {
        Flag& f = raise(FlagCode::ReplicateFarOff);
        f.value = replicates.worst_z;
        f.threshold = replicates.worst_limit;
        f.count = static_cast<uint64_t>(replicates.far);
        f.of = reps;                    // "replicate 3 of 32": of all of them, not of those judged
        f.dof = replicates.worst_index; // which replicate (0-based)
        f.se = l.has_exact ? 1.0 : 0.0; // 1: judged against the exact value
        f.replicates_judged = replicates.judged;
        f.replicate_misses = replicates.misses;
        f.miss_allowance = replicates.allowance;
    } else if (replicates.skewed_index >= 0) {
        // Within kFarOffZ of the others' mean and its spread, but skewed runs pull that mean and
        // spread with them: the runs 5.9-7.1 standard errors from the exact value in the fresh
        // battery (corner peaks, border products) were 4.5-7.0 of their own error bars from the
        // others' mean, on the side the deviations skew toward.
        Flag& f = raise(FlagCode::ReplicateFarOff);
        f.value = replicates.skewed_z;
        f.threshold = replicates.skewed_limit;
        f.count = 1;
        f.of = reps;
        f.dof = replicates.skewed_index;
        f.se = 0.0; // judged against the others' mean
        f.skewness = replicates.skewness;
        f.replicates_judged = replicates.judged;
        f.replicate_misses = replicates.misses;
        f.miss_allowance = replicates.allowance;
    }
    // A random estimator whose own error bar is 0 while its replicates disagree: the runs saw
    // no variation (e.g. both points of every stratum on the same side of a discontinuity),
    // and their intervals are wrong. When every replicate agrees (f/p constant) 0 is right.
    // The spread is measured on the estimates over their largest magnitude (their squares
    // underflow below 1e-154, where l.variance reads 0 for replicates that differ), and the flag
    // needs the replicates to differ by that measure too: never "differ (standard deviation 0)".
    Spread replicate_spread = spread_of(l.estimates);
    if (l.estimates.size() < 2) { // no replicates kept (one run judged alone): its variance
        replicate_spread.deviation = std::sqrt(l.variance);
        const double nan = std::numeric_limits<double>::quiet_NaN();
        replicate_spread.lowest = replicate_spread.highest = nan;
    }
    if (l.zero_error_runs > 0 && l.estimates_spread && replicate_spread.deviation > 0.0) {
        Flag& f = raise(FlagCode::ZeroErrorBar);
        f.count = static_cast<uint64_t>(l.zero_error_runs);
        f.of = reps;
        f.value = replicate_spread.deviation;
        f.threshold = replicate_spread.lowest; // the range the replicates span, for the sentence
        f.se = replicate_spread.highest;
    }
    // The replicates' spread against their own error bars, with or without an exact value: each
    // run's se^2 estimates the variance of its estimate, so s^2 (across the R replicates) over
    // the mean se^2 is F(R - 1, sum of the runs' dof) for normal estimates [Snedecor]. Far above
    // (p < 1e-3): the error bars are too small, e.g. a stratified or randomized-QMC error bar
    // whose few strata or randomizations all missed a discontinuity's sliver.
    if (l.reps >= 4 && l.estimates_spread && l.zero_error_runs == 0 && l.mean_run_variance > 0.0 &&
        std::isfinite(l.mean_run_variance) && std::isfinite(l.variance) && l.run_dof_total >= 1.0) {
        const double ratio = l.variance / l.mean_run_variance;
        const double p = f_sf(ratio, static_cast<double>(l.reps - 1), l.run_dof_total);
        if (ratio > 1.0 && p < kLevelDriftP) {
            Flag& f = raise(FlagCode::ErrorBarsUnderstate);
            f.value = ratio;
            f.dof = l.reps - 1;
            f.p_value = p;
            f.threshold = kLevelDriftP;
            f.of = reps;
        }
        // Far below (the lower tail at p < 1e-3): the error bars are conservative, e.g. the
        // collapsed-strata bound of a stratified run on a smooth integrand (worth knowing: the
        // intervals are right, only wider than they need be).
        const double p_low = 1.0 - p;
        if (ratio < 1.0 && p_low < kLevelDriftP) {
            Flag& f = raise(FlagCode::ConservativeErrorBars);
            f.value = std::sqrt(1.0 / ratio); // how many times too wide
            f.dof = l.reps - 1;
            f.p_value = p_low;
            f.threshold = kLevelDriftP;
            f.of = reps;
        }
    }
    // The same judged replicate by replicate (replicate_scatter): a lattice on Genz's corner
    // peak in d = 10 at N = 8192 had most runs' error bars 14 times too small beside a few
    // large ones, whose share of the mean se^2 hid them from the F test (count: the replicates
    // judged, 0 for the F test).
    const bool understated = std::any_of(flags.begin(), flags.end(), [](const Flag& f) {
        return f.code == FlagCode::ErrorBarsUnderstate;
    });
    if (scattered && !understated) {
        Flag& f = raise(FlagCode::ErrorBarsUnderstate);
        f.value = scatter.q / scatter.judged; // the variance ratio: Q over its mean
        f.dof = scatter.judged;
        f.count = static_cast<uint64_t>(scatter.judged);
        f.p_value = scatter.p_value;
        f.threshold = kLevelDriftP;
        f.of = reps;
    }
    // The runs' own error bars disagree with each other far beyond what their degrees of
    // freedom allow (Bartlett's test), by more than a factor kUnstableSpread: some runs saw a
    // feature (a sliver of a step, a rare peak) that others missed entirely, and those others'
    // error bars are far too small, though the mean of the se^2 may match the spread.
    if (!l.exact_to_roundoff && l.reps >= 2) {
        const double spread = error_bar_spread(l.run_std_errors);
        const double p = bartlett_p(l.run_std_errors, l.run_dofs);
        if (spread > kUnstableSpread && p < kLevelDriftP) {
            Flag& f = raise(FlagCode::ErrorBarsUnstable);
            f.value = spread;
            f.threshold = kUnstableSpread;
            f.p_value = p;
            f.of = reps;
            record_evidence(f, no_scatter);
        }
    }
    const RunDiagnostics& d = l.diagnostics;
    if (d.nonfinite) {
        Flag& f = raise(FlagCode::NonfiniteSamples);
        f.count = d.nonfinite;
        f.of = l.n * reps;
    }
    if (d.zero_pdf) {
        Flag& f = raise(FlagCode::ZeroPdfSamples);
        f.count = d.zero_pdf;
        f.of = l.n * reps;
    }
    // Weights so skewed that their mean is not yet near normal at this N: the t interval's
    // coverage fails first in the tail the skew points away from (runs that missed the rare
    // large weights have estimates and error bars both too small). Cochran's rule: the normal
    // approximation holds for N > 25 g1^2, where the mean's own skewness g1 / sqrt(N) is below
    // 0.2 [Cochran77, section 2.15]; g1 is the skewness of the weights pooled over the R runs
    // (R N values reach further into the tail than one run). For randomized QMC the error bar is
    // the spread of each run's K batch means: the rule is then on them, K > 25 g1^2.
    //  - a warning from a mean's skewness of 0.4 (N < 25 g1^2 / 4);
    //  - between 0.2 and 0.4 a warning when the runs' own error bars disagree by more than a
    //    factor 2 (their variance estimates are unstable: some are off by 40% or more), else
    //    info, with the N from which the rule holds.
    // The units are the weights, or for K randomizations the K batch means of each run. A batch
    // mean averages m = N/K points; where the points barely see f (skewed weights) it is close
    // to a mean of m independent weights, whose skewness is g1_w / sqrt(m) [Cochran77, 2.15],
    // and the K R batch means pooled here may not yet show it (a rare hit in one batch of one
    // run): the larger of the two is taken.
    const double units_per_run =
        l.reps > 0 ? static_cast<double>(d.error_units.count()) / static_cast<double>(l.reps) : 0.0;
    double g1 = d.error_units.skewness();
    if (d.batch_units && units_per_run > 0.0 && std::isfinite(g1)) {
        const double per_unit = static_cast<double>(l.n) / units_per_run;
        const double from_weights = std::fabs(d.weights.skewness()) / std::sqrt(per_unit);
        if (std::isfinite(from_weights) && from_weights > std::fabs(g1)) g1 = from_weights;
    }
    const double rule_n = kSkewnessRule * g1 * g1;
    if (!l.exact_to_roundoff && std::isfinite(g1) && units_per_run < rule_n) {
        const bool strongly_skewed = units_per_run < rule_n / 4.0;
        const double spread = error_bar_spread(l.run_std_errors);
        Flag& f = raise(FlagCode::SkewedWeights);
        f.value = g1;
        f.threshold = rule_n; // the number of units per run from which the rule holds
        f.count = static_cast<uint64_t>(units_per_run + 0.5);
        f.dof = d.batch_units ? static_cast<int>(f.count) : 0; // K batch means, or weights
        f.se = spread;
        const bool unsettled = !(spread <= kErrorBarSpread); // NaN (fewer than 2 runs) too
        f.severity = strongly_skewed || unsettled ? Severity::Warning : Severity::Info;
        // Blind, R replicates cannot vouch for a mean that is strongly skewed and rests on a
        // few weights (one of them kRulingShare of a run's sum or more): its intervals fail in
        // the tail the skew points away from a few times in a hundred (stratified, Latin
        // hypercube and uniform runs on Genz's corner peak in d = 3 at N = 8192: 2-8% of 400
        // runs beyond 5 standard errors, 76% coverage), which 32 replicates judged against
        // their own mean, itself pulled toward the runs that missed the rare large weights,
        // seldom show. Not for randomized QMC's K batch means: the same rule on their measured
        // skewness raised alarms on 119 more of 2674 fine cells (five fresh batteries, 4.5%)
        // to catch one run 5.6 standard errors off.
        const bool few_rule =
            strongly_skewed && !d.batch_units && d.max_weight_share >= kRulingShare;
        record_evidence(f, !few_rule);
    }
    // Kish's effective sample size: when a handful of samples carry the sum (a narrow peak
    // barely hit, a few huge weights), the estimate and its error bar rest on those few.
    if (!l.exact_to_roundoff && l.ess_mean < kLowEss &&
        l.ess_mean < kLowEssShare * static_cast<double>(l.n)) {
        Flag& f = raise(FlagCode::LowEss);
        f.value = l.ess_mean;
        f.threshold = kLowEss;
    }
    // An iteration average whose iterations disagree: the error bar of the weighted mean
    // assumes they estimate one value (vegas's and GSL's chi^2 / dof check, pooled over runs).
    if (l.iteration_dof > 0) {
        const double p = chi_square_sf(l.iteration_chi2, l.iteration_dof);
        if (p < kLevelDriftP) {
            Flag& f = raise(FlagCode::IterationsDisagree);
            f.value = l.iteration_chi2;
            f.dof = l.iteration_dof;
            f.p_value = p;
            f.threshold = kLevelDriftP;
            f.of = reps;
        }
    }
    // With the exact value known: the replicates' mean must lie within a few of its own
    // standard errors of it, or the estimator is biased or its variance infinite.
    if (l.has_exact) {
        const double tolerance = kExactOutsideZ * l.std_error + 1e-12 * std::fabs(l.mean - l.bias);
        if (std::fabs(l.bias) > tolerance) {
            Flag& f = raise(FlagCode::ExactOutsideCi);
            f.value = l.std_error > 0.0 ? std::fabs(l.bias) / l.std_error
                                        : std::numeric_limits<double>::infinity();
            f.threshold = kExactOutsideZ;
            f.of = reps;
        }
    }
    return flags;
}

std::vector<Flag> tail_flags(const LevelStats& deepest, bool bounded,
                             const IntegrandTail* integrand) {
    std::vector<Flag> flags;
    if (integrand && integrand->k > 0 && integrand->alpha > 0.0) {
        // The integrand's own tail at uniform probes: an infinite index (|f| constant at the
        // top, or bounded: no tail) raises nothing.
        const double alpha = integrand->alpha;
        const double se = alpha / std::sqrt(static_cast<double>(integrand->k));
        const bool infinite_variance = alpha < kHeavyTailAlpha + 2.0 * se;
        if (!std::isfinite(alpha) || (!infinite_variance && !(alpha < kHeavyTail4Alpha)))
            return flags;
        Flag f(infinite_variance ? FlagCode::HeavyTail : FlagCode::HeavyTail4);
        f.n = deepest.n;
        f.value = alpha;
        f.se = se;
        f.count = static_cast<uint64_t>(integrand->k);
        f.of = integrand->probes;
        f.threshold = infinite_variance ? kHeavyTailAlpha : kHeavyTail4Alpha;
        // int f^2 known finite from f's form: Hill's index, read low by a slowly varying factor
        // at 2^15 probes, is no evidence against it.
        if (bounded || integrand->square_integrable == true) f.severity = Severity::Info;
        flags.push_back(f);
        return flags;
    }
    // A tail index of exactly 0 is Hill's answer when fewer than k + 1 weights are non-zero
    // (hill_tail_index): points that never saw f have no tail to measure, and the level's own
    // flags (exact_outside_ci, low_ess, zero_error_bar, ...) say what is wrong.
    if (!std::isfinite(deepest.tail_index) || deepest.tail_k <= 0 || deepest.exact_to_roundoff ||
        deepest.tail_index == 0.0)
        return flags;
    const double alpha = deepest.tail_index;
    const double se = alpha / std::sqrt(static_cast<double>(deepest.tail_k));
    const bool infinite_variance = alpha < kHeavyTailAlpha + 2.0 * se;
    if (!infinite_variance && !(alpha < kHeavyTail4Alpha)) return flags;
    Flag f(infinite_variance ? FlagCode::HeavyTail : FlagCode::HeavyTail4);
    f.n = deepest.n;
    f.value = alpha;
    f.se = se;
    f.count = static_cast<uint64_t>(deepest.tail_k);
    f.threshold = infinite_variance ? kHeavyTailAlpha : kHeavyTail4Alpha;
    if (bounded) f.severity = Severity::Info;
    flags.push_back(f);
    return flags;
}

bool known_bias_source(const EstimatorStudy& e) {
    const SupportCheck& sc = e.support;
    // flagged: a missed mass beyond kSupportTolerance of the integral of |f|; a mass that is not
    // finite (|f| not integrable where p = 0) is missed too; so is any probe that found f != 0
    // where p = 0.
    const bool missed_mass = sc.method == "quadrature" && !std::isfinite(sc.missed_mass);
    if (sc.flagged || sc.missed > 0 || missed_mass) return true;
    for (const LevelStats& l : e.levels)
        if (l.diagnostics.zero_pdf > 0 || l.diagnostics.nonfinite > 0) return true;
    return false;
}

std::vector<Flag> estimator_flags(const EstimatorStudy& e, const StudySettings& settings) {
    std::vector<Flag> flags;
    if (!e.levels.empty())
        flags = tail_flags(e.levels.back(), e.weights_bounded,
                           e.integrand.k > 0 ? &e.integrand : nullptr);
    const SupportCheck& sc = e.support;
    if (sc.flagged) {
        Flag f(FlagCode::PdfSupport);
        f.value = sc.missed_fraction;
        f.threshold = kSupportTolerance;
        f.count = sc.missed;
        f.of = sc.f_nonzero;
        flags.push_back(f);
    }
    if (e.consistency.dof > 0 && e.consistency.p_value < kLevelDriftP) {
        Flag f(FlagCode::LevelDrift);
        f.value = e.consistency.chi2;
        f.dof = e.consistency.dof;
        f.p_value = e.consistency.p_value;
        f.threshold = kLevelDriftP;
        flags.push_back(f);
    }
    // A bias that dominates the MSE from some N on: the MSE stops falling with the variance.
    size_t first = e.levels.size();
    while (first > 0) {
        const LevelStats& l = e.levels[first - 1];
        const bool dominated = l.has_exact && !l.exact_to_roundoff && std::isfinite(l.bias) &&
                               std::isfinite(l.variance) && l.bias * l.bias > l.variance &&
                               std::fabs(l.bias) > 3.0 * l.std_error;
        if (!dominated) break;
        --first;
    }
    // Under an infinite variance (heavy_tail as a warning) the replicates' mean of an unbiased
    // estimator falls short of the integral too: the rare huge weights that make up the rest
    // are missed by most runs. Without a known source of bias (mass the pdf misses, dropped
    // samples) that shortfall is the heavy tail's, which heavy_tail reports: no bias_dominates.
    const bool infinite_variance = std::any_of(flags.begin(), flags.end(), [](const Flag& f) {
        return f.code == FlagCode::HeavyTail && f.severity == Severity::Warning;
    });
    if (first < e.levels.size() && !(infinite_variance && !known_bias_source(e))) {
        const LevelStats& deepest = e.levels.back();
        Flag f(FlagCode::BiasDominates);
        f.n = e.levels[first].n;
        f.value = deepest.bias;
        f.se = deepest.std_error;
        f.threshold = deepest.mse > 0.0 ? deepest.bias * deepest.bias / deepest.mse : 1.0;
        flags.push_back(f);
    }
    if (settings.accumulator == Accumulator::Float32) {
        flags.push_back(Flag(FlagCode::Float32Accumulator));
    }
    return flags;
}

} // namespace mcp
