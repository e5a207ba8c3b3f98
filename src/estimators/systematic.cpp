// Systematic sampling [Owen13, ch. 10; CranleyPatterson76]: each randomization is a grid of m
// points, g_a cells along axis a (g_0 g_1 ... g_{d-1} = m, stratification_grid), every cell
// holding the point at the same offset s of its cell:
//   x_c = ((c_0 + s_0) / g_0, ..., (c_{d-1} + s_{d-1}) / g_{d-1}),   s uniform on [0,1)^d,
// the grid of cell corners rotated modulo 1 [CranleyPatterson76] (shifting by s/g gives the
// point sets a uniform shift modulo 1 gives: the grid is invariant under shifts by 1/g). Each
// x_c is uniform, so the batch mean
// b = (1/m) sum_c f(x_c) / p(x_c) is unbiased; a run of N points is K = 16 independent shifts
// of N/K points, its estimate the mean of the K batch means and its error bar their spread,
// s_b / sqrt(K) on K - 1 degrees of freedom [LEcuyerLemieux02]. One shift for every cell, where
// stratified sampling jitters each cell apart: for a smooth f the cells' errors do not cancel,
// a grid of g = m^(1/d) cells per axis errs by O(1/g), and the variance falls as N^(-2/d), N^-2
// in 1D (where the grid is the rank-1 lattice) but the uniform N^-1 in 2D and slower beyond,
// against stratified sampling's N^(-1-2/d) [Owen13, ch. 10]: the teaching contrast.
#include <algorithm>
#include <string>

#include "estimators/estimator_kind.h"

namespace mcp {
namespace {

constexpr int kSystematicShifts = 16; // K: independent randomizations per run

class SystematicEstimator final : public EstimatorAlgorithm {
  public:
    SystematicEstimator(const Problem& problem, const EstimatorSpec& spec, Accumulator accumulator)
        : problem_(problem), spec_(spec), float32_(accumulator == Accumulator::Float32) {}

    void begin(uint64_t n, Pcg32& rng) override {
        total_ = std::max<uint64_t>(n, 1);
        dim_ = problem_.domain.sample_dim();
        const size_t k = static_cast<size_t>(std::min<uint64_t>(kSystematicShifts, total_));
        shifts_.resize(k * static_cast<size_t>(dim_));
        for (double& s : shifts_) s = rng.next_double();
        accumulator_.reset(ErrorMethod::Randomizations, total_, k, float32_);
        grid_size_ = 0;
        next_ = 0;
        prepared_ = false;
    }

    bool run_block(Pcg32& /*rng*/, Workspace& ws) override {
        if (next_ >= total_) return false;
        if (!prepared_) {
            prepare_workspace(problem_.domain, ws);
            ws.batch.clear();
            prepared_ = true;
        }
        const size_t count = static_cast<size_t>(std::min<uint64_t>(kBlockSize, total_ - next_));
        const SampleBlock b =
            batched_block(problem_, next_, count, total_, ws,
                          [&](uint64_t first, size_t m) { make_points(first, m, ws); });
        notify(b);
        accumulator_.add_block(b.first, b.f, b.pdf, b.pdf, b.count); // weights overwrite p
        next_ += count;
        return true;
    }

    PointDesign design() const override {
        const size_t k = shifts_.size() / static_cast<size_t>(std::max(dim_, 1));
        return {stratification_grid(total_ / std::max<size_t>(k, 1), dim_), 1, k};
    }

    RunResult result() const override {
        RunResult r = accumulator_.finish(quantity_scale(problem_));
        r.n = total_;
        return r;
    }

  private:
    size_t batches() const { return shifts_.size() / static_cast<size_t>(dim_); }
    uint64_t batch_begin(size_t k) const { return total_ * k / batches(); }

