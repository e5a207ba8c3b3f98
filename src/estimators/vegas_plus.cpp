// VEGAS+ [Lepage21, sec. 3]: the VEGAS map, and adaptive stratification of the y space before
// it. The unit cube of y is cut into M^d hypercubes h of volume V = M^-d; each iteration puts
// n_h >= 2 points in h, n_h proportional to sigma_h^beta (sigma_h the standard deviation of the
// weights w = f J / p in h at the previous iteration), and estimates
//   I = sum_h V mean_h(w),   var(I) = sum_h V^2 s_h^2 / n_h.
// Training iterations (train_map, estimators/vegas_train.h, fed by the hypercubes' points) adapt
// the map and the allocation; the final iteration freezes both.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/stats.h"
#include "estimators/estimator_kind.h"
#include "estimators/vegas_train.h"

namespace mcp {
namespace {

// The largest share of the estimate the pilot's points get in a hypercube (pilot_weight).
constexpr double kMostPilotShare = 0.25;

// sigma^beta, the allocation's share of a hypercube: for the default beta 0.75 as sqrt(sigma)
// sqrt(sqrt(sigma)), two square roots (vectorised) for one pow, which at 10^5 hypercubes per
// allocation took 2-3% of a 2-D estimate's time; the same value to a few ulps.
inline double power_beta(double sigma, double beta) {
    if (beta == 0.75) {
        const double root = std::sqrt(sigma);
        return root * std::sqrt(root);
    }
    return std::pow(sigma, beta);
}

// A hypercube's count, mean and variance: RunningMoments::add's arithmetic without the third
// moment, which the hypercubes never read (the same values bit for bit, fewer operations).
class CubeMoments {
  public:
    void add(double x) {
        ++n_;
        sum_.add(x);
        const WelfordStep s(x, mean_, n_);
        mean_ += s.delta_n;
        m2_ += s.m2_increment;
    }
    uint64_t count() const { return n_; }
    double mean() const { return n_ ? sum_.value() / static_cast<double>(n_) : 0.0; }
    double variance() const { return n_ > 1 ? m2_ / static_cast<double>(n_ - 1) : 0.0; }

  private:
    uint64_t n_ = 0;
    NeumaierSum sum_;
    double mean_ = 0.0, m2_ = 0.0;
};

class VegasPlusEstimator final : public EstimatorAlgorithm, private TrainingPoints {
  public:
    VegasPlusEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec),
          options_(
              vegas_resolved(spec.vegas_options, spec.sampler, true, problem.domain.sample_dim())),
          float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& /*rng*/) override {
        const VegasOptions& o = options_;
        dim_ = problem_.domain.sample_dim();
        total_ = n;
        uint64_t train = static_cast<uint64_t>(o.train_fraction * static_cast<double>(n));
        iterations_ = vegas_training_iterations(o, train);
        final_ = n - train;
        // The grid of hypercubes: M per axis with about 4 points per hypercube in the smallest
        // iteration (at least 2 each, as the per-hypercube variances need).
        const uint64_t smallest = train >= 2 ? std::min(final_, train / iterations_) : final_;
        per_axis_ = vegas_plus_per_axis(dim_, smallest);
        cubes_ = 1;
        for (int j = 0; j < dim_; ++j) cubes_ *= per_axis_;
        if (train < 2 * cubes_) train = 0; // too small to train: one frozen (uniform) iteration
        if (train == 0) iterations_ = 0;
        final_ = n - train;
        train_ = train;
        int increments = iterations_ > 0
                             ? vegas_trainable_increments(o, dim_, train_ / iterations_, train_)
                             : (o.increments > 0 ? o.increments : vegas_increments(dim_, final_));
        nested_ = iterations_ >= kVegasSizingIterations && o.increments <= 0 &&
                  per_axis_ >= kVegasPlusNestedAxis;
        if (nested_) {
            // Two points per hypercube in the training, as GSL's boxes [Lepage78]: the map's
            // increments (K = M / b) follow the singularity only as finely as the hypercubes,
            // and at 4 points each a 3-D training iteration at N = 10^6 had 18 per axis against
            // GSL's 46 bins (2 points are all a hypercube's error needs; the training's
            // allocation is then even, as GSL's; what it gained: docs/performance-notes.md).
            per_axis_ = vegas_plus_per_axis(dim_, 2 * smallest);
            cubes_ = 1;
            for (int j = 0; j < dim_; ++j) cubes_ *= per_axis_;
            // GSL's stratified mode [Lepage78, sec. 3]: every increment holds a whole number b
            // of hypercubes per axis (b = ceil(M / K), K = M / b, M = b K), so that a
            // hypercube's spread is variance the estimate has, all of it from within one
            // increment of each axis: the map then trains on those errors (train).
            const uint64_t b = (per_axis_ + static_cast<uint64_t>(increments) - 1) /
                               static_cast<uint64_t>(increments);
            increments = static_cast<int>(per_axis_ / b);
            per_axis_ = b * static_cast<uint64_t>(increments);
            cubes_ = 1;
            for (int j = 0; j < dim_; ++j) cubes_ *= per_axis_;
        }
        alpha_ = nested_ && spec_.vegas_options.alpha < 0.0 ? kVegasNestedAlpha : o.alpha;
        stage_.reset(dim_, increments);
        sigma_.assign(cubes_, 1.0); // uniform allocation first
        trained_ = false;
        refined_ = false;
        piloting_ = false;
        pilot_ = 0;
        lambda_.clear();
        pilot_moments_.clear();
        planned_ = false;
        prepared_ = false;
        finished_final_ = false;
        log_.begin(stage_.map(), iterations_, static_cast<bool>(observer_));
        importance_.assign(kBlockSize, 1.0);
        weight_.assign(kBlockSize, 0.0);
        cube_of_.assign(kBlockSize, 0);
        offsets_.assign(static_cast<size_t>(dim_) * kBlockSize, 0.0);
    }

