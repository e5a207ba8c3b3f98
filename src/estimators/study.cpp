#include "estimators/study.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include "core/quadrature.h"
#include "core/special.h"

#include "core/parallel.h"
#include "estimators/registry.h"

namespace mcp {

namespace {
constexpr uint64_t kMaxN = uint64_t(1) << 36;
constexpr int kMaxReps = 100000;
constexpr int kMaxThreads = 256;
constexpr uint64_t kSupportProbes = 1 << 16;
} // namespace

namespace {

struct Span {
    double a, b;
};

// Integer with thousands separators, for notes ("65,536").
std::string count_text(uint64_t n) {
    std::string d = std::to_string(n), out;
    for (size_t i = 0; i < d.size(); ++i) {
        if (i && (d.size() - i) % 3 == 0) out += ',';
        out += d[i];
    }
    return out;
}

std::string g_text(double x, const char* f = "%.3g") {
    char buf[64];
    std::snprintf(buf, sizeof buf, f, x);
    return buf;
}

// Where a 1D density is zero on [a, b], as disjoint sorted intervals. Tabulated: exactly its
// zero bins (the density is read at each bin's centre). Analytic kinds are unimodal, so their
// zero set (where the density underflows, or a single end point) is found on a grid of 4096
// cells whose transitions are then bisected to the last double.
std::vector<Span> zero_spans(const Distribution1D& d) {
    const double a = d.lower(), b = d.upper();
    const size_t bins = d.kind() == Dist1DKind::Tabulated ? d.bins() : 0;
    const size_t cells = bins ? bins : 4096;
    auto edge = [&](size_t i) {
        return i == cells ? b : a + (b - a) * (static_cast<double>(i) / static_cast<double>(cells));
    };
    std::vector<char> zero(cells);
    double mid[kBlockSize], dens[kBlockSize];
    for (size_t first = 0; first < cells; first += kBlockSize) {
        const size_t m = std::min<size_t>(kBlockSize, cells - first);
        for (size_t i = 0; i < m; ++i) {
            mid[i] = 0.5 * edge(first + i) + 0.5 * edge(first + i + 1);
            dens[i] = 1.0;
        }
        d.multiply_pdf_block(mid, dens, m);
        for (size_t i = 0; i < m; ++i) zero[first + i] = !(dens[i] > 0.0);
    }
    // Bisects [lo, hi] (density zero at `zero_end`, positive at the other end) to the edge.
    auto bisect = [&](double lo, double hi, bool zero_at_hi) {
        for (int it = 0; it < 200; ++it) {
            const double m = 0.5 * lo + 0.5 * hi;
            if (!(m > lo && m < hi)) break;
            const bool z = !(d.pdf(m) > 0.0);
            if (z == zero_at_hi)
                hi = m;
            else
                lo = m;
        }
        return zero_at_hi ? hi : lo;
    };
    std::vector<Span> spans;
    for (size_t i = 0; i < cells;) {
        if (!zero[i]) {
            ++i;
            continue;
        }
        size_t j = i;
        while (j < cells && zero[j]) ++j;
        double lo = edge(i), hi = edge(j);
        if (!bins) { // analytic: the edges of the zero run lie between cell centres
            const double c = [&](size_t k) { return 0.5 * edge(k) + 0.5 * edge(k + 1); }(i);
            if (i > 0) lo = bisect(0.5 * edge(i - 1) + 0.5 * edge(i), c, true);
            const double c2 = 0.5 * edge(j - 1) + 0.5 * edge(j);
            if (j < cells) hi = bisect(c2, 0.5 * edge(j) + 0.5 * edge(j + 1), false);
        }
        if (hi > lo) spans.push_back({lo, hi});
        i = j;
    }
    return spans;
}

double spans_length(const std::vector<Span>& spans) {
    double total = 0.0;
    for (const Span& s : spans) total += s.b - s.a;
    return total;
}

// [lo, hi] minus the spans (sorted, disjoint, inside [lo, hi]).
std::vector<Span> complement(const std::vector<Span>& spans, double lo, double hi) {
    std::vector<Span> out;
    double at = lo;
    for (const Span& s : spans) {
        if (s.a > at) out.push_back({at, s.a});
        at = s.b;
    }
    if (hi > at) out.push_back({at, hi});
    return out;
}

struct Rect {
    Span x, y;
};

// The quadrature's evaluations are capped so that the check stays a small part of a study.
constexpr int kSupportQuadratureBudget = 1 << 22;

struct Budget {
    int used = 0;
    bool exceeded = false;
};

// int_a^b g by adaptive Gauss-Kronrod [Piessens83] on pieces: `uniform` equal pieces, the two
// end pieces cut geometrically `levels` times toward a and b (widths h 2^-k), so that a feature
// touching an end of the interval (a table's zero bin next to where f lives) is seen at its own
// scale instead of falling between the nodes of one rule. NaN when the budget is exceeded;
// non-finite when g is.
double integrate_graded(const std::function<double(double)>& g, double a, double b, int uniform,
                        int levels, Budget& budget) {
    std::vector<double> t{0.0};
    const double h = 1.0 / uniform;
    for (int k = levels; k >= 1; --k) t.push_back(std::ldexp(h, -k));
    for (int j = 1; j < uniform; ++j) t.push_back(j * h);
    for (int k = 1; k <= levels; ++k) t.push_back(1.0 - std::ldexp(h, -k));
    t.push_back(1.0);
    NeumaierSum sum;
    double x0 = a;
    for (size_t i = 1; i < t.size(); ++i) {
        const double x1 = i + 1 == t.size() ? b : a + (b - a) * t[i];
        if (!(x1 > x0)) continue;
        if (budget.used > kSupportQuadratureBudget) {
            budget.exceeded = true;
            return std::numeric_limits<double>::quiet_NaN();
        }
        const QuadratureResult r = integrate_adaptive(g, x0, x1, 1e-6, 0.0, 64);
        budget.used += r.evaluations;
        if (!std::isfinite(r.value)) return r.value;
        sum.add(r.value);
        x0 = x1;
    }
    return sum.value();
}

// int over a rectangle (a 1D span when dim = 1) of |f|: nested graded quadrature in 2D.
double integrate_abs(const Integrand& f, int dim, const Rect& r, Budget& budget) {
    if (dim == 1) {
        auto g = [&](double x) { return std::fabs(evaluate_point(f, &x)); };
        return integrate_graded(g, r.x.a, r.x.b, 16, 40, budget);
    }
    auto outer = [&](double y) {
        if (budget.exceeded) return 0.0;
        auto inner = [&](double x) {
            const double p[2] = {x, y};
            return std::fabs(evaluate_point(f, p));
        };
        const double v = integrate_graded(inner, r.x.a, r.x.b, 4, 16, budget);
        return budget.exceeded ? 0.0 : v;
    };
    const double v = integrate_graded(outer, r.y.a, r.y.b, 4, 16, budget);
    return budget.exceeded ? std::numeric_limits<double>::quiet_NaN() : v;
}

// The zero set of the proposal as rectangles of a 1D or 2D box, and its share of the domain's
// measure. False when it is not known in that form.
bool zero_set(const Proposal& p, const Domain& d, std::vector<Rect>* rects, double* share,
              std::string* why_not) {
    rects->clear();
    *share = 0.0;
    if (p.kind == ProposalKind::CosineHemisphere) return true; // zero only on z = 0 (null set)
    if (p.kind == ProposalKind::Product1D) {
        const size_t dim = p.marginals.size();
        std::vector<std::vector<Span>> z(dim);
        double positive = 1.0;
        for (size_t j = 0; j < dim; ++j) {
            z[j] = zero_spans(p.marginals[j]);
            positive *= 1.0 - spans_length(z[j]) / (d.hi[j] - d.lo[j]);
        }
        *share = 1.0 - positive;
        if (*share == 0.0) return true;
        if (dim == 1) {
            for (const Span& s : z[0]) rects->push_back({s, {0.0, 0.0}});
            return true;
        }
        if (dim == 2) { // Z0 x [lo1, hi1], then (not Z0) x Z1: disjoint
            for (const Span& s : z[0]) rects->push_back({s, {d.lo[1], d.hi[1]}});
            for (const Span& s : complement(z[0], d.lo[0], d.hi[0]))
                for (const Span& t : z[1]) rects->push_back({s, t});
            return true;
        }
        *why_not = "the zero set of a product pdf in " + std::to_string(dim) +
                   " dimensions is not integrated";
        return false;
    }
    if (p.kind == ProposalKind::Tabulated2D) {
        const TabulatedDistribution2D& t = p.table;
        const int nx = t.nx(), ny = t.ny();
        auto ex = [&](int i) { return i == nx ? t.x1() : t.x0() + (t.x1() - t.x0()) * i / nx; };
        auto ey = [&](int i) { return i == ny ? t.y1() : t.y0() + (t.y1() - t.y0()) * i / ny; };
        // Runs of zero cells per row; a run repeated on the next row extends its rectangle.
        struct Open {
            int ix0, ix1, iy0, iy1;
        };
        std::vector<Open> open, done;
        size_t zero_cells = 0;
        for (int iy = 0; iy < ny; ++iy) {
            const double yc = 0.5 * ey(iy) + 0.5 * ey(iy + 1);
            std::vector<Open> next;
            for (int ix = 0; ix < nx;) {
                if (t.pdf(0.5 * ex(ix) + 0.5 * ex(ix + 1), yc) > 0.0) {
                    ++ix;
                    continue;
                }
                int jx = ix;
                while (jx < nx && !(t.pdf(0.5 * ex(jx) + 0.5 * ex(jx + 1), yc) > 0.0)) ++jx;
                zero_cells += static_cast<size_t>(jx - ix);
                Open run{ix, jx, iy, iy + 1};
                for (Open& o : open)
                    if (o.ix0 == ix && o.ix1 == jx && o.iy1 == iy) {
                        run.iy0 = o.iy0;
                        o.ix0 = -1; // taken over
                    }
                next.push_back(run);
                ix = jx;
            }
            for (const Open& o : open)
                if (o.ix0 >= 0) done.push_back(o);
            open = next;
        }
        done.insert(done.end(), open.begin(), open.end());
        for (const Open& o : done)
            rects->push_back({{ex(o.ix0), ex(o.ix1)}, {ey(o.iy0), ey(o.iy1)}});
        *share = static_cast<double>(zero_cells) / (static_cast<double>(nx) * ny);
        return true;
    }
    *why_not = std::string("the zero set of pdf '") + proposal_kind_name(p.kind) +
               "' is not known in closed form";
    return false;
}

} // namespace

IntegrandTail integrand_tail(const Problem& problem, uint64_t probes, uint64_t seed) {
    IntegrandTail tail;
    tail.probes = probes;
    const Domain& d = problem.domain;
    if (d.kind == DomainKind::Box)
        tail.square_integrable = integrand_square_integrable(problem.integrand, d.lo, d.hi);
    Pcg32 rng(mix64(seed ^ 0x7461696cULL), hash_string("integrand_tail")); // "tail"
    const SamplerPlan plan =
        make_sampler_plan(SamplerKind::Independent, d.sample_dim(), probes, rng);
    std::vector<double> values;
    values.reserve(static_cast<size_t>(probes));
    Workspace ws;
    for_each_block(problem, uniform_proposal(d), plan, ws, [&](const SampleBlock& b) {
        for (size_t i = 0; i < b.count; ++i) {
            const double a = std::fabs(b.f[i]);
            if (std::isfinite(a)) values.push_back(a);
        }
    });
    const int k = tail_order(probes);
    if (k <= 0 || values.size() < static_cast<size_t>(k) + 1) return tail;
    std::nth_element(values.begin(), values.begin() + k, values.end(), std::greater<double>());
    values.resize(static_cast<size_t>(k) + 1);
    std::sort(values.begin(), values.end(), std::greater<double>());
    tail.k = k;
    tail.alpha = hill_tail_index(values, k);
    // Hill's reading assumes a power tail above x_(k+1): the log-excesses log(x_(i) / x_(k+1))
    // are then k exponentials of mean 1 / alpha, whose largest m exceeds a given value with
    // P(max < m) = (1 - e^(-alpha m))^k. A top far more compressed than that (p below
    // kBoundedTopP) has an upper end, not a tail: a bounded peak (a narrow Gaussian on a plateau
    // reads alpha 0.6 at k = 2048 though f is bounded). No tail: alpha infinite.
    const double m = std::log(values.front() / values[static_cast<size_t>(k)]);
    if (tail.alpha > 0.0 && std::isfinite(tail.alpha) && m > 0.0) {
        const double log_p = k * std::log1p(-std::exp(-tail.alpha * m));
        tail.top_log_p = log_p;
        if (log_p < std::log(kBoundedTopP)) tail.alpha = std::numeric_limits<double>::infinity();
    }
    return tail;
}

SupportCheck check_support(const Problem& problem, const EstimatorSpec& spec, uint64_t probes,
                           uint64_t seed) {
    SupportCheck check;
    check.probes = probes;
    for (const Proposal* p : proposals_of(spec))
        if (!p->importance) { // uniform proposals cover the whole domain
            check.note = "a uniform pdf is positive on the whole domain";
            return check;
        }
    const Domain& d = problem.domain;
    Pcg32 rng(mix64(seed ^ 0x737570706f7274ULL), hash_string(spec.name.c_str())); // "support"
    const Proposal uniform = uniform_proposal(d);
    const SamplerPlan plan =
        make_sampler_plan(SamplerKind::Independent, d.sample_dim(), probes, rng);
    NeumaierSum all, missed, covered;
    Workspace ws;
    for_each_block(problem, uniform, plan, ws, [&](const SampleBlock& b) {
        const size_t count = b.count;
        const double* f = b.f;
        double* p = b.pdf; // the uniform densities, replaced by the proposal's
        sampling_density_block(spec, d, *b.x, p);
        for (size_t i = 0; i < count; ++i) {
            const double a = std::fabs(f[i]);
            if (!(a > 0.0) || !std::isfinite(a)) continue;
            ++check.f_nonzero;
            all.add(a);
            if (!(p[i] > 0.0)) {
                ++check.missed;
                missed.add(a);
            } else {
                covered.add(a);
            }
        }
    });
    check.missed_fraction = all.value() > 0.0 ? missed.value() / all.value() : 0.0;
    // The probes' estimate of int |f| over the support of p: measure x mean of |f| [p > 0].
    const double support_abs =
        probes ? d.measure() * covered.value() / static_cast<double>(probes) : 0.0;
    check.abs_integral = d.measure() * all.value() / static_cast<double>(probes ? probes : 1);

    std::vector<Rect> rects;
    std::string why_not;
    double share = 0.0;
    if (spec.has_techniques())
        why_not = "the zero set of a mixture of pdfs is not computed";
    else if (zero_set(spec.proposal, d, &rects, &share, &why_not)) {
        Budget budget;
        NeumaierSum mass;
        bool finite = true;
        for (const Rect& r : rects) {
            const double m = integrate_abs(problem.integrand, d.point_dim(), r, budget);
            if (budget.exceeded) break;
            if (!std::isfinite(m)) finite = false;
            mass.add(m);
        }
        check.quadrature_evaluations = budget.used;
        if (!budget.exceeded) {
            check.method = "quadrature";
            check.zero_measure = share;
            check.missed_mass = finite ? mass.value() : std::numeric_limits<double>::infinity();
            check.abs_integral = check.missed_mass + support_abs;
            check.missed_fraction =
                check.abs_integral > 0.0 ? check.missed_mass / check.abs_integral : 0.0;
            check.flagged = !finite || check.missed > 0 ||
                            check.missed_mass > kSupportTolerance * check.abs_integral;
            if (rects.empty())
                check.note = share == 0.0 ? "the pdf is positive on the whole domain up to a set "
                                            "of measure zero (its zero set is known)"
                                          : "the pdf's zero set has no area";
            else
                check.note =
                    "the pdf is zero on " + g_text(100.0 * share) +
                    "% of the domain (known from its bins or factors); |f| was integrated "
                    "there by adaptive Gauss-Kronrod quadrature graded toward the edges (" +
                    count_text(static_cast<uint64_t>(budget.used)) +
                    " evaluations), which finds features touching those edges down to "
                    "2^-40 of their width; flagged above " +
                    g_text(kSupportTolerance) + " of the integral of |f|";
            return check;
        }
        why_not = "the quadrature over the pdf's zero set stopped at its budget of " +
                  count_text(kSupportQuadratureBudget) + " evaluations";
    }
    check.method = "probes";
    check.flagged = check.missed > 0;
    check.note = "probed " + count_text(probes) + " uniform points; features narrower than ~1/" +
                 count_text(probes) + " of the domain can be missed (" + why_not + ")";
    return check;
}

std::string check_settings(const StudySettings& s) {
    if (s.n_min < 1) return "n_min must be >= 1, got " + std::to_string(s.n_min);
    if (s.n_max > kMaxN)
        return "n_max must be <= 2^36 (" + std::to_string(kMaxN) + "), got " +
               std::to_string(s.n_max);
    if (s.n_max < s.n_min)
        return "n_max (" + std::to_string(s.n_max) + ") must be >= n_min (" +
               std::to_string(s.n_min) + ")";
    if (n_ladder(s.n_min, s.n_max).empty())
        return "no power of two lies between n_min = " + std::to_string(s.n_min) +
               " and n_max = " + std::to_string(s.n_max);
    if (s.reps < 2 || s.reps > kMaxReps)
        return "reps must be in 2.." + std::to_string(kMaxReps) +
               " (a variance needs two replicates), got " + std::to_string(s.reps);
    if (s.threads < 0 || s.threads > kMaxThreads)
        return "threads must be in 0.." + std::to_string(kMaxThreads) + " (0 = all cores), got " +
               std::to_string(s.threads);
    return "";
}

uint64_t study_evaluations(const StudySettings& s, size_t estimators) {
    const uint64_t kMax = std::numeric_limits<uint64_t>::max();
    uint64_t ladder = 0; // <= 2^37 for n_max <= 2^36
    for (uint64_t n : n_ladder(s.n_min, s.n_max)) ladder += n;
    const uint64_t reps = s.reps > 0 ? static_cast<uint64_t>(s.reps) : 0;
    const uint64_t e = static_cast<uint64_t>(estimators);
    if (reps && ladder > kMax / reps) return kMax;
    const uint64_t per_estimator = ladder * reps;
    if (e && per_estimator > kMax / e) return kMax;
    return per_estimator * e;
}

std::string check_study_size(const StudySettings& s, size_t estimators) {
    const uint64_t evals = study_evaluations(s, estimators);
    const std::string given = "n_max = " + std::to_string(s.n_max) +
                              ", reps = " + std::to_string(s.reps) + " and " +
                              std::to_string(estimators) + " estimator(s)";
    if (evals > kMaxStudyEvaluations)
        return given + " ask for " + std::to_string(evals) +
               " integrand evaluations (sum over N of N x reps x estimators), more than the "
               "limit of " +
               std::to_string(kMaxStudyEvaluations) +
               " (2^40): lower n_max, reps or the number of estimators";
    const uint64_t levels = n_ladder(s.n_min, s.n_max).size();
    const uint64_t results = levels * static_cast<uint64_t>(s.reps > 0 ? s.reps : 0) * estimators;
    if (results > kMaxReplicateResults)
        return given + " over " + std::to_string(levels) + " N levels keep " +
               std::to_string(results) +
               " replicate results (levels x reps x estimators), more than the limit of " +
               std::to_string(kMaxReplicateResults) +
               " (2^21): raise n_min, or lower n_max, reps or the number of estimators";
    return "";
}

std::vector<uint64_t> n_ladder(uint64_t n_min, uint64_t n_max) {
    std::vector<uint64_t> ladder;
    for (uint64_t n = 1; n <= n_max && n != 0; n <<= 1)
        if (n >= n_min) ladder.push_back(n);
    return ladder;
}

uint64_t replicate_stream(uint64_t seed, const std::string& estimator, uint64_t n, int rep) {
    uint64_t h = hash_combine(mix64(seed), hash_string(estimator.c_str()));
    h = hash_combine(h, n);
    return hash_combine(h, static_cast<uint64_t>(rep));
}

Pcg32 replicate_rng(uint64_t seed, const std::string& estimator, uint64_t n, int rep) {
    const uint64_t key = replicate_stream(seed, estimator, n, rep);
    // Both the starting state and the stream come from the key: replicates start at
    // unrelated points of unrelated streams.
    return Pcg32(hash_combine(key, 0x7374617465ULL), key); // "state"
}

LevelStats summarise_level(const std::vector<RunResult>& runs, const Problem& problem) {
    LevelStats s;
    s.reps = static_cast<int>(runs.size());
    if (runs.empty()) return s;
    s.n = runs[0].n;
    s.run_dof = runs[0].dof;
    const double run_quantile = interval_quantile(s.run_dof);
    RunningMoments est, se, times;
    std::vector<double> seconds;
    seconds.reserve(runs.size());
    NeumaierSum sq_err, time, training_time;
    double training_share = 0.0;
    int covered = 0, se_count = 0;
    NeumaierSum se2;
    double run_dof_sum = 0.0;
    s.has_exact = problem.exact.has_value();
    const double exact = s.has_exact ? *problem.exact : 0.0;
    // Every run keeps its kTailWeights largest |w|, so the largest of the pooled tops are the
    // largest weights of all R N samples: the tail index uses them all.
    std::vector<double> pooled;
    double nonzero = 0.0, ess = 0.0;
    for (const RunResult& r : runs) {
        // A run whose every sample was NaN/Inf has no estimate (run_estimate gives NaN).
        if (std::isnan(r.estimate) && r.n > 0 && r.diagnostics.nonfinite == r.n)
            ++s.no_estimate_runs;
        // An error bar of 0 to round-off: right only if every replicate agrees (f/p constant).
        if (std::isfinite(r.estimate) && std::isfinite(r.std_error) &&
            r.std_error <= 64.0 * 2.220446049250313e-16 * std::fabs(r.estimate))
            ++s.zero_error_runs;
        ess += r.diagnostics.ess;
        if (r.iteration_dof > 0 && std::isfinite(r.iteration_chi2)) {
            s.iteration_chi2 += r.iteration_chi2;
            s.iteration_dof += r.iteration_dof;
        }
        pooled.insert(pooled.end(), r.top.begin(), r.top.end());
        nonzero += static_cast<double>(r.diagnostics.nonzero);
        est.add(r.estimate);
        time.add(r.seconds);
        times.add(r.seconds);
        seconds.push_back(r.seconds);
        training_time.add(r.training_seconds);
        training_share +=
            r.n > 0 ? static_cast<double>(r.training_n) / static_cast<double>(r.n) : 0.0;
        s.diagnostics.merge(r.diagnostics);
        s.estimates.push_back(r.estimate);
        s.run_std_errors.push_back(r.std_error);
        s.run_dofs.push_back(r.dof);
        if (std::isfinite(r.std_error)) {
            se.add(r.std_error);
            se2.add(r.std_error * r.std_error);
            run_dof_sum += std::max(r.dof, 0);
            ++se_count;
        }
        if (s.has_exact) {
            const double e = r.estimate - exact;
            sq_err.add(e * e);
            // An interval is never narrower than the arithmetic: an estimate exact to round-off
            // (64 eps relative, as for zero error bars) covers.
            if (std::isfinite(r.std_error) &&
                std::fabs(e) <=
                    run_quantile * r.std_error + 64.0 * 2.220446049250313e-16 * std::fabs(exact))
                ++covered;
        }
    }
    const double R = static_cast<double>(s.reps);
    s.nonzero_per_run = nonzero / R;
    s.ess_mean = ess / R;
    std::sort(pooled.begin(), pooled.end(), std::greater<double>());
    s.tail_index =
        stable_tail_index(pooled, tail_order(s.n * static_cast<uint64_t>(s.reps)), &s.tail_k);
    s.mean = est.mean();
    s.variance = est.variance();
    // s^2 / sigma^2 ~ chi^2_{R-1} for normal estimates.
    const double dof = R - 1.0;
    s.variance_lo = dof * s.variance / chi_square_quantile(0.975, dof);
    s.variance_hi = dof * s.variance / chi_square_quantile(0.025, dof);
    s.std_error = std::sqrt(s.variance / R);
    const double t = student_t_quantile(0.975, dof);
    s.ci_lo = s.mean - t * s.std_error;
    s.ci_hi = s.mean + t * s.std_error;
    s.mean_run_se = se_count ? se.mean() : std::numeric_limits<double>::quiet_NaN();
    s.mean_run_variance =
        se_count ? se2.value() / se_count : std::numeric_limits<double>::quiet_NaN();
    s.run_dof_total = run_dof_sum;
    s.time_total = time.value();
    s.time_mean = s.time_total / R;
    s.time_std = std::sqrt(times.variance());
    // The median and its 95% interval: robust to the replicate that a busy machine delayed.
    const MedianInterval mi = median_interval(seconds);
    s.time_median = mi.median;
    s.time_median_lo = mi.lo;
    s.time_median_hi = mi.hi;
    s.training_time_mean = training_time.value() / R;
    s.training_share = training_share / R;
    s.efficiency = s.variance > 0.0 && s.time_mean > 0.0 ? 1.0 / (s.variance * s.time_mean)
                                                         : std::numeric_limits<double>::infinity();
    if (s.has_exact) {
        s.bias = s.mean - exact;
        s.mse = sq_err.value() / R;
        s.rmse = std::sqrt(s.mse);
        // Coverage of the runs' own intervals: none when no run had an error bar.
        s.coverage =
            se_count ? static_cast<double>(covered) / R : std::numeric_limits<double>::quiet_NaN();
        s.error = s.rmse;
    } else {
        s.error = std::sqrt(s.variance);
    }
    if (s.has_exact) s.exact = exact;
    // Spread and agreement judged on the estimates themselves, never on their squares (which
    // underflow below 1e-154: f = 1e-170 x would look exact).
    double lowest = std::numeric_limits<double>::infinity(), highest = -lowest, largest = 0.0;
    bool every_run_deterministic = !runs.empty();
    for (const RunResult& r : runs) {
        if (std::isfinite(r.estimate)) {
            lowest = std::min(lowest, r.estimate);
            highest = std::max(highest, r.estimate);
            largest = std::max(largest, std::fabs(r.estimate));
        }
        // One deterministic point set reports no error bar (NaN) and no degrees of freedom.
        if (!(std::isnan(r.std_error) && r.dof <= 0)) every_run_deterministic = false;
    }
    const double roundoff = 64.0 * 2.220446049250313e-16 * largest;
    s.estimates_spread = highest - lowest > roundoff;
    // (Runs without an error bar that differ are random runs too small for theirs: a Walsh
    // bound below 2^10 points.)
    s.deterministic = every_run_deterministic && !s.estimates_spread;
    s.values_underflow = largest > 0.0 && largest < kUnderflowScale;
    // Exact: the replicates agree to round-off on a non-zero, finite mean from random runs with
    // no dropped sample, and, when the exact value is known, on that value (agreement alone can
    // be a shared wrong answer).
    const bool matches_exact =
        !s.has_exact || std::fabs(s.mean - exact) <= 1e-12 * std::fabs(exact) + roundoff;
    s.exact_to_roundoff = !s.estimates_spread && !s.deterministic && !s.values_underflow &&
                          matches_exact && std::isfinite(s.mean) && s.mean != 0.0 &&
                          s.diagnostics.nonfinite == 0 && s.diagnostics.zero_pdf == 0;
    if (s.no_estimate_runs > 0) {
        // No estimate: nothing derived from the (dropped) samples means anything.
        const double nan = std::numeric_limits<double>::quiet_NaN();
        s.mean = s.variance = s.variance_lo = s.variance_hi = s.std_error = nan;
        s.ci_lo = s.ci_hi = s.bias = s.mse = s.rmse = s.coverage = s.mean_run_se = nan;
        s.mean_run_variance = nan;
        s.efficiency = s.error = s.tail_index = s.ess_mean = nan;
        s.tail_k = 0;
        s.estimates_spread = false;
        s.zero_error_runs = 0;
    }
    return s;
}

const char* level_measure_name(LevelMeasure m) {
    switch (m) {
    case LevelMeasure::Variance: return "variance";
    case LevelMeasure::Mse: return "mse";
    case LevelMeasure::RelativeMse: return "relative_mse";
    }
    return "variance";
}

namespace {

// The weighted line through points[first..] and its chi-square; levels_used 0 when the line
// cannot be drawn (fewer than 3 points, or one N).
PowerLawSegment fit_segment(const std::vector<FitPoint>& points, size_t first) {
    PowerLawSegment seg;
    if (points.size() < first + 3) return seg;
    std::vector<double> x, y, sd;
    uint64_t lo = points[first].n, hi = points[first].n;
    for (size_t i = first; i < points.size(); ++i) {
        const FitPoint& p = points[i];
        x.push_back(std::log(static_cast<double>(p.n)));
        y.push_back(std::log(p.value));
        sd.push_back(p.sd_log);
        lo = std::min(lo, p.n);
        hi = std::max(hi, p.n);
    }
    const LineFit line = fit_weighted_line(x, y, sd);
    if (!(line.sxx > 0.0)) return seg;
    seg.order = line.slope;
    seg.intercept = line.intercept;
    seg.order_se = line.slope_se;
    seg.levels_used = static_cast<int>(x.size());
    seg.dof = seg.levels_used - 2;
    seg.chi2 = line.chi2; // NaN for unit weights
    seg.p_value = std::isfinite(seg.chi2) ? chi_square_sf(seg.chi2, seg.dof) : seg.chi2;
    seg.n_first = lo;
    seg.n_last = hi;
    return seg;
}

} // namespace

ConvergenceFit fit_power_law(const std::vector<FitPoint>& points, LevelMeasure measure) {
    ConvergenceFit fit;
    fit.measure = measure;
    fit.levels_used = static_cast<int>(points.size());
    const PowerLawSegment all = fit_segment(points, 0);
    if (all.levels_used == 0) return fit;
    fit.valid = true;
    fit.order = all.order;
    fit.intercept = all.intercept;
    fit.order_se = all.order_se;
    fit.chi2 = all.chi2;
    fit.dof = all.dof;
    fit.p_value = all.p_value;
    fit.n_first = all.n_first;
    fit.n_last = all.n_last;
    // Not one power law: the longest tail of the ladder that is one (a pre-asymptotic start,
    // a map still learning), if any.
    if (all.p_value < kPowerLawP)
        for (size_t first = 1; first + kSuffixLevels <= points.size(); ++first) {
            const PowerLawSegment tail = fit_segment(points, first);
            if (tail.levels_used > 0 && tail.p_value >= kSuffixP) {
                fit.suffix = tail;
                break;
            }
        }
    return fit;
}

ConvergenceFit fit_mse(const std::vector<LevelStats>& levels) {
    std::vector<FitPoint> points;
    for (const LevelStats& l : levels) {
        if (!l.has_exact || !std::isfinite(l.mse) || l.exact_to_roundoff) continue;
        const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(l.mean);
        if (!(l.mse > roundoff * roundoff)) continue;
        // R squared errors: a chi-square of R degrees of freedom when the bias is 0 (a
        // non-central one, narrower in log, when it is not).
        const double sd_log = l.reps > 0 ? std::sqrt(trigamma(0.5 * l.reps)) : 0.0;
        points.push_back({l.n, l.mse, sd_log});
    }
    ConvergenceFit fit = fit_power_law(points, LevelMeasure::Mse);
    if (points.size() < 3) fit.note = "fewer than 3 levels with an MSE above round-off: no fit";
    return fit;
}

ConvergenceFit fit_convergence(const std::vector<LevelStats>& levels) {
    std::vector<FitPoint> points;
    int skipped = 0, missing = 0, exact_levels = 0;
    for (const LevelStats& l : levels) {
        if (!std::isfinite(l.mean) || !std::isfinite(l.variance) || l.variance < 0.0) {
            ++missing; // no estimate at this N (every sample NaN/Inf, or an overflow)
            continue;
        }
        // A variance at the round-off level of the mean (an exact estimator such as a pdf
        // proportional to f) carries no convergence information.
        const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(l.mean);
        exact_levels += l.exact_to_roundoff ? 1 : 0;
        if (l.variance > roundoff * roundoff && std::isfinite(l.variance)) {
            const double sd_log = l.reps > 1 ? std::sqrt(trigamma(0.5 * (l.reps - 1))) : 0.0;
            points.push_back({l.n, l.variance, sd_log});
        } else {
            ++skipped;
        }
    }
    ConvergenceFit fit = fit_power_law(points, LevelMeasure::Variance);
    if (skipped)
        fit.note = std::to_string(skipped) + " level(s) with zero (round-off) variance left out";
    if (missing)
        fit.note += (fit.note.empty() ? "" : "; ") + std::to_string(missing) +
                    " level(s) without an estimate left out";
    if (points.size() < 3) {
        if (points.empty() && skipped && !missing)
            fit.note = exact_levels == skipped
                           ? "exact to round-off at every N (f/p constant): nothing to fit"
                           : "variance is zero at every N, but not from an exact estimator "
                             "(the replicates agree on 0, or dropped samples): the samples saw "
                             "nothing of f, no fit";
        else if (points.empty() && missing && !skipped)
            fit.note = "no estimate at any N: no fit";
        else
            fit.note = "fewer than 3 levels with a variance: no fit" +
                       (fit.note.empty() ? "" : "; " + fit.note);
    }
    return fit;
}

LevelConsistency level_consistency(const std::vector<LevelStats>& levels) {
    LevelConsistency c;
    // Levels exact to round-off (replicates that agree to 64 eps, estimates_spread false) have
    // nothing to test: their spread is the arithmetic's, and native and wasm differ in it. The
    // others' errors are floored at the round-off of their means: means that agree to round-off
    // agree, whatever their spread says.
    auto error_of = [](const LevelStats& l) {
        const double roundoff = 64.0 * 2.220446049250313e-16 * std::fabs(l.mean);
        return std::sqrt(l.std_error * l.std_error + roundoff * roundoff);
    };
    auto usable = [](const LevelStats& l) {
        return std::isfinite(l.std_error) && l.std_error > 0.0 && std::isfinite(l.mean) &&
               l.estimates_spread;
    };
    double wsum = 0.0, wmean = 0.0;
    for (const LevelStats& l : levels)
        if (usable(l)) {
            const double e = error_of(l);
            wsum += 1.0 / (e * e);
            wmean += l.mean / (e * e);
        }
    if (wsum == 0.0) return c;
    wmean /= wsum;
    // A level's standard error comes from its R replicates, so its z follows Student's t with
    // R - 1 degrees of freedom, whose tails are far heavier than the normal's for R = 10: summed
    // as chi^2 they would flag consistent levels (about 1% of consistent ladders at p < 1e-3
    // instead of 0.1%). Each z enters as the normal score of its own tail probability.
    int used = 0;
    for (const LevelStats& l : levels)
        if (usable(l)) {
            const double z = std::fabs(l.mean - wmean) / error_of(l);
            const double tail = student_t_sf(z, std::max(1, l.reps - 1));
            const double score = tail > 0.0 ? normal_quantile(tail) : -INFINITY;
            c.chi2 += score * score;
            ++used;
        }
    c.dof = used - 1;
    c.p_value = c.dof > 0 ? chi_square_sf(c.chi2, c.dof) : 1.0;
    return c;
}

int resolve_threads(int requested) {
#if MCPLAY_HAS_THREADS
    if (requested > 0) return requested;
    unsigned hw = std::thread::hardware_concurrency();
    return hw > 0 ? static_cast<int>(hw) : 1;
#else
    (void)requested;
    return 1;
#endif
}

StudyPlan plan_study(const Problem& problem, const std::vector<EstimatorSpec>& estimators,
                     const StudySettings& settings) {
    const auto start = std::chrono::steady_clock::now();
    StudyPlan plan;
    plan.levels = n_ladder(settings.n_min, settings.n_max);
    plan.evaluations = study_evaluations(settings, estimators.size());
    const size_t tasks = estimators.size() * static_cast<size_t>(std::max(settings.reps, 1));
    plan.threads = static_cast<int>(std::max<size_t>(
        1, std::min<size_t>(static_cast<size_t>(resolve_threads(settings.threads)), tasks)));
    const uint64_t per_estimator = study_evaluations(settings, 1);
    Workspace ws;
    double total = 0.0;
    for (const EstimatorSpec& spec : estimators) {
        EstimatorPlan e;
        e.name = spec.name;
        e.evaluations = per_estimator;
        // The stream of a replicate the study never draws (rep = -1 wraps to 2^64 - 1).
        Pcg32 rng = replicate_rng(settings.seed, spec.name, kPilotSamples, -1);
        double seconds = run_estimate(problem, spec, kPilotSamples, rng, ws).seconds;
        if (seconds < 0.005) seconds = run_estimate(problem, spec, kPilotSamples, rng, ws).seconds;
        e.seconds_per_evaluation = seconds / static_cast<double>(kPilotSamples);
        e.predicted_seconds = e.seconds_per_evaluation * static_cast<double>(per_estimator);
        total += e.predicted_seconds;
        plan.estimators.push_back(e);
    }
    plan.predicted_seconds = total / plan.threads;
    plan.pilot_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return plan;
}

EstimatorStudy begin_estimator_study(const Problem& problem, const EstimatorSpec& spec,
                                     const StudySettings& settings, IntegrandTail* shared_tail) {
    EstimatorStudy es;
    es.spec = spec;
    es.error_method = error_method_for(spec);
    es.support = check_support(problem, spec, kSupportProbes, settings.seed);
    es.weights_bounded = weights_bounded(problem, spec);
    if (variance_follows_integrand(spec) && !es.weights_bounded) {
        if (!shared_tail) {
            es.integrand = integrand_tail(problem, kTailProbes, settings.seed);
        } else {
            if (shared_tail->probes == 0)
                *shared_tail = integrand_tail(problem, kTailProbes, settings.seed);
            es.integrand = *shared_tail;
        }
    }
    return es;
}

void add_level(EstimatorStudy& es, const std::vector<RunResult>& runs, const Problem& problem) {
    es.levels.push_back(summarise_level(runs, problem));
    es.fit = fit_convergence(es.levels);
    es.mse_fit = fit_mse(es.levels);
    es.consistency = level_consistency(es.levels);
}

StudyResult run_study(const Problem& problem, const std::vector<EstimatorSpec>& estimators,
                      const StudySettings& settings, const StudyProgress& progress) {
    const auto start = std::chrono::steady_clock::now();
    StudyResult result;
    result.problem = problem;
    result.settings = settings;
    result.threads_used = resolve_threads(settings.threads);
    IntegrandTail shared_tail; // measured once, for every estimator whose variance follows f's
    for (const EstimatorSpec& spec : estimators)
        result.estimators.push_back(begin_estimator_study(problem, spec, settings, &shared_tail));
    if (problem_stopped(problem)) {
        result.cancelled = true;
        return result;
    }
    const std::vector<uint64_t> ladder = n_ladder(settings.n_min, settings.n_max);
    const size_t reps = static_cast<size_t>(settings.reps);
    std::vector<Workspace> workspaces(static_cast<size_t>(std::max(result.threads_used, 1)));
    auto run = [&](size_t e, uint64_t n, int r, int worker) {
        Pcg32 rng = replicate_rng(settings.seed, estimators[e].name, n, r);
        return run_estimate(problem, estimators[e], n, rng, workspaces[size_t(worker)],
                            settings.accumulator);
    };
    auto end_level = [&](size_t level, const std::vector<RunResult>& runs) {
        if (problem_stopped(problem)) return false; // the level's runs were cut short
        for (size_t e = 0; e < estimators.size(); ++e) {
            std::vector<RunResult> level_runs(runs.begin() + static_cast<long>(e * reps),
                                              runs.begin() + static_cast<long>((e + 1) * reps));
            add_level(result.estimators[e], level_runs, problem);
        }
        result.wall_seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return !progress || progress(result, level);
    };
    result.cancelled = !run_ladder<RunResult>(ladder, estimators.size(), settings.reps,
                                              result.threads_used, run, end_level);
    result.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

} // namespace mcp

namespace mcp {

SampleDump dump_samples(const Problem& problem, const EstimatorSpec& spec, uint64_t n,
                        uint64_t seed, uint64_t adaptive_n) {
    SampleDump dump;
    const uint64_t shown = n;
    const bool adaptive = kind_of(spec).adaptive;
    if (adaptive) n = std::max(n, adaptive_n);
    const Domain& d = problem.domain;
    dump.sample_dim = d.sample_dim();
    dump.point_dim = d.point_dim();
    // The same stream and seeding as replicate 0 of the study at this N.
    Pcg32 rng = replicate_rng(seed, spec.name, n, 0);
    std::unique_ptr<EstimatorAlgorithm> estimator =
        make_estimator(problem, spec, Accumulator::Compensated);
    estimator->observe([&](const SampleBlock& blk) {
        for (size_t i = 0; i < blk.count && dump.f.size() < shown; ++i) {
            for (int j = 0; j < dump.sample_dim; ++j) dump.u.push_back(blk.u->coord(j)[i]);
            for (int j = 0; j < dump.point_dim; ++j) dump.x.push_back(blk.x->coord(j)[i]);
            const double p = blk.pdf[i], f = blk.f[i];
            dump.pdf.push_back(p);
            dump.f.push_back(f);
            dump.weight.push_back(p > 0.0 ? f / p : (f == 0.0 ? 0.0 : NAN));
        }
    });
    Workspace ws;
    estimator->begin(n, rng);
    const PointDesign design = estimator->design(); // the estimator's own layout of its points
    dump.strata = design.strata;
    dump.per_stratum = design.per_stratum;
    dump.randomizations = design.randomizations;
    while (estimator->run_block(rng, ws)) {
    }
    dump.adaptive = estimator->adaptive_view();
    return dump;
}

} // namespace mcp
