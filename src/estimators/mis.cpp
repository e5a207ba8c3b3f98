// Multiple importance sampling for integrals [Veach97, ch. 9]. Technique k draws n_k points
// from p_k; at each point every technique's density is evaluated and the point's share of f is
// w_k(x) from the shared heuristics (core/mis.h), with q_k = a_k p_k, a_k = n_k / N
// (multi-sample) or the choice probability c_k (one-sample). Every sample carries the value
//   y = w_k(x) f(x) / (a_k p_k(x)),
// so that the estimate is (1/N) sum y in both forms:
//   multi-sample [Veach97, 9.2]: I = sum_k (n_k/N) mean_k(y), variance sum_k (n_k/N)^2 s_k^2/n_k
//     (the techniques are independent strata);
//   one-sample [Veach97, 9.2.4]: each of the N points picks technique k with probability c_k,
//     so the counts are multinomial and the y are independent and identically distributed.
// Optimal MIS [Kondapaneni19]: with q(x) = sum_k a_k p_k(x), the optimal weights make
//   I = sum_k alpha_k,   alpha = argmin sum_x (f/q - sum_k alpha_k p_k/q)^2,
// the balance heuristic with the densities p_k (integral 1 each) as control variates, solved
// from the samples; the residuals give the error bar.
// Dropped samples (f/p not finite) count 0, as everywhere; the weight accumulator keeps the
// diagnostics of the y.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/regression.h"
#include "core/stats.h"
#include "estimators/estimator_kind.h"

namespace mcp {
namespace {

class MisEstimator final : public EstimatorAlgorithm {
  public:
    MisEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), options_(spec.mis_options),
          techniques_(static_cast<int>(spec.mis_options.proposals.size())),
          float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        const size_t k = static_cast<size_t>(techniques_);
        total_ = n;
        counts_.assign(k, 0);
        if (options_.one_sample) {
            // Each point's technique, drawn ahead: the counts are multinomial(N, c), and the
            // points of one technique are then independent draws of it, in any order.
            std::vector<double> cumulative(k);
            double c = 0.0;
            for (size_t t = 0; t < k; ++t) cumulative[t] = (c += options_.fractions[t]);
            for (uint64_t i = 0; i < n; ++i) {
                const double u = rng.next_double() * c;
                size_t t = 0;
                while (t + 1 < k && u >= cumulative[t]) ++t;
                ++counts_[t];
            }
            share_ = options_.fractions;
        } else {
            // n_k from the fractions; two each (a variance per technique) when N allows.
            const uint64_t least = n >= 2 * k ? 2 : 0;
            counts_.assign(k, least);
            allocate_largest_remainders(n - least * k, options_.fractions, &counts_);
            share_.resize(k);
            for (size_t t = 0; t < k; ++t)
                share_[t] = n > 0 ? static_cast<double>(counts_[t]) / static_cast<double>(n) : 0.0;
        }
        plan_all_ = SamplerPlan(); // the accumulator's iid method reads no plan data
        plan_all_.dim = problem_.domain.sample_dim();
        plan_all_.total = n;
        accumulator_.reset(ErrorMethod::Iid, plan_all_, float32_);
        moments_.assign(k, RunningMoments());
        const int groups = options_.one_sample ? 1 : techniques_;
        covariance_.assign(static_cast<size_t>(groups), RunningCovariance());
        for (RunningCovariance& c : covariance_) c.reset(techniques_ + 1);
        technique_ = 0;
        next_ = accumulated_ = 0;
        plan_ready_ = false;
        density_.assign(k * kBlockSize, 0.0);
        q_.assign(k * kBlockSize, 0.0);
        weight_.assign(kBlockSize, 0.0);
        value_.assign(kBlockSize, 0.0);
        seen_.assign(kBlockSize, 0.0);
        mixture_.assign(kBlockSize, 0.0);
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        while (technique_ < techniques_ && next_ >= counts_[static_cast<size_t>(technique_)]) {
            ++technique_;
            next_ = 0;
            plan_ready_ = false;
        }
        if (technique_ >= techniques_) return false;
        const size_t t = static_cast<size_t>(technique_);
        if (!plan_ready_) {
            prepare_workspace(problem_.domain, ws);
            plan_ = make_sampler_plan(SamplerKind::Independent, problem_.domain.sample_dim(),
                                      counts_[t], rng);
            plan_ready_ = true;
        }
        const size_t count =
            static_cast<size_t>(std::min<uint64_t>(kBlockSize, plan_.total - next_));
        const Proposal& own = options_.proposals[t];
        SampleBlock b = sample_block(problem_, own, plan_, next_, count, ws);
        weigh(b, t);
        if (observer_) {
            // Seen as a sample of density a_k p_k / w_k: its weight f / density is its y.
            for (size_t i = 0; i < count; ++i)
                seen_[i] = weight_[i] > 0.0 ? q_[t * kBlockSize + i] / weight_[i]
                                            : std::numeric_limits<double>::infinity();
            SampleBlock seen = b;
            seen.first = accumulated_;
            seen.pdf = seen_.data();
            notify(seen);
        }
        // y = (w f) / (a_k p_k): the accumulator forms it, drops what is not finite.
        double* q_own = q_.data() + t * kBlockSize;
        for (size_t i = 0; i < count; ++i) value_[i] = weight_[i] * b.f[i];
        std::copy(q_own, q_own + count, seen_.data());
        accumulator_.add_block(accumulated_, value_.data(), seen_.data(), seen_.data(), count);
        const double* y = seen_.data();
        moments_[t].add_block(y, count);
        if (options_.optimal) {
            // Columns p_k / q and y (= f / q with the balance heuristic) of the regression.
            const double* columns[kMaxMisTechniques + 1];
            for (size_t k = 0; k < static_cast<size_t>(techniques_); ++k) {
                double* z = density_.data() + k * kBlockSize;
                // (A point whose every density is 0, at a warp's edge, has y = 0: left out.)
                for (size_t i = 0; i < count; ++i)
                    z[i] = mixture_[i] > 0.0 ? z[i] / mixture_[i] : 0.0;
                columns[k] = z;
            }
            columns[techniques_] = y;
            covariance_[options_.one_sample ? 0 : t].add_block(columns, count);
        }
        next_ += count;
        accumulated_ += count;
        return true;
    }