    bool run_block(Pcg32& rng, Workspace& ws) override {
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            prepared_ = true;
        }
        if (!trained_) {
            VegasOptions training = options_;
            training.alpha = alpha_;
            const TrainingSpent spent = train_map(stage_, training, problem_, spec_.proposal,
                                                  iterations_, train_, *this, rng, ws, log_);
            if (spent.iterations < iterations_ && spent.calls < train_) {
                final_ += train_ - spent.calls; // settled early: the calls left go to the estimate
                train_ = spent.calls;
            }
            if (nested_ && spent.iterations > 0) { // the last measured map (finish)
                stage_.map() = measured_map_;
                log_.adapted(stage_.map(), iterations_); // the history ends with the frozen map
            }
            trained_ = true;
        }
        if (!planned_) {
            if (finished_final_) return false;
            if (!refined_) {
                log_.end_training();
                pilot_ = refine_grid(final_);
                refined_ = true;
                if (pilot_ > 0) {
                    start_iteration(pilot_, rng, true);
                } else {
                    start_iteration(final_, rng, false);
                }
            } else {
                start_iteration(final_ - pilot_, rng, false); // after the pilot
            }
        }
        const size_t count = next(ws.u);
        if (count == 0) {
            if (piloting_) {
                finish_pilot();
            } else {
                finish_iteration(false);
            }
            return true;
        }
        stage_.warp(problem_, spec_.proposal, ws, false);
        evaluate_block(problem_.integrand, ws.x, ws.f.data());
        weigh(ws, count, weight_.data());
        // The pilot's points only size the allocation and join the estimate's hypercube means
        // (finish_iteration); the accumulator's diagnostics see the estimate's points.
        if (piloting_) return true;
        // The accumulator sees the weights scaled by V N / n_h (its plain mean is then the
        // stratified estimate), for its diagnostics: non-finite and zero-pdf counts, the
        // largest weights, the effective sample size.
        if (observer_) notify(block_of(ws, accumulated_, count));
        for (size_t i = 0; i < count; ++i) ws.pdf[i] /= importance_[i];
        accumulator_.add_block(accumulated_, ws.f.data(), ws.pdf.data(), ws.pdf.data(), count);
        accumulated_ += count;
        return true;
    }

    AdaptiveView adaptive_view() const override {
        AdaptiveView v = view_of(stage_.map());
        log_.add_history(&v);
        return v;
    }

    RunResult result() const override {
        RunResult r = final_result_;
        r.n = total_;
        log_.report(&r);
        return r;
    }

  private:
    // The estimate's hypercubes, sized by the estimate's own points: the training grid cut r
    // times finer on every axis [Lepage21, sec. 3 sizes the hypercubes by each iteration's
    // evaluations]. Stratification's gain grows with the number of strata: the training grid
    // alone left about 30 points per hypercube in the estimate at the default 10 iterations.
    // But VEGAS+'s allocation n_h ~ sigma_h^beta needs sigma_h measured on the hypercubes it
    // allocates [Lepage21, sec. 3]: inherited from its parent, a cut or a singularity got the
    // parent's share split evenly among r^d children, its child often only 2 points that miss
    // the cut or the tail's largest weights, and the error bar, dominated by that one child,
    // fell far short (1-D Genz discontinuous: 15-20 of 32 runs covered, the worst 170-230
    // standard errors off). So the finer grid is measured before it is used, as MISER explores
    // a region before it allocates to it [PressFarrar90]: a pilot of 2 points per hypercube (its
    // size returned; 0 when the points are too few) measures sigma_h (finish_pilot), and the
    // estimate's points, about 4 per hypercube (the grid is sized for 6), follow it. The
    // pilot's points count in a hypercube's estimate only with a weight its own points do not
    // set (pilot_weight): an allocation that depended on the points a hypercube's mean is made
    // of would bias it by O(1/n_h) in every hypercube, O(sqrt(N)/n_h) standard errors in all.
    uint64_t refine_grid(uint64_t points) {
        const uint64_t r = vegas_plus_per_axis(dim_, points * 2 / 3) / per_axis_; // 4 of 6
        if (r <= 1) return 0;
        const uint64_t fine = r * per_axis_;
        uint64_t cubes = 1;
        for (int j = 0; j < dim_; ++j) cubes *= fine;
        std::vector<double> sigma(cubes);
        parent_.resize(cubes);
        parents_ = cubes_;
        std::vector<uint64_t> digits(static_cast<size_t>(dim_), 0); // the last axis fastest
        for (uint64_t h = 0; h < cubes; ++h) { // the parents' sigma_h, without a pilot
            uint64_t parent = 0;
            for (int j = 0; j < dim_; ++j) parent = parent * per_axis_ + digits[j] / r;
            sigma[h] = sigma_[parent];
            parent_[h] = static_cast<uint32_t>(parent);
            for (int j = dim_ - 1; j >= 0; --j) {
                if (++digits[j] < fine) break;
                digits[j] = 0;
            }
        }
        sigma_.swap(sigma);
        per_axis_ = fine;
        cubes_ = cubes;
        const uint64_t pilot = 2 * cubes_;
        if (points < pilot + 4 * cubes_) return 0;
        lambda_.clear(); // set from the pilot (finish_pilot)
        return pilot;
    }

    // The pilot's share of the estimate in each hypercube, lambda_h (lambda_; empty: none):
    //   I = sum_h V (lambda_h mean_pilot,h + (1 - lambda_h) mean_h).
    // lambda_h depends on the pilot's points outside h only (`others`: the spread h's
    // neighbours' means imply and its siblings' median variance, each without h's own points),
    // so the combination is unbiased (given the pilot, the estimate's points are unbiased in
    // every hypercube; lambda_h is independent of h's pilot mean), and its variance, sum_h V^2
    // sigma_h^2 (lambda_h^2 / 2 + (1 - lambda_h)^2 / n_h), is estimated with the estimate's
    // s_h^2 in both terms (finish_iteration). lambda_h = min(kMostPilotShare, 2 / (2 + n_h)),
    // n_h the allocation `others` predict (allocate's shares, without the rounding): the
    // inverse-variance weight of the pilot's 2 points. Not the weight from the actual n_h: a
    // pilot that drew a large weight raises its n_h and lowers its own share, a bias toward
    // small estimates. Not n_h from the training's sigma_h alone (the parent's): the
    // hypercubes it did not foresee, along a cut, got large shares whose 2 pilot points then
    // dominated them, which needed the cap at 0.1, below the 2 / 7.5 of the pilot's points at
    // the 7.5 points a hypercube gets on average in 2-D at N = 10^6 (Genz discontinuous d = 2,
    // R = 30, relative RMSE: at N = 10^6 2.9e-4 without the pilot, 8.1e-4 with 2 / (2 + n_h)
    // uncapped; at 2^20 3.4e-4 with the cap 0.2, 2.2e-4 with 0.1, with `others` 2.3e-4 at 0.25).
    // The cap 0.25 stays: what h's own points show is not in `others` (a point singularity's
    // hypercube). Not in 1-D: a cut or a point singularity sits in one fine hypercube that
    // carries much of the variance, and its pilot's two-valued error went unseen (blind
    // calibrate at N = 65536 and 262144: runs 5.5-10 standard errors off on Genz
    // discontinuous and x^-a, 2026-12-07); in d >= 2 the variance spreads over the hypercubes
    // along a cut or an axis.
    // `others`: the variance `others` predict per hypercube (overwritten with its sigma).
    void pilot_weight(uint64_t estimate_points, std::vector<double>& others) {
        lambda_.clear();
        if (dim_ < 2) return;
        const uint64_t least = estimate_points >= 2 * cubes_ ? 2 : 1;
        const double rest =
            static_cast<double>(estimate_points - std::min(estimate_points, least * cubes_));
        for (double& v : others) v = std::sqrt(v);
        allocation_shares(others);
        lambda_.resize(cubes_);
        for (uint64_t h = 0; h < cubes_; ++h) {
            const double n = static_cast<double>(least) + rest * share_[h];
            lambda_[h] = std::min(kMostPilotShare, 2.0 / (2.0 + n));
        }
    }

    // sigma_h from the pilot's 2 points per hypercube, and at least the spread its
    // neighbours' means imply: a weight linear across the hypercube, with slope g_j per
    // hypercube width along axis j, varies there by sum_j g_j^2 / 12. Two points miss a cut
    // inside a hypercube with probability p^2 + (1-p)^2 and then report sigma_h = 0; its
    // neighbours, on either side of the cut, differ by the jump. And at least the median of its
    // siblings' (the children of its training hypercube): a variance from 2 points has one
    // degree of freedom, often far below sigma_h^2 (E[1 / s_h] is infinite), and where the
    // hypercubes average 10-20 points (d = 2-3, N = 10^6) the allocation starved some to 2 at
    // random. The median, not the mean: among the children of a hypercube that a cut crosses,
    // those off the cut keep their small spread.
    void finish_pilot() {
        std::vector<double> mean(cubes_);
        for (uint64_t h = 0; h < cubes_; ++h) mean[h] = cube_moments_[h].mean();
        std::vector<double> slopes(cubes_, 0.0), others(cubes_, 0.0);
        uint64_t stride = 1; // of axis j, the last axis fastest
        for (int j = dim_ - 1; j >= 0; --j) {
            for (uint64_t h = 0; h < cubes_; ++h) {
                const uint64_t digit = (h / stride) % per_axis_;
                const uint64_t lo = digit > 0 ? h - stride : h;
                const uint64_t hi = digit + 1 < per_axis_ ? h + stride : h;
                if (lo == hi) continue;
                const double g = (mean[hi] - mean[lo]) / static_cast<double>((hi - lo) / stride);
                slopes[h] += g * g / 12.0;
                if (lo != h && hi != h) others[h] += g * g / 12.0; // without h's own mean
            }
            stride *= per_axis_;
        }
        // The pilot's variances grouped by parent (counting sort), their medians the floors.
        std::vector<uint64_t> start(parents_ + 1, 0);
        for (uint64_t h = 0; h < cubes_; ++h) ++start[parent_[h] + 1];
        for (uint64_t q = 0; q < parents_; ++q) start[q + 1] += start[q];
        std::vector<uint64_t> at(start.begin(), start.end() - 1);
        std::vector<double> own(cubes_), grouped(cubes_), floor(parents_, 0.0);
        std::vector<MedianWithoutOne> without(parents_); // the siblings' medians without one
        for (uint64_t h = 0; h < cubes_; ++h) {
            own[h] = cube_moments_[h].variance();
            if (!std::isfinite(own[h])) own[h] = 0.0;
            grouped[at[parent_[h]]++] = own[h];
        }
        for (uint64_t q = 0; q < parents_; ++q) {
            if (start[q + 1] == start[q]) continue;
            double* first = grouped.data() + start[q];
            if (start[q + 1] - start[q] < 2) {
                floor[q] = *first;
                continue;
            }
            without[q] = median_without_one(first, grouped.data() + start[q + 1]);
            floor[q] = first[(start[q + 1] - start[q]) / 2];
        }
        for (uint64_t h = 0; h < cubes_; ++h) {
            const uint32_t q = parent_[h];
            others[h] = std::max(others[h], without[q].of(own[h]));
        }
        pilot_weight(final_ - pilot_, others);
        for (uint64_t h = 0; h < cubes_; ++h)
            sigma_[h] = std::sqrt(std::max({own[h], slopes[h], floor[parent_[h]]}));
        pilot_moments_.swap(cube_moments_);
        planned_ = false;
        piloting_ = false;
    }

    // The training points (TrainingPoints, for train_map): an iteration in the hypercubes.
    void start(uint64_t calls, Pcg32& rng) override { start_iteration(calls, rng, true); }
    void finish(VegasMap& map) override {
        flush_cube(map);
        finish_iteration(true);
        // Nested, the estimate keeps the map this iteration used, on which its sigma_h were
        // measured: with alpha 1.5 an error-trained map can overshoot in one step (Genz's
        // discontinuous family in 2-D: variance per point 1.4e6, then 1.4e9), and sigma_h from
        // the map before it then starve the hypercubes that now hold the variance (error bars
        // of half the RMSE). Not the iteration of least variance: that favours one whose
        // points missed a peak, and its sigma_h starve the peak.
        if (nested_) measured_map_ = map;
    }

    // Where the hypercubes are at least as fine as the map's increments (per_axis_ >= K, the
    // condition of GSL's stratified mode [Lepage78, sec. 3]), the map is trained on the errors:
    // a point counts for its increments with its squared deviation from its hypercube's mean,
    // (w - mean_h)^2 n_h / (n_h - 1), not w^2, so that the increments shrink where the
    // stratified estimate's variance comes from (a singularity's hypercubes), not where w^2 is
    // large. Coarser hypercubes hold the variance between increments too, which the map alone
    // (w^2) balances. A hypercube's points wait in train until its last one is seen.
    void train(VegasMap& map, const uint32_t* bins, const double* weights, const double* importance,
               size_t count) override {
        if (per_axis_ < static_cast<uint64_t>(map.increments()) ||
            per_axis_ % static_cast<uint64_t>(map.increments()) != 0) {
            map.add_training(bins, weights, importance, count);
            return;
        }
        for (size_t i = 0; i < count; ++i) {
            if (cube_of_[i] != pending_cube_) flush_cube(map);
            pending_cube_ = cube_of_[i];
            for (int j = 0; j < dim_; ++j)
                pending_bins_.push_back(bins[static_cast<size_t>(j) * kBlockSize + i]);
            pending_w_.push_back(weights[i]);
            pending_c_.push_back(importance[i]);
        }
    }
    void flush_cube(VegasMap& map) {
        const size_t n = pending_w_.size();
        if (n >= 2) {
            const double mean = cube_moments_[pending_cube_].mean();
            const double unbiased = static_cast<double>(n) / static_cast<double>(n - 1);
            for (size_t i = 0; i < n; ++i) {
                const double dev = pending_w_[i] - mean;
                map.add_square(pending_bins_.data() + i * static_cast<size_t>(dim_), 1,
                               unbiased * dev * dev, pending_c_[i]);
            }
        }
        pending_bins_.clear();
        pending_w_.clear();
        pending_c_.clear();
    }

    // The iteration's next block: points of the current hypercube, then the next ones.
    size_t next(PointBlock& u) override {
        size_t count = 0;
        while (count < kBlockSize && cube_ < cubes_) {
            if (left_in_cube_ == 0) {
                if (++cube_ == cubes_) break;
                advance_digits();
                left_in_cube_ = allocation_[cube_];
                continue;
            }
            for (int j = 0; j < dim_; ++j) { // the draws; their positions in a second pass
                u.coord(j)[count] = jitter_.next_double();
                offsets_[static_cast<size_t>(j) * kBlockSize + count] =
                    static_cast<double>(digits_[j]);
            }
            cube_of_[count] = static_cast<uint32_t>(cube_);
            --left_in_cube_;
            ++count;
        }
        // y = (digit + draw) / M per axis, in loops the compiler vectorises.
        const double per_axis = static_cast<double>(per_axis_);
        for (int j = 0; j < dim_; ++j) {
            double* y = u.coord(j);
            const double* offset = offsets_.data() + static_cast<size_t>(j) * kBlockSize;
            for (size_t i = 0; i < count; ++i) y[i] = below_one((offset[i] + y[i]) / per_axis);
        }
        if (count > 0) u.n = count;
        return count;
    }

    // The block's weights w = f J / p into `weights` (dropped ones as 0, as the weight
    // accumulator drops and counts them) and into their hypercubes' moments; the points'
    // importance 1 / q(y) relative to uniform, V N / n_h, into importance_.
    const double* weigh(const Workspace& ws, size_t count, double* weights) override {
        const double n_iteration = static_cast<double>(points_);
        for (size_t i = 0; i < count; ++i) {
            const double w = ws.f[i] / ws.pdf[i];
            weights[i] = std::isfinite(w) && !(ws.pdf[i] == 0.0 && ws.f[i] != 0.0) ? w : 0.0;
        }
        // A hypercube's points come in a row: its moments and importance once per run.
        for (size_t i = 0; i < count;) {
            const uint32_t h = cube_of_[i];
            size_t end = i + 1;
            while (end < count && cube_of_[end] == h) ++end;
            CubeMoments m = cube_moments_[h];
            for (size_t k = i; k < end; ++k) m.add(weights[k]);
            cube_moments_[h] = m;
            const double importance =
                n_iteration / (static_cast<double>(cubes_) * static_cast<double>(allocation_[h]));
            for (size_t k = i; k < end; ++k) importance_[k] = importance;
            i = end;
        }
        return importance_.data();
    }

    // Allocation n_h = 2 + the rest of the iteration's points in proportion to sigma_h^beta
    // (largest remainders), so that they sum to the iteration's size exactly.
    void start_iteration(uint64_t points, Pcg32& rng, bool training) {
        points_ = allocate(points, &allocation_);
        cube_moments_.assign(cubes_, CubeMoments());
        const uint64_t seed = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        const uint64_t stream = (uint64_t(rng.next_u32()) << 32) | rng.next_u32();
        jitter_ = Pcg32(seed, stream);
        cube_ = 0;
        digits_.assign(static_cast<size_t>(dim_), 0);
        left_in_cube_ = allocation_[0];
        piloting_ = training && refined_;
        if (!training) {
            plan_ = SamplerPlan(); // the accumulator's iid error method reads no plan data
            plan_.dim = dim_;
            plan_.total = points_;
            accumulator_.reset(ErrorMethod::Iid, plan_, float32_);
            accumulated_ = 0;
        }
        planned_ = true;
    }

    // The allocation of `points` over the hypercubes from sigma_: n_h = 2 + the rest in
    // proportion to sigma_h^beta; the points allocated returned.
    uint64_t allocate(uint64_t points, std::vector<uint64_t>* allocation) {
        // Two points per hypercube; one only in a run of one point (then no error bar).
        const uint64_t least = points >= 2 * cubes_ ? 2 : 1;
        points = std::max<uint64_t>(points, least * cubes_);
        allocation->assign(cubes_, least);
        const uint64_t rest = points - least * cubes_;
        if (rest == 0) return points; // the pilot: 2 points each
        allocation_shares(sigma_);
        allocate_largest_remainders(rest, share_, allocation);
        return points;
    }

    // share_[h]: hypercube h's share of the points past the 2 each, from `sigma` per hypercube:
    // in proportion to sigma_h^beta, mixed with the even share.
    void allocation_shares(const std::vector<double>& sigma) {
        std::vector<double>& share = share_;
        share.resize(cubes_);
        double total = 0.0;
        // sigma_h^beta, once per run of equal sigma_h: the children of a training hypercube
        // inherit its sigma_h (refine_grid), r of them in a row on the last axis.
        double last_sigma = std::numeric_limits<double>::quiet_NaN(), last_share = 0.0;
        for (uint64_t h = 0; h < cubes_; ++h) {
            if (!(sigma[h] == last_sigma)) {
                last_sigma = sigma[h];
                last_share = power_beta(last_sigma, options_.beta);
                if (!std::isfinite(last_share)) last_share = 0.0;
            }
            share[h] = last_share;
            total += share[h];
        }
        if (!(total > 0.0)) {
            std::fill(share.begin(), share.end(), 1.0);
            total = static_cast<double>(cubes_);
        }
        // The even share (as for the map's increments): a hypercube whose training points all
        // saw f = 0 may still hold a sliver of a large f (a cut); with only its 2 points it would
        // mostly miss it and report a variance of 0.
        const double even = options_.uniform_share;
        for (uint64_t h = 0; h < cubes_; ++h)
            share[h] = (1.0 - even) * share[h] / total + even / static_cast<double>(cubes_);
    }

    void advance_digits() {
        for (int j = dim_ - 1; j >= 0; --j) {
            if (++digits_[j] < per_axis_) return;
            digits_[j] = 0;
        }
    }

    void finish_iteration(bool training) {
        // sigma_h for the next allocation; the stratified estimate and its variance.
        const double volume = 1.0 / static_cast<double>(cubes_);
        StratifiedSum strata;
        const bool combined = !training && !lambda_.empty() && pilot_ > 0;
        for (uint64_t h = 0; h < cubes_; ++h) {
            const CubeMoments& m = cube_moments_[h];
            sigma_[h] = std::sqrt(m.variance());
            if (!combined) { // StratifiedSum::add(volume, m)'s terms
                const uint64_t n = m.count();
                if (n > 0)
                    strata.add_part(volume * m.mean(),
                                    volume * volume * m.variance() / static_cast<double>(n), n);
                continue;
            }
            const CubeMoments& p = pilot_moments_[h];
            const double lambda = lambda_[h];
            const double n = static_cast<double>(m.count());
            const double factor = lambda * lambda / static_cast<double>(p.count()) +
                                  (1.0 - lambda) * (1.0 - lambda) / n;
            strata.add_part(volume * (lambda * p.mean() + (1.0 - lambda) * m.mean()),
                            volume * volume * m.variance() * factor, m.count());
        }
        planned_ = false;
        if (training) return; // train_map adapts the map
        const double scale = quantity_scale(problem_);
        final_result_ = accumulator_.finish(scale);
        final_result_.estimate = scale * strata.estimate();
        final_result_.std_error = strata.has_variance() ? scale * std::sqrt(strata.variance())
                                                        : std::numeric_limits<double>::quiet_NaN();
        final_result_.dof = strata.dof();
        finished_final_ = true;
    }

    const Problem& problem_;
    const EstimatorSpec& spec_;
    const VegasOptions options_; // spec_'s, the defaults filled in
    bool float32_;
    int dim_ = 1;
    uint64_t total_ = 0, train_ = 0, final_ = 0, points_ = 0, accumulated_ = 0;
    uint64_t per_axis_ = 1, cubes_ = 1, cube_ = 0, left_in_cube_ = 0;
    int iterations_ = 0;
    bool nested_ = false;   // hypercubes nested in the map's increments (begin)
    double alpha_ = 0.5;    // the map's damping: options_'s, or kVegasNestedAlpha when nested_
    VegasMap measured_map_; // nested: the map the last training iteration used (finish)
    bool trained_ = false, planned_ = false, prepared_ = false, finished_final_ = false;
    bool refined_ = false;                   // the estimate's grid is set (refine_grid)
    bool piloting_ = false;                  // the current points are the pilot's (finish_pilot)
    uint64_t pilot_ = 0;                     // the pilot's points, 0 without one
    std::vector<double> lambda_;             // the pilot's share per hypercube (pilot_weight)
    std::vector<CubeMoments> pilot_moments_; // the pilot's, per hypercube (finish_pilot)
    std::vector<uint32_t> parent_;           // the estimate's hypercubes' training ones
    uint64_t parents_ = 0;                   // the training grid's hypercubes
    TrainingLog log_;
    MapStage stage_; // the map and its buffers
    Pcg32 jitter_;
    std::vector<uint64_t> digits_, allocation_;
    std::vector<double> sigma_, importance_, weight_;
    std::vector<double> share_; // allocate's, kept between iterations
    std::vector<uint32_t> cube_of_;
    std::vector<double> offsets_; // next's hypercube digits per axis and point
    std::vector<CubeMoments> cube_moments_;
    uint32_t pending_cube_ = 0;          // the hypercube whose training points wait (train)
    std::vector<uint32_t> pending_bins_; // per waiting point, its dim increments
    std::vector<double> pending_w_, pending_c_;
    SamplerPlan plan_; // the run's points
    WeightAccumulator accumulator_;
    RunResult final_result_;
};

} // namespace

const EstimatorKind& vegas_plus_estimator_kind() {
    static const EstimatorKind kind{
        "vegas_plus",
        "VEGAS+: the VEGAS map and adaptively allocated hypercubes, trained then frozen",
        [](const EstimatorSpec&) { return "vegas_plus"; },
        // the sum of independent parts: the hypercubes
        [](const EstimatorSpec&) { return ErrorMethod::PartsSum; },
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<VegasPlusEstimator>(problem, spec, accumulator);
        },
        [](const EstimatorSpec&) { return false; }, // a learnt map and allocation
        true,
    };
    return kind;
}

} // namespace mcp
