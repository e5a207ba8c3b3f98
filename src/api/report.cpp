// Study results as JSON (docs/result-schema.md): integration and stopping studies, their levels,
// fits and warnings, and the progress records; the render API's levels start from
// level_to_json. The table and the CSV are rendered from this JSON (api/report_text.cpp).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "api/report.h"
#include "core/special.h"
#include "estimators/diagnostics.h"
#include "estimators/registry.h"
#include "estimators/stopping.h"

namespace mcp {

Json num(double x) {
    return std::isfinite(x) ? Json(x) : Json(nullptr);
}

// A warning: a stable code (for clients that filter or group), its severity and a sentence for
// people.
Json warning(const char* code, Severity severity, const std::string& message) {
    return Json{{"code", code}, {"severity", severity_name(severity)}, {"message", message}};
}

Json flag_warning(const Flag& flag, const std::string& message) {
    return warning(flag_code_name(flag.code), flag.severity, message);
}

void sort_by_severity(Json& warnings) {
    if (!warnings.is_array()) return;
    auto rank = [](const Json& w) {
        const auto it = w.find("severity");
        const std::string s = it != w.end() && it->is_string() ? it->get<std::string>() : "";
        return s == "error" ? 0 : s == "warning" ? 1 : 2;
    };
    std::stable_sort(warnings.begin(), warnings.end(),
                     [&](const Json& a, const Json& b) { return rank(a) < rank(b); });
}

std::string fmt(const char* f, double x) {
    if (!std::isfinite(x)) return "-";
    // A fixed-point conversion ("%.1f") of a number beyond 1e6 or below 1e-4 (not 0) is written
    // in scientific notation, "1.7e+51 standard errors", never 52 digits or "0.0".
    std::string format = f;
    const double magnitude = std::fabs(x);
    if (magnitude >= 1e6 || (magnitude > 0.0 && magnitude < 1e-4)) {
        const size_t percent = format.find('%');
        const size_t conversion = percent == std::string::npos
                                      ? std::string::npos
                                      : format.find_first_not_of("0123456789.-+ #", percent + 1);
        if (conversion != std::string::npos && format[conversion] == 'f') format[conversion] = 'e';
    }
    char buf[64];
    std::snprintf(buf, sizeof buf, format.c_str(), x);
    return buf;
}

namespace {

// NaN and infinities become null in the JSON.
Json diagnostics_to_json(const RunDiagnostics& d) {
    return Json{{"nonfinite", d.nonfinite},
                {"zero_pdf", d.zero_pdf},
                {"nonzero", d.nonzero},
                {"max_weight_share", num(d.max_weight_share)},
                {"weight_skewness", num(d.weights.skewness())},
                {"error_unit_skewness", num(d.error_units.skewness())}};
}

// Plain-language sentences for the flags the core raises (estimators/diagnostics.h).

// "2 of 32 (up to 3 is what honest 95% intervals give)".
std::string replicate_evidence(const Flag& f) {
    return std::to_string(f.replicate_misses) + " of " + std::to_string(f.replicates_judged) +
           " (up to " + std::to_string(f.miss_allowance) +
           " is what honest 95% intervals give), none far off";
}

Json level_warning(const Flag& f, const LevelStats& l) {
    const std::string at_n = " at N = " + std::to_string(l.n);
    switch (f.code) {
    case FlagCode::NoEstimate:
        return flag_warning(f, f.count == f.of
                                   ? std::string("every sample was NaN or infinite: no estimate")
                                   : "every sample was NaN or infinite in " +
                                         std::to_string(f.count) + " of " + std::to_string(f.of) +
                                         " replicates" + at_n + ": no estimate at this N");
    case FlagCode::NonfiniteEstimate:
        return flag_warning(f, "the mean of the replicates is not a finite number" + at_n +
                                   " (the sum of the weights overflowed): no estimate");
    case FlagCode::NonfiniteVariance:
        return flag_warning(f, "the variance across replicates is not a finite number >= 0" + at_n +
                                   ": no error bar");
    case FlagCode::ZeroErrorBar:
        return flag_warning(
            f, std::to_string(f.count) + " of " + std::to_string(f.of) +
                   " replicates reported a standard error of 0" + at_n +
                   " although the replicates differ (standard deviation " + fmt("%.3g", f.value) +
                   (std::isfinite(f.threshold)
                        ? ", from " + fmt("%.3g", f.threshold) + " to " + fmt("%.3g", f.se)
                        : std::string()) +
                   (l.values_underflow ? "): their error bars are wrong (the squares of values "
                                         "this small underflow: values_underflow)"
                                       : "): their error bars are wrong (too few samples to see "
                                         "f vary)"));
    case FlagCode::ErrorBarsUnderstate:
        if (f.count > 0) // Cochran's Q: each replicate in its own standard errors
            return flag_warning(
                f, "the " + std::to_string(f.count) + " replicates" + at_n + " lie " +
                       fmt("%.3g", std::sqrt(f.value)) + " times farther from " +
                       (l.has_exact ? "the exact value" : "their mean") +
                       " than their own standard errors say (chi-square " +
                       fmt("%.4g", f.value * f.dof) + " on " + std::to_string(f.dof) + " dof, " +
                       p_value_text(f.p_value) +
                       "): runs with small error bars scatter far beyond them, and the error "
                       "bars are too small");
        return flag_warning(f, "the " + std::to_string(f.of) + " replicates" + at_n + " spread " +
                                   fmt("%.3g", std::sqrt(f.value)) +
                                   " times more than their own standard errors say (F test, " +
                                   p_value_text(f.p_value) +
                                   "): the error bars are too small (too few strata, "
                                   "randomizations or points saw how f varies)");
    case FlagCode::NonfiniteSamples:
        return flag_warning(f, std::to_string(f.count) +
                                   " sample(s) with NaN/Inf f/p dropped: the estimate is biased");
    case FlagCode::ZeroPdfSamples:
        return flag_warning(f, std::to_string(f.count) +
                                   " sample(s) with f != 0 where p = 0: the pdf misses part of the "
                                   "integrand, the estimate is biased");
    case FlagCode::SkewedWeights: {
        // The units: the weights (count = N), or each run's K batch means (randomized QMC).
        const bool batches = f.dof > 0;
        const std::string skew = "(skewness " + fmt("%.3g", f.value) + " over all runs)" + at_n;
        const std::string rule =
            batches
                ? "the " + std::to_string(f.count) + " batch means of each run are skewed " + skew +
                      ", and a t error bar from them needs more than 25 x skewness^2 = " +
                      fmt("%.3g", f.threshold) + " of them (Cochran's rule)"
                : "the weights are skewed " + skew +
                      ", and a normal error bar needs N above 25 x skewness^2 = " +
                      fmt("%.3g", f.threshold) + " (Cochran's rule)";
        if (f.severity == Severity::Info && f.replicates_judged > 0 &&
            f.replicate_misses <= f.miss_allowance)
            return flag_warning(f, rule + "; but the replicates' own intervals missed " +
                                       replicate_evidence(f) +
                                       ": the error bars hold here, though the skew may show "
                                       "in some runs");
        if (f.severity == Severity::Info)
            return flag_warning(f, rule + ": the intervals may cover a few percent less than "
                                          "95% until then");
        const std::string spread =
            std::isfinite(f.se) && f.se > kErrorBarSpread
                ? "; the runs' error bars differ by a factor " + fmt("%.2g", f.se)
                : std::string();
        const std::string why =
            batches ? "a run whose randomizations missed a rare feature has an estimate and an "
                      "error bar both too small"
                    : "runs that missed the rare large weights have estimates and error bars "
                      "both too small";
        return flag_warning(f, rule + spread + ": " + why +
                                   ", so the error bar is not trustworthy at this N");
    }
    case FlagCode::ConservativeErrorBars:
        return flag_warning(f, "conservative error bars" + at_n + ": the " + std::to_string(f.of) +
                                   " replicates spread " + fmt("%.3g", f.value) +
                                   " times less than their own error bars say (F test, " +
                                   p_value_text(f.p_value) +
                                   "): the intervals cover, and are wider than they need be");
    case FlagCode::ErrorBarsUnstable:
        if (f.severity == Severity::Info)
            return flag_warning(f, "the replicates' own error bars differ by a factor " +
                                       fmt("%.3g", f.value) + at_n + " (Bartlett's test, " +
                                       p_value_text(f.p_value) +
                                       ", which assumes normal data), but their intervals "
                                       "missed " +
                                       replicate_evidence(f) +
                                       ": the error bars vary from run to run and still hold");
        return flag_warning(f, "the replicates' own error bars differ by a factor " +
                                   fmt("%.3g", f.value) + at_n + " (Bartlett's test, " +
                                   p_value_text(f.p_value) +
                                   "): some runs saw a feature (a sliver of a step, a rare peak) "
                                   "that others missed, and those others' error bars are far too "
                                   "small");
    case FlagCode::LowEss:
        return flag_warning(f, "effective sample size " + fmt("%.1f", f.value) + " of " +
                                   std::to_string(l.n) + at_n +
                                   ": the estimate rests on a few samples (narrow peak, small "
                                   "support or huge weights), its error bar is unreliable");
    case FlagCode::ValuesUnderflow:
        return flag_warning(f, "the estimates are about " + fmt("%.3g", f.value) + at_n +
                                   ", below " + fmt("%.0e", f.threshold) +
                                   ": their squares underflow double precision, so variances "
                                   "and error bars computed from them are 0 or wrong (scale the "
                                   "integrand up)");
    case FlagCode::ReplicateFarOff:
        if (std::isfinite(f.skewness))
            return flag_warning(
                f, "replicate " + std::to_string(f.dof + 1) + " of " + std::to_string(f.of) +
                       " lies " + fmt("%.1f", f.value) +
                       " of its own standard errors from the other replicates' mean" + at_n +
                       " (beyond " + fmt("%.1f", f.threshold) +
                       ") on the side toward which the replicates' deviations in their own error "
                       "bars skew (skewness " +
                       fmt("%.2f", f.skewness) + ", beyond " + fmt("%.1f", kSkewSignature) +
                       "): skewed weights give the runs that miss the rare large ones both " +
                       (f.skewness < 0.0 ? "a low" : "a high") +
                       " estimate and a small error bar, so the error bars understate the error "
                       "on that side");
        return flag_warning(
            f, "replicate " + std::to_string(f.dof + 1) + " of " + std::to_string(f.of) +
                   (f.replicates_judged < int(f.of)
                        ? " (" + std::to_string(f.replicates_judged) + " of the " +
                              std::to_string(f.of) + " had an error bar to judge)"
                        : std::string()) +
                   " lies " + fmt("%.1f", f.value) + " of its own standard errors from " +
                   (f.se > 0.0 ? "the exact value" : "the other replicates' mean") + at_n +
                   " (beyond " + fmt("%.1f", f.threshold) +
                   ", 5 standard errors widened for its degrees of freedom" +
                   (f.count > 1 ? "; " + std::to_string(f.count) + " such" : "") +
                   "): its error bar is far too small, and any one run's may be");
    case FlagCode::ExactOutsideCi:
        return flag_warning(
            f, "the mean of " + std::to_string(f.of) + " replicates misses the exact value by " +
                   (std::isfinite(f.value) ? fmt("%.1f", f.value) + " standard errors"
                                           : std::string("a margin with zero spread")) +
                   at_n + ": the estimator is biased or its error bars are wrong");
    case FlagCode::IterationsDisagree:
        return flag_warning(f, "the iterations of the runs disagree beyond their error bars" +
                                   at_n + " (chi2 = " + fmt("%.1f", f.value) + " for " +
                                   std::to_string(f.dof) + " degrees of freedom over " +
                                   std::to_string(f.of) + " replicates, " +
                                   p_value_text(f.p_value) +
                                   "): the weighted average and its error bar are not "
                                   "trustworthy (the map was still changing, or the integrand "
                                   "has a feature the iterations saw differently)");
    default: return flag_warning(f, "");
    }
}

Json warnings_for(const LevelStats& l) {
    Json w = Json::array();
    for (const Flag& f : level_flags(l)) w.push_back(level_warning(f, l));
    sort_by_severity(w);
    return w;
}

} // namespace

Json tail_warning(const Flag& f, uint64_t pooled, const TailWording& words) {
    if (f.of > 0) { // the integrand's tail at uniform probes (tail_flags)
        const std::string where = " (from the " + std::to_string(f.count) + " largest of |f| at " +
                                  std::to_string(f.of) +
                                  " uniform points; the sampling density is bounded above and "
                                  "below, so the weights' variance is finite where int f^2 is)";
        if (f.code == FlagCode::HeavyTail && f.severity == Severity::Info)
            return flag_warning(f, "f looks heavy-tailed: tail index " + fmt("%.2f", f.value) +
                                       " +/- " + fmt("%.2f", f.se) + where +
                                       ", but f's form makes int f^2 finite (bounded, or every "
                                       "power above -1/2), so the variance is finite: a slowly "
                                       "varying tail that Hill's index reads too heavy");
        if (f.code == FlagCode::HeavyTail)
            return flag_warning(f, "f is heavy-tailed: tail index " + fmt("%.2f", f.value) +
                                       " +/- " + fmt("%.2f", f.se) + where +
                                       ", and below 2 the variance is infinite: the error bars "
                                       "are not trustworthy");
        return flag_warning(f, "f has a heavy tail: tail index " + fmt("%.2f", f.value) + where +
                                   " is below 4, so the variance is finite but its estimate is "
                                   "unreliable and the error bars may be too small");
    }
    const std::string where = " (from the " + std::to_string(f.count) + " largest of " +
                              std::to_string(pooled) + " " + words.unit + " at " + words.n_name +
                              " = " + std::to_string(f.n) + ")";
    if (f.code == FlagCode::HeavyTail && f.severity == Severity::Info)
        return flag_warning(
            f, std::string(words.what) + " look heavy-tailed: tail index " + fmt("%.2f", f.value) +
                   " +/- " + fmt("%.2f", f.se) + where + ", but they are bounded (" +
                   (words.bounded_why ? std::string(words.bounded_why)
                                      : "f bounded, the density bounded below") +
                   "), so every moment is finite: a pre-asymptotic tail that fades as " +
                   words.n_name + " grows" +
                   (words.bounded_why ? ""
                                      : " (skewed_weights says from which N the error bars "
                                        "hold)"));
    if (f.code == FlagCode::HeavyTail)
        return flag_warning(f, std::string(words.what) + " are heavy-tailed: tail index " +
                                   fmt("%.2f", f.value) + " +/- " + fmt("%.2f", f.se) + where +
                                   ", and below 2 " + words.variance +
                                   " is infinite: the error bars are not trustworthy");
    return flag_warning(f, std::string(words.what) + " have a heavy tail: tail index " +
                               fmt("%.2f", f.value) + where + " is below 4, so " + words.variance +
                               " is finite but its estimate is unreliable and the error "
                               "bars may be too small");
}

void add_tail_warnings(Json& w, const LevelStats& deepest, uint64_t pooled,
                       const TailWording& words, bool bounded, const IntegrandTail* integrand) {
    for (const Flag& f : tail_flags(deepest, bounded, integrand))
        w.push_back(tail_warning(f, pooled, words));
}

namespace {

Json estimator_warnings(const EstimatorStudy& e, const StudySettings& s) {
    Json w = Json::array();
    if (!e.levels.empty()) {
        const LevelStats& deepest = e.levels.back();
        add_tail_warnings(w, deepest, deepest.n * static_cast<uint64_t>(deepest.reps),
                          TailWording{"the weights f/p", "weights", "N", "the variance"},
                          e.weights_bounded, e.integrand.k > 0 ? &e.integrand : nullptr);
    }
    const SupportCheck& sc = e.support;
    for (const Flag& f : estimator_flags(e, s)) {
        switch (f.code) {
        case FlagCode::PdfSupport:
            if (sc.method == "quadrature")
                w.push_back(flag_warning(
                    f, std::isfinite(sc.missed_mass)
                           ? "the pdf is zero on " + fmt("%.3g", 100.0 * sc.zero_measure) +
                                 "% of the domain, where the integral of |f| is " +
                                 fmt("%.6g", sc.missed_mass) + " (" +
                                 fmt("%.3g", 100.0 * sc.missed_fraction) +
                                 "% of the integral of |f|, by quadrature): the estimator "
                                 "never samples there and is biased"
                           : "the pdf is zero on " + fmt("%.3g", 100.0 * sc.zero_measure) +
                                 "% of the domain, where |f| is not finite or not "
                                 "integrable: the estimator never samples there and is "
                                 "biased"));
            else
                w.push_back(flag_warning(f, "the pdf is zero at " + std::to_string(sc.missed) +
                                                " of " + std::to_string(sc.f_nonzero) +
                                                " probe points where f != 0 (" +
                                                fmt("%.3g", 100.0 * sc.missed_fraction) +
                                                "% of |f|): the estimator never samples there and "
                                                "is biased"));
            break;
        case FlagCode::LevelDrift:
            w.push_back(
                flag_warning(f, "the means at different N disagree beyond their error bars "
                                "(chi2 = " +
                                    fmt("%.1f", f.value) + " for " + std::to_string(f.dof) +
                                    " degrees of freedom, " + p_value_text(f.p_value) +
                                    "): the error bars understate the error (heavy tails, too "
                                    "few samples, or bias)"));
            break;
        case FlagCode::BiasDominates:
            w.push_back(flag_warning(
                f, "from N = " + std::to_string(f.n) + " on the bias (" + fmt("%.3g", f.value) +
                       " at the largest N, " + fmt("%.0f", 100.0 * f.threshold) +
                       "% of the MSE) is larger than the spread of an estimate: the MSE stops "
                       "falling with N, and its fitted order describes the bias, not the "
                       "estimator's variance"));
            break;
        case FlagCode::Float32Accumulator:
            w.push_back(flag_warning(f, "float32 accumulation (teaching mode): the estimates are "
                                        "naive single-precision sums and stall or drift at large "
                                        "N"));
            break;
        default: break; // the tail flags are worded above
        }
    }
    sort_by_severity(w);
    return w;
}

} // namespace

Json level_to_json(const LevelStats& l) {
    Json j{{"n", l.n},
           {"reps", l.reps},
           {"measure", level_measure_name(l.measure)},
           {"mean", num(l.mean)},
           {"variance", num(l.variance)},
           {"variance_ci95", {num(l.variance_lo), num(l.variance_hi)}},
           {"std_error", num(l.std_error)},
           {"ci95", {num(l.ci_lo), num(l.ci_hi)}},
           {"mean_run_std_error", num(l.mean_run_se)},
           // The runs' 95% intervals are estimate +- t std_error, t the Student quantile with
           // this many degrees of freedom (0: no error bar).
           {"run_dof", l.run_dof},
           {"time_mean_s", num(l.time_mean)},
           {"time_std_s", num(l.time_std)}, // over the replicates: the timing's own noise
           {"time_total_s", num(l.time_total)},
           // Adaptive estimators: the share of the calls and the seconds per estimate spent
           // training or probing (in n and time_mean_s too; 0 for fixed estimators).
           {"training_share", num(l.training_share)},
           {"training_time_mean_s", num(l.training_time_mean)},
           {"efficiency", num(l.efficiency)},
           {"error", num(l.error)},
           {"diagnostics", diagnostics_to_json(l.diagnostics)},
           {"tail_index", num(l.tail_index)},
           {"tail_k", l.tail_k},
           {"nonzero_per_run", num(l.nonzero_per_run)},
           {"ess", num(l.ess_mean)},
           {"no_estimate_runs", l.no_estimate_runs},
           {"zero_error_runs", l.zero_error_runs},
           {"deterministic", l.deterministic},
           {"values_underflow", l.values_underflow},
           {"exact_to_roundoff", l.exact_to_roundoff},
           {"warnings", warnings_for(l)}};
    // A variance below 0 is not a variance: null, like NaN (warnings_for flags both).
    if (!(l.variance >= 0.0)) j["variance"] = j["variance_ci95"] = j["std_error"] = nullptr;
    if (l.has_exact) {
        j["bias"] = num(l.bias);
        j["mse"] = num(l.mse);
        j["rmse"] = num(l.rmse);
        j["coverage95"] = num(l.coverage);
    } else {
        j["bias"] = j["mse"] = j["rmse"] = j["coverage95"] = nullptr;
    }
    // Iteration averages (VEGAS "report": "iterations"): the pooled consistency of iterations.
    if (l.iteration_dof > 0)
        j["iterations"] = {{"chi2", num(l.iteration_chi2)},
                           {"dof", l.iteration_dof},
                           {"p_value", num(chi_square_sf(l.iteration_chi2, l.iteration_dof))}};
    Json est = Json::array(), se = Json::array();
    for (double x : l.estimates) est.push_back(num(x));
    for (double x : l.run_std_errors) se.push_back(num(x));
    j["replicates"] = Json{{"estimate", est}, {"std_error", se}};
    // The median time per estimate (per image in a render study) and its interval: robust to
    // the replicate a busy machine delayed.
    j["time_median_s"] = num(l.time_median);
    j["time_median_ci95_s"] = {num(l.time_median_lo), num(l.time_median_hi)};
    return j;
}

Json fit_to_json(const ConvergenceFit& f) {
    Json suffix(nullptr);
    if (f.suffix) {
        const PowerLawSegment& s = *f.suffix;
        suffix = Json{{"order", num(s.order)},
                      {"order_se", num(s.order_se)},
                      {"intercept", num(s.intercept)},
                      {"levels_used", s.levels_used},
                      {"chi2", num(s.chi2)},
                      {"dof", s.dof},
                      {"p_value", num(s.p_value)},
                      {"n_first", s.n_first},
                      {"n_last", s.n_last}};
    }
    const Json none(nullptr);
    return Json{{"valid", f.valid},
                {"measure", level_measure_name(f.measure)},
                {"order", f.valid ? num(f.order) : none},
                {"order_se", f.valid ? num(f.order_se) : none},
                {"intercept", f.valid ? num(f.intercept) : none},
                {"levels_used", f.levels_used},
                {"note", f.note},
                {"chi2", f.valid ? num(f.chi2) : none},
                {"dof", f.valid ? Json(f.dof) : none},
                {"p_value", f.valid ? num(f.p_value) : none},
                {"n_first", f.valid ? Json(f.n_first) : none},
                {"n_last", f.valid ? Json(f.n_last) : none},
                {"suffix", suffix}};
}

namespace {

Json estimator_header(const EstimatorStudy& e, const StudySettings& s, const Domain& domain) {
    const PointWords words = point_words(e.spec); // the estimator's words for its points
    return Json{
        {"name", e.spec.name},
        {"kind", kind_of(e.spec).name},
        {"method", estimator_method(e.spec)},
        {"sampler", words.sampler},
        {"samples_per_stratum", e.spec.per_stratum},
        {"pdf", describe_sampling(e.spec)},
        {"pdf_text", describe_sampling_text(e.spec, domain)},
        {"importance", e.spec.proposal.importance || e.spec.has_techniques()},
        {"randomization", words.randomization ? Json(words.randomization) : Json(nullptr)},
        {"randomizations", words.randomizations ? Json(words.randomizations) : Json(nullptr)},
        {"error_method", error_method_name(e.error_method)},
        // Error bars wider than the estimator's spread by design: coverage above 95% is no fault.
        {"error_bars_conservative", error_method_conservative(e.error_method)},
        {"support_check",
         {{"probes", e.support.probes},
          {"f_nonzero", e.support.f_nonzero},
          {"missed", e.support.missed},
          {"missed_fraction", num(e.support.missed_fraction)},
          {"method", e.support.method},
          {"zero_measure", num(e.support.zero_measure)},
          {"missed_mass",
           e.support.method == "quadrature" ? num(e.support.missed_mass) : Json(nullptr)},
          {"abs_integral", num(e.support.abs_integral)},
          {"tolerance", kSupportTolerance},
          {"quadrature_evaluations", e.support.quadrature_evaluations},
          {"flagged", e.support.flagged},
          {"note", e.support.note}}},
        {"consistency",
         {{"chi2", num(e.consistency.chi2)},
          {"dof", e.consistency.dof},
          {"p_value", num(e.consistency.p_value)}}},
        {"warnings", estimator_warnings(e, s)}};
}

} // namespace

namespace {
Json scene_to_json(const Problem& p) {
    return Json{{"name", p.name},
                {"description", p.description},
                {"domain", domain_kind_name(p.domain.kind)},
                {"domain_text", p.domain.describe()},
                {"dimension", p.domain.point_dim()},
                {"integrand", describe_integrand(p.integrand)},
                {"quantity", p.quantity == Quantity::Mean ? "mean" : "integral"},
                {"exact", p.exact ? num(*p.exact) : Json(nullptr)}};
}

double median_of(std::vector<double> v) {
    if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
    std::sort(v.begin(), v.end());
    const size_t m = v.size() / 2;
    return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}
} // namespace

Json stopping_to_json(const StoppingStudy& st) {
    const Problem& p = st.problem;
    const StudySettings& set = st.settings;
    Json estimators = Json::array();
    for (size_t e = 0; e < st.specs.size(); ++e) {
        EstimatorStudy header;
        header.spec = st.specs[e];
        header.error_method = error_method_for(st.specs[e]);
        Json j = estimator_header(header, set, p.domain);
        Json runs = Json::array();
        std::vector<double> seconds, evaluations;
        int met = 0, within = 0;
        std::map<std::string, int> unmet;
        for (const StoppingResult& r : st.runs[e]) {
            Json steps = Json::array();
            for (const StoppingStep& s : r.steps)
                steps.push_back({{"n", s.n},
                                 {"estimate", num(s.estimate)},
                                 {"std_error", num(s.std_error)},
                                 {"half_width", num(s.half_width)},
                                 {"dof", s.dof},
                                 {"trusted", s.trusted},
                                 {"agrees", s.agrees},
                                 {"flagged", s.flagged}});
            Json flags = Json::array();
            for (const Flag& f : r.flags)
                flags.push_back({{"code", flag_code_name(f.code)},
                                 {"severity", severity_name(f.severity)},
                                 {"value", num(f.value)},
                                 {"threshold", num(f.threshold)}});
            Json run{{"estimate", num(r.answer.estimate)},
                     {"std_error", num(r.answer.std_error)},
                     {"half_width", num(r.half_width)},
                     {"target", num(r.target)},
                     {"met", r.met},
                     {"reason", stop_reason_name(r.reason)},
                     {"n", r.answer.n},
                     {"evaluations", r.evaluations},
                     {"extended", r.extended},
                     {"flags", flags},
                     {"seconds", num(r.seconds)},
                     {"steps", steps}};
            if (p.exact) {
                const double tol = std::fmax(set.abs_tol, set.rel_tol * std::fabs(*p.exact));
                const bool in = std::fabs(r.answer.estimate - *p.exact) <= tol;
                run["within_tolerance"] = in;
                within += in;
            }
            met += r.met;
            if (!r.met) ++unmet[stop_reason_name(r.reason)];
            seconds.push_back(r.seconds);
            evaluations.push_back(static_cast<double>(r.evaluations));
            runs.push_back(run);
        }
        j["runs"] = runs;
        j["met"] = met;
        j["within_tolerance"] = p.exact ? Json(within) : Json(nullptr);
        j["evaluations_median"] = num(median_of(evaluations));
        j["seconds_median"] = num(median_of(seconds));
        j["seconds_min"] = seconds.empty() ? Json(nullptr)
                                           : num(*std::min_element(seconds.begin(), seconds.end()));
        j["seconds_max"] = seconds.empty() ? Json(nullptr)
                                           : num(*std::max_element(seconds.begin(), seconds.end()));
        Json warnings = Json::array();
        for (const auto& [reason, count] : unmet) {
            const std::string why =
                reason == "no_error_bar"
                    ? "the estimator has no error bar (a point set without randomization), so "
                      "no tolerance can be judged"
                : reason == "untrusted_error_bar"
                    ? "their error bars met it, but a flag (heavy tail, skewed or few weights) "
                      "or disagreement with earlier doublings said they cannot be trusted"
                : reason == "all_zero"
                    ? "every point of two doublings in a row gave f = 0, so the estimate is 0 "
                      "+- 0: a relative tolerance of a 0 estimate is 0 and cannot be met, and "
                      "points alone cannot show f = 0 where none fell (doubling on would "
                      "only repeat it; an absolute tolerance does not make 0 +- 0 evidence)"
                : reason == "n_max"
                    ? "n_max = " + std::to_string(set.n_max) + " was reached first"
                    : "the time budget (max_seconds = " + fmt("%.3g", set.max_seconds) +
                          ") ended first";
            warnings.push_back(Json{
                {"code", "tolerance_not_met"},
                {"severity",
                 reason == "no_error_bar" || reason == "untrusted_error_bar" ? "error" : "warning"},
                {"message", std::to_string(count) + " of " + std::to_string(st.runs[e].size()) +
                                " runs did not meet the tolerance: " + why}});
        }
        j["warnings"] = warnings;
        estimators.push_back(j);
    }
    Json settings{
        {"n_min", set.n_min},
        {"n_max", set.n_max},
        {"reps", set.reps},
        {"seed", set.seed},
        {"accumulator", set.accumulator == Accumulator::Float32 ? "float32" : "compensated"},
        {"threads", 1}};
    return Json{
        {"version", kResultSchemaVersion},
        {"mcplay", MCPLAY_VERSION},
        {"kind", "stopping"},
        {"scene", scene_to_json(p)},
        {"settings", settings},
        {"stopping",
         {{"rel_tol", num(set.rel_tol)},
          {"abs_tol", num(set.abs_tol)},
          {"max_seconds", set.max_seconds > 0.0 ? num(set.max_seconds) : Json(nullptr)},
          {"rule", "95% half-width <= max(abs_tol, rel_tol |estimate|) at N, trusted (N > 25 "
                   "skewness^2, ESS, no warning or error flag), agreeing with N/2: randomized QMC "
                   "extends its K sequences (t interval of the K batch means, paired N/2 check, "
                   "skewness of the batch means), one Sobol' sequence with the Walsh bound "
                   "extends it (the bound meets the tolerance, the last four doublings' bounds "
                   "hold the answer, N > 25 skewness^2, ESS), others run each N afresh with the "
                   "run at N/2 predicting the tolerance"}}},
        {"wall_time_s", num(st.wall_seconds)},
        {"estimators", estimators}};
}

Json study_to_json(const StudyResult& r) {
    const Problem& p = r.problem;
    Json scene = scene_to_json(p);
    Json settings{
        {"n_min", r.settings.n_min},
        {"n_max", r.settings.n_max},
        {"reps", r.settings.reps},
        {"seed", r.settings.seed},
        {"accumulator", r.settings.accumulator == Accumulator::Float32 ? "float32" : "compensated"},
        {"threads", r.threads_used}};
    Json estimators = Json::array();
    for (const EstimatorStudy& e : r.estimators) {
        Json j = estimator_header(e, r.settings, p.domain);
        Json levels = Json::array();
        for (const LevelStats& l : e.levels) levels.push_back(level_to_json(l));
        j["levels"] = levels;
        j["fit"] = fit_to_json(e.fit);
        j["mse_fit"] = fit_to_json(e.mse_fit);
        estimators.push_back(j);
    }
    return Json{{"version", kResultSchemaVersion},
                {"mcplay", MCPLAY_VERSION},
                {"scene", scene},
                {"settings", settings},
                {"cancelled", r.cancelled},
                {"wall_time_s", num(r.wall_seconds)},
                {"estimators", estimators}};
}

Json progress_to_json(const StudyResult& partial, size_t level_index) {
    Json estimators = Json::array();
    uint64_t n = 0;
    for (const EstimatorStudy& e : partial.estimators) {
        Json j = estimator_header(e, partial.settings, partial.problem.domain);
        if (level_index < e.levels.size()) {
            j["level"] = level_to_json(e.levels[level_index]);
            n = e.levels[level_index].n;
        }
        j["fit"] = fit_to_json(e.fit);
        j["mse_fit"] = fit_to_json(e.mse_fit);
        estimators.push_back(j);
    }
    return Json{{"version", kResultSchemaVersion},
                {"level_index", level_index},
                {"n", n},
                {"estimators", estimators}};
}

} // namespace mcp