    RunResult result() const override {
        const double scale = quantity_scale(problem_);
        RunResult r = accumulator_.finish(scale);
        r.n = total_;
        if (options_.optimal) {
            optimal_estimate(scale, &r);
        } else if (!options_.one_sample) {
            StratifiedSum strata;
            for (size_t t = 0; t < moments_.size(); ++t) strata.add(share_[t], moments_[t]);
            r.estimate = scale * strata.estimate();
            r.std_error = strata.has_variance() ? scale * std::sqrt(strata.variance())
                                                : std::numeric_limits<double>::quiet_NaN();
            r.dof = strata.has_variance() ? strata.dof() : 0;
        }
        return r;
    }

  private:
    /// Densities of every technique at the block's points, q_k = a_k p_k, the mixture
    /// q = sum_k q_k and technique t's weights.
    void weigh(const SampleBlock& b, size_t t) {
        const size_t k_count = static_cast<size_t>(techniques_);
        const double* q_rows[kMaxMisTechniques];
        std::fill(mixture_.begin(), mixture_.begin() + static_cast<long>(b.count), 0.0);
        for (size_t k = 0; k < k_count; ++k) {
            double* p = density_.data() + k * kBlockSize;
            if (k == t)
                std::copy(b.pdf, b.pdf + b.count, p);
            else
                proposal_pdf_block(options_.proposals[k], problem_.domain, *b.x, p);
            double* q = q_.data() + k * kBlockSize;
            for (size_t i = 0; i < b.count; ++i) {
                q[i] = share_[k] * p[i];
                mixture_[i] += q[i];
            }
            q_rows[k] = q;
        }
        const MisWeighting balance{MisHeuristic::Balance};
        mis_weight_block(options_.optimal ? balance : options_.weighting, q_rows, techniques_,
                         static_cast<int>(t), b.count, weight_.data());
    }