    // Points first .. first + m - 1 of the run into ws.u, warped into ws.x and ws.pdf.
    void make_points(uint64_t first, size_t m, Workspace& ws) {
        for (size_t i = 0; i < m; ++i) {
            const uint64_t index = first + i;
            size_t k = static_cast<size_t>(index * batches() / total_);
            while (batch_begin(k + 1) <= index) ++k;
            while (batch_begin(k) > index) --k;
            const uint64_t begin = batch_begin(k), size = batch_begin(k + 1) - begin;
            if (size != grid_size_) {
                grid_ = stratification_grid(size, dim_);
                grid_size_ = size;
            }
            uint64_t cell = index - begin; // its cell, mixed radix, axis 0 fastest
            const double* s = &shifts_[k * static_cast<size_t>(dim_)];
            for (int a = 0; a < dim_; ++a) {
                const uint64_t g = grid_[static_cast<size_t>(a)];
                const uint64_t c = cell % g;
                cell /= g;
                const double x = (static_cast<double>(c) + s[a]) / static_cast<double>(g);
                ws.u.coord(a)[i] = below_one(x);
            }
        }
        ws.u.n = m;
        warp_block(spec_.proposal, problem_.domain, ws.u, ws.x, ws.pdf.data());
    }

    const Problem& problem_;
    const EstimatorSpec& spec_;
    bool float32_;
    int dim_ = 1;
    uint64_t total_ = 0, next_ = 0, grid_size_ = 0;
    bool prepared_ = false;
    std::vector<double> shifts_; ///< K shifts s in [0,1)^d, shift k at [k d, (k + 1) d)
    std::vector<uint64_t> grid_; ///< cells per axis of a batch of grid_size_ points
    WeightAccumulator accumulator_;
};

PointWords systematic_words(const EstimatorSpec&) {
    return {"systematic", "random_shift", kSystematicShifts};
}

// A study's runs are K grids of N/K points, N doubling from n_first to n_max: N/K must be a
// whole number of points, and the largest runs' grids must cut every axis at least twice
// (2^d points), or the dimension is too high for a grid (smaller runs leave some axes uncut:
// still unbiased, the cut axes stratified).
std::string systematic_check(const EstimatorSpec&, const StudyShape& study) {
    const uint64_t k = kSystematicShifts;
    const int d = study.dim;
    const std::string grids = "systematic sampling runs " + std::to_string(k) +
                              " shifted grids of N/" + std::to_string(k) + " points";
    const uint64_t least = d < 58 ? k << d : 0; // 16 x 2^d, 0 past 2^64
    if (least == 0 || least > study.n_max)
        return grids + ", each to be cut at least twice along every axis: in " + std::to_string(d) +
               " dimensions that takes N >= " + std::to_string(k) + " x 2^" + std::to_string(d) +
               (least ? " = " + std::to_string(least) : "") +
               ", beyond n_max = " + std::to_string(study.n_max) +
               ": raise n_max, or use latin_hypercube or sobol in this many dimensions";
    if (study.n_first < k)
        return grids + ": n_min must be at least " + std::to_string(k) + ", got " +
               std::to_string(study.n_first);
    if (study.n_first % k != 0)
        return grids + ": n_min must be a multiple of " + std::to_string(k) + ", got " +
               std::to_string(study.n_first);
    return "";
}

} // namespace

const EstimatorKind& systematic_estimator_kind() {
    static const EstimatorKind kind{
        "systematic",
        "systematic sampling: 16 randomly shifted grids of N/16 points, the error bar from the "
        "spread of their means",
        [](const EstimatorSpec&) { return "systematic"; },
        [](const EstimatorSpec&) { return ErrorMethod::Randomizations; },
        [](const Problem& problem, const EstimatorSpec& spec,
           Accumulator accumulator) -> std::unique_ptr<EstimatorAlgorithm> {
            return std::make_unique<SystematicEstimator>(problem, spec, accumulator);
        },
        [](const EstimatorSpec&) { return false; }, // a design of all N
        false,
        systematic_words,
        systematic_check,
    };
    return kind;
}

} // namespace mcp