    /// [Kondapaneni19]: alpha from the normal equations of the pooled samples (columns of
    /// techniques that drew nothing left out: their p_k / q need not integrate to 1), the
    /// estimate sum alpha_k, and the variance of the residuals r = y - alpha . z, per technique
    /// (multi-sample) or pooled (one-sample), with N / (N - K) for the fitted coefficients.
    void optimal_estimate(double scale, RunResult* r) const {
        const int d = techniques_ + 1;
        const size_t m = static_cast<size_t>(techniques_);
        std::vector<double> gram(static_cast<size_t>(d) * static_cast<size_t>(d), 0.0);
        for (const RunningCovariance& c : covariance_) {
            const double n = static_cast<double>(c.count());
            for (int a = 0; a < d; ++a)
                for (int b = 0; b < d; ++b)
                    gram[static_cast<size_t>(a * d + b)] +=
                        c.comoment(a, b) + n * c.mean(a) * c.mean(b);
        }
        std::vector<double> a(m * m, 0.0), rhs(m, 0.0), alpha;
        for (size_t i = 0; i < m; ++i) {
            const bool used = share_[i] > 0.0;
            for (size_t j = 0; j < m; ++j)
                a[i * m + j] = used && share_[j] > 0.0 ? gram[i * static_cast<size_t>(d) + j] : 0.0;
            rhs[i] = used ? gram[i * static_cast<size_t>(d) + m] : 0.0;
        }
        const int rank = solve_psd(a, rhs, techniques_, &alpha);
        NeumaierSum estimate;
        for (double x : alpha) estimate.add(x);
        std::vector<double> v(static_cast<size_t>(d));
        for (size_t k = 0; k < m; ++k) v[k] = -alpha[k];
        v[m] = 1.0;
        const double n_all = static_cast<double>(total_);
        const double fitted = n_all > rank ? n_all / (n_all - rank) : 1.0;
        r->estimate =
            total_ > 0 ? scale * estimate.value() : std::numeric_limits<double>::quiet_NaN();
        if (options_.one_sample) {
            const RunningCovariance& c = covariance_[0];
            const double dof = n_all - rank;
            if (dof < 1.0) {
                r->std_error = std::numeric_limits<double>::quiet_NaN();
                r->dof = 0;
                return;
            }
            // The residuals' mean is 0 by the normal equations (the columns span the constant).
            const double var = c.quadratic_form(v) / dof / n_all;
            r->std_error = scale * std::sqrt(var);
            r->dof = static_cast<int>(std::min(1e6, dof));
            return;
        }
        NeumaierSum variance;
        double satterthwaite = 0.0;
        bool complete = true;
        for (size_t t = 0; t < m; ++t) {
            const RunningCovariance& c = covariance_[t];
            if (c.count() == 0) continue;
            if (c.count() < 2) {
                complete = false;
                continue;
            }
            const double nt = static_cast<double>(c.count());
            const double vt =
                share_[t] * share_[t] * c.quadratic_form(v) / (nt - 1.0) / nt * fitted;
            variance.add(vt);
            satterthwaite += vt * vt / (nt - 1.0);
        }
        const double var = std::max(0.0, variance.value());
        r->std_error = complete ? scale * std::sqrt(var) : std::numeric_limits<double>::quiet_NaN();
        const double dof =
            satterthwaite > 0.0 ? var * var / satterthwaite - (rank - 1) : n_all - rank;
        r->dof = complete ? static_cast<int>(std::min(1e6, std::max(1.0, dof))) : 0;
    }

    const Problem& problem_;
    const MisOptions& options_;
    int techniques_;
    bool float32_;
    uint64_t total_ = 0, next_ = 0, accumulated_ = 0;
    int technique_ = 0;
    bool plan_ready_ = false;
    std::vector<uint64_t> counts_;
    std::vector<double> share_; // a_k
    SamplerPlan plan_, plan_all_;
    WeightAccumulator accumulator_;
    std::vector<RunningMoments> moments_;
    std::vector<RunningCovariance> covariance_;
    std::vector<double> density_, q_, weight_, value_, seen_, mixture_;
};

} // namespace

const EstimatorKind& mis_estimator_kind() {
    static const EstimatorKind kind{
        "mis",
        "multiple importance sampling: techniques combined by a heuristic's or optimal weights",
        [](const EstimatorSpec&) { return "mis"; },
        [](const EstimatorSpec& spec) {
            // Multi-sample: the techniques are independent strata; one-sample: independent
            // points, or the residuals of their regression for optimal weights.
            if (!spec.mis_options.one_sample) return ErrorMethod::PartsSum;
            return spec.mis_options.optimal ? ErrorMethod::Regression : ErrorMethod::Iid;
        },
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<MisEstimator>(problem, spec, accumulator);
        },
        [](const EstimatorSpec&) { return true; }, // independent points
        false,
    };
    return kind;
}

} // namespace mcp
