// The chi-square test of a warp: see warp_test.h. The samples are drawn, warped and binned
// block by block; the pdf is integrated over every bin by a pair of tensor rules of degree 5
// (Gauss-Legendre of 3 nodes per axis and an inset Gauss-Lobatto of 4), cells where the two
// disagree being halved along the axes where they vary most, level by level, so that steps,
// peaks and singular lines inside a bin are resolved (every level's nodes run through the pdf
// in blocks); bins where a sample's pdf stands far above the nodes are integrated again around
// their samples; then the counts are pooled and the statistic, its range under the
// quadrature's error and the verdict computed.
#include "estimators/warp_test.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "core/points.h"
#include "core/rng.h"
#include "core/special.h"
#include "core/stats.h" // NeumaierSum
#include "core/trig.h"  // sincos_turns

namespace mcp {
namespace {

/// A cell's quadrature is refined when its two rules differ by more than this share of
/// sqrt(expected / bins) of its bin's count (so that the errors of all bins add up to a small
/// part of the statistic's spread)...
constexpr double kCountAccuracy = 0.1;
/// ... and by more than a threshold in probability scaled by this share of pdf_tolerance (see
/// integrate_bins), so that the summed error estimate stays under the tolerance.
constexpr double kIntegralAccuracy = 0.01;
/// Most cells in one level of the refinement (bounds its memory).
constexpr size_t kMaxCellsPerLevel = size_t(1) << 18;
/// The error estimate of a cell: this multiple of its two rules' difference. Smooth pdfs give
/// differences far above the error; a step's error may exceed the difference (by up to 1.4 in
/// 1-D, more where an edge crosses a cell's corner: a triangle's edges left 4 times it).
constexpr double kErrorSafety = 8.0;
/// A bin's expected count is settled when its error is under this share of sqrt(expected).
constexpr double kTrustedError = 0.05;
/// Pooling threshold on the expected count of a cell [Mitsuba3].
constexpr double kMinExpected = 5.0;

std::string fmt(double v, int digits = 4) {
    if (std::isnan(v)) return "NaN"; // printf writes "nan" or "-nan"
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.*g", digits, v);
    return buf;
}

std::string tuple(const double* v, int n) {
    std::string s = "(";
    for (int j = 0; j < n; ++j) s += (j ? ", " : "") + fmt(v[j], 10);
    return s + ")";
}

/// atan(a) for a in [0, 1] to 1.4e-8 [AS64, 4.4.49]: a first guess of the azimuth's bin, which
/// Natural::azimuth_bin then corrects exactly.
double atan_unit(double a) {
    static const double c[9] = {0.0028662257,  -0.0161657367, 0.0429096138,
                                -0.0752896400, 0.1065626393,  -0.1420889944,
                                0.1999355085,  -0.3333314528, 1.0};
    const double s = a * a;
    double p = c[0];
    for (int i = 1; i < 9; ++i) p = p * s + c[i];
    return a * p;
}

/// phi / 2 pi in [0, 1] of the direction (x, y), to ~2e-9; y < 0 gives phi in [pi, 2 pi].
double approx_turns(double x, double y) {
    const double ax = std::fabs(x), ay = std::fabs(y);
    const double big = ax > ay ? ax : ay, small = ax > ay ? ay : ax;
    double r = big > 0.0 ? atan_unit(small / big) : 0.0;
    r = ay > ax ? 0.5 * kPi - r : r;
    r = x < 0.0 ? kPi - r : r;
    const double t = r * (0.5 / kPi);
    return y < 0.0 ? 1.0 - t : t;
}

/// The domain's natural coordinates (warp_test.h): forward (t -> x) for the quadrature's
/// nodes, backward (x -> t, with the membership test) for the samples.
class Natural {
  public:
    /// bins: per axis, for bin_block (may be null for forward alone).
    explicit Natural(const Domain& d, const int* bins = nullptr) : d_(d) {
        axes_ = d.kind == DomainKind::Box ? static_cast<int>(d.lo.size()) : 2;
        if (bins && d.kind != DomainKind::Box && d.kind != DomainKind::Triangle) {
            // The azimuth's bin edges as unit vectors, e_j at phi = 2 pi j / bins.
            const int nb = bins[1];
            edges_.resize(size_t(nb) + 1);
            for (int j = 0; j <= nb; ++j) {
                const SinCos e = sincos_turns(static_cast<double>(j) / nb);
                edges_[size_t(j)] = Vec2{e.cos, e.sin};
            }
        }
        if (d.kind == DomainKind::Triangle) {
            e0_ = d.v0 - d.v2;
            e1_ = d.v1 - d.v2;
            inv_det_ = 1.0 / (e0_.x * e1_.y - e1_.x * e0_.y);
        }
    }
    int axes() const { return axes_; }

    std::vector<std::string> names() const {
        switch (d_.kind) {
        case DomainKind::Box: {
            static const char* const kNames[3] = {"(x - lo) / (hi - lo)", "(y - lo) / (hi - lo)",
                                                  "(z - lo) / (hi - lo)"};
            return std::vector<std::string>(kNames, kNames + axes_);
        }
        case DomainKind::Disk: return {"|x - c|^2 / R^2", "phi / 2 pi"};
        case DomainKind::Triangle: return {"(1 - b0)^2", "b1 / (1 - b0)"};
        case DomainKind::Sphere: return {"(1 - z) / 2", "phi / 2 pi"};
        case DomainKind::Hemisphere: return {"1 - z", "phi / 2 pi"};
        }
        return {};
    }

    /// x (point_dim coordinates) of t.
    void forward(const double* t, double* x) const {
        switch (d_.kind) {
        case DomainKind::Box:
            for (int j = 0; j < axes_; ++j)
                x[j] = d_.lo[size_t(j)] + (d_.hi[size_t(j)] - d_.lo[size_t(j)]) * t[j];
            return;
        case DomainKind::Disk: {
            const double r = d_.radius * std::sqrt(t[0]), phi = 2.0 * kPi * t[1];
            x[0] = d_.center.x + r * std::cos(phi);
            x[1] = d_.center.y + r * std::sin(phi);
            return;
        }
        case DomainKind::Triangle: {
            const double s = std::sqrt(t[0]);
            const double b0 = 1.0 - s, b1 = t[1] * s;
            const Vec2 q = b0 * d_.v0 + b1 * d_.v1 + (1.0 - b0 - b1) * d_.v2;
            x[0] = q.x;
            x[1] = q.y;
            return;
        }
        case DomainKind::Sphere:
        case DomainKind::Hemisphere: {
            const bool sphere = d_.kind == DomainKind::Sphere;
            const double z = sphere ? 1.0 - 2.0 * t[0] : 1.0 - t[0];
            const double r =
                sphere ? 2.0 * std::sqrt(t[0] * (1.0 - t[0])) : std::sqrt(t[0] * (2.0 - t[0]));
            const double phi = 2.0 * kPi * t[1];
            x[0] = r * std::cos(phi);
            x[1] = r * std::sin(phi);
            x[2] = z;
            return;
        }
        }
    }

    /// t of a point x in the domain (std::atan2 for the azimuth), each in [0, 1).
    void backward(const double* x, double* t) const {
        auto turns = [](double a, double b) {
            const double phi = std::atan2(b, a) * (0.5 / kPi);
            return phi < 0.0 ? phi + 1.0 : phi;
        };
        t[0] = t[1] = t[2] = 0.0;
        switch (d_.kind) {
        case DomainKind::Box:
            for (int j = 0; j < axes_; ++j)
                t[j] = (x[j] - d_.lo[size_t(j)]) / (d_.hi[size_t(j)] - d_.lo[size_t(j)]);
            break;
        case DomainKind::Disk: {
            const double dx = x[0] - d_.center.x, dy = x[1] - d_.center.y;
            t[0] = (dx * dx + dy * dy) / (d_.radius * d_.radius);
            t[1] = turns(dx, dy);
            break;
        }
        case DomainKind::Triangle: {
            const double px = x[0] - d_.v2.x, py = x[1] - d_.v2.y;
            const double b0 = (px * e1_.y - e1_.x * py) * inv_det_;
            const double b1 = (e0_.x * py - px * e0_.y) * inv_det_;
            const double s = 1.0 - b0;
            t[0] = s * s;
            t[1] = s > 0.0 ? b1 / s : 0.0;
            break;
        }
        case DomainKind::Sphere:
        case DomainKind::Hemisphere:
            t[0] = d_.kind == DomainKind::Sphere ? 0.5 * (1.0 - x[2]) : 1.0 - x[2];
            t[1] = turns(x[0], x[1]);
            break;
        }
        const double below_one = std::nextafter(1.0, 0.0);
        for (int j = 0; j < axes_; ++j) t[j] = std::min(std::max(t[j], 0.0), below_one);
    }

    /// Writes the flat bin of each of the n points of x; returns the index of the first point
    /// outside the domain (beyond kWarpDomainTolerance), or n.
    size_t bin_block(const PointBlock& x, size_t n, const int* bins, uint32_t* out) const {
        constexpr double tol = kWarpDomainTolerance;
        auto flat = [&](double t0, double t1, double t2) {
            const double t[3] = {t0, t1, t2};
            uint32_t index = 0, stride = 1;
            for (int j = 0; j < axes_; ++j) {
                int k = static_cast<int>(t[j] * bins[j]);
                k = k < 0 ? 0 : (k >= bins[j] ? bins[j] - 1 : k);
                index += stride * static_cast<uint32_t>(k);
                stride *= static_cast<uint32_t>(bins[j]);
            }
            return index;
        };
        // A radial coordinate t0 and the azimuth's bin.
        auto flat_azimuth = [&](double t0, double px, double py) {
            int k = static_cast<int>(t0 * bins[0]);
            k = k < 0 ? 0 : (k >= bins[0] ? bins[0] - 1 : k);
            return static_cast<uint32_t>(k) +
                   static_cast<uint32_t>(bins[0]) *
                       static_cast<uint32_t>(azimuth_bin(px, py, bins[1]));
        };
        switch (d_.kind) {
        case DomainKind::Box: {
            double lo[3] = {0, 0, 0}, w[3] = {1, 1, 1};
            for (int j = 0; j < axes_; ++j) {
                lo[j] = d_.lo[size_t(j)];
                w[j] = d_.hi[size_t(j)] - d_.lo[size_t(j)];
            }
            for (size_t i = 0; i < n; ++i) {
                double t[3] = {0, 0, 0};
                for (int j = 0; j < axes_; ++j) {
                    t[j] = (x.coord(j)[i] - lo[j]) / w[j];
                    if (!(t[j] >= -tol && t[j] <= 1.0 + tol)) return i;
                }
                out[i] = flat(t[0], t[1], t[2]);
            }
            return n;
        }
        case DomainKind::Disk: {
            const double inv_r2 = 1.0 / (d_.radius * d_.radius), limit = (1 + tol) * (1 + tol);
            for (size_t i = 0; i < n; ++i) {
                const double dx = x.coord(0)[i] - d_.center.x, dy = x.coord(1)[i] - d_.center.y;
                const double r2 = (dx * dx + dy * dy) * inv_r2;
                if (!(r2 <= limit)) return i;
                out[i] = flat_azimuth(r2, dx, dy);
            }
            return n;
        }
        case DomainKind::Triangle:
            for (size_t i = 0; i < n; ++i) {
                const double px = x.coord(0)[i] - d_.v2.x, py = x.coord(1)[i] - d_.v2.y;
                const double b0 = (px * e1_.y - e1_.x * py) * inv_det_;
                const double b1 = (e0_.x * py - px * e0_.y) * inv_det_;
                if (!(b0 >= -tol && b1 >= -tol && 1.0 - b0 - b1 >= -tol)) return i;
                const double s = 1.0 - b0;
                out[i] = flat(s * s, s > 0.0 ? b1 / s : 0.0, 0.0);
            }
            return n;
        case DomainKind::Sphere:
        case DomainKind::Hemisphere: {
            const bool sphere = d_.kind == DomainKind::Sphere;
            for (size_t i = 0; i < n; ++i) {
                const double a = x.coord(0)[i], b = x.coord(1)[i], z = x.coord(2)[i];
                const double r2 = a * a + b * b + z * z;
                if (!(std::fabs(r2 - 1.0) <= 2.0 * tol) || !(sphere || z >= -tol)) return i;
                out[i] = flat_azimuth(sphere ? 0.5 * (1.0 - z) : 1.0 - z, a, b);
            }
            return n;
        }
        }
        return 0;
    }

  private:
    /// The bin of phi / 2 pi of (x, y) among nb: approx_turns' guess, moved to the bin whose
    /// edges e_k, e_k+1 have v at or past e_k (e_k x v >= 0) and before e_k+1, the cross
    /// products' signs being exact up to rounding and valid within half a turn of the edge.
    int azimuth_bin(double x, double y, int nb) const {
        int k = static_cast<int>(approx_turns(x, y) * nb);
        k = k < 0 ? 0 : (k >= nb ? nb - 1 : k);
        auto past = [&](int j) {
            const Vec2& e = edges_[size_t(j)];
            return e.x * y - e.y * x >= 0.0;
        };
        while (k > 0 && !past(k)) --k;
        while (k + 1 < nb && past(k + 1)) ++k;
        return k;
    }

    const Domain& d_;
    std::vector<Vec2> edges_;
    int axes_ = 1;
    Vec2 e0_{0.0}, e1_{0.0};
    double inv_det_ = 0.0;
};

/// One node of the pair of rules on [0, 1]^k: its position and its weight in each rule.
struct Node {
    double at[3];
    double w3, w4; ///< in the Gauss-Legendre rule (3 nodes per axis), in the Lobatto one (4)
};

/// How far the end nodes of the second rule sit inside the cell (a share of its width): off
/// the domain's boundary, where a pdf may be singular or a direction ambiguous.
constexpr double kEndInset = 1e-3;

/// Tensor rules of 3 and 4 points per axis on [0, 1]^k, one after the other: Gauss-Legendre
/// (the value), and Gauss-Lobatto with its end nodes moved in by kEndInset and its interior
/// nodes and weights solved again for degree 5 (the check). A step inside a cell changes the
/// two rules' sums by different amounts wherever it lies (their cumulative weights, 0.28,
/// 0.72 at 0.11, 0.5, 0.89 and 0.084, 0.5, 0.92 at 0.001, 0.28, 0.72, 0.999, never coincide
/// between the inset end nodes), so it is always detected; two Gauss rules would both miss a
/// step near an edge of the cell, and two symmetric rules of even order one in its middle.
std::vector<Node> rule_pair(int k) {
    const double g3x[3] = {0.5 - 0.5 * std::sqrt(0.6), 0.5, 0.5 + 0.5 * std::sqrt(0.6)};
    const double g3w[3] = {5.0 / 18.0, 8.0 / 18.0, 5.0 / 18.0};
    // Symmetric nodes 1/2 -+ sqrt(e), 1/2 -+ sqrt(m) with weights we, wm: exact for 1, t^2
    // and t^4 about 1/2 (the odd powers by symmetry) when we + wm = 1/2, we e + wm m = 1/24,
    // we e^2 + wm m^2 = 1/160; e is fixed by the inset, which gives m and the weights
    // (kEndInset = 0: Gauss-Lobatto, m = 1/20, we = 1/12).
    const double e = (0.5 - kEndInset) * (0.5 - kEndInset);
    const double m = (1.0 / 160.0 - e / 24.0) / (1.0 / 24.0 - e / 2.0);
    const double we = (1.0 / 24.0 - m / 2.0) / (e - m), wm = 0.5 - we;
    const double l4x[4] = {kEndInset, 0.5 - std::sqrt(m), 0.5 + std::sqrt(m), 1.0 - kEndInset};
    const double l4w[4] = {we, wm, wm, we};
    std::vector<Node> nodes;
    for (int rule = 0; rule < 2; ++rule) {
        const int count_1d = rule == 0 ? 3 : 4;
        const double* xs = rule == 0 ? g3x : l4x;
        const double* ws = rule == 0 ? g3w : l4w;
        int count = 1;
        for (int j = 0; j < k; ++j) count *= count_1d;
        for (int c = 0; c < count; ++c) {
            Node nd{{0.5, 0.5, 0.5}, 0.0, 0.0};
            double w = 1.0;
            for (int j = 0, r = c; j < k; ++j, r /= count_1d) {
                nd.at[j] = xs[r % count_1d];
                w *= ws[r % count_1d];
            }
            (rule == 0 ? nd.w3 : nd.w4) = w;
            nodes.push_back(nd);
        }
    }
    return nodes;
}

/// A cell of the quadrature: a box of [0, 1)^k inside one bin, of width 2^-level[j] of the
/// bin's along axis j.
struct Cell {
    double lo[3];
    uint32_t bin;
    uint16_t level[3];
    bool seeded; ///< it or a parent held a probe far above its nodes: it may go deeper
    uint32_t seed_begin, seed_end; ///< the probes inside it (a range of integrate_bins' seeds)
};

/// A sample kept to probe the pdf where the quadrature's nodes may not have looked.
struct Probe {
    double t[3] = {0.0, 0.0, 0.0}, x[3] = {0.0, 0.0, 0.0};
    double pdf = 0.0;
    uint64_t sample = 0;
};
/// Samples kept per bin (the first ones to fall in it) to find the bins to check again...
constexpr int kProbesPerBin = 4;
/// ... with their first samples, up to this many per bin: a part of the pdf the nodes missed
/// that none of them reveals holds under 1/4096 of its bin's samples, its expected count E
/// under E / 4096 (below sqrt(E) while E < 1.7e7).
constexpr uint64_t kSeedsPerBin = 4096;
/// A probe whose pdf exceeds this multiple of every node of its cell sits on a peak the nodes
/// missed (a smooth pdf varies far less between a cell's nodes and any point of it).
constexpr double kProbeRatio = 4.0;

struct Quadrature {
    std::vector<double> expected;       ///< per bin, N times the integral
    std::vector<double> expected_error; ///< per bin, N times the summed rule differences
    std::vector<double> max_pdf;        ///< per bin, the largest value at a node
    std::vector<uint8_t> unresolved;    ///< per bin, a probe's peak never seen by the nodes
    double integral = 0.0, error = 0.0;
    uint64_t evaluations = 0;
    std::string error_message;
};

/// The expected counts of the bins `which` (flat indices, ascending), by the adaptive rule
/// pair (see the top of the file). `seeds` (sorted by bin, may be empty): a cell holding a
/// seed whose pdf is far above all its nodes is split until its nodes see the peak, deeper
/// than the usual levels (the seeds are reordered as cells split).
Quadrature integrate_bins(const Domain& domain, const Warp& warp, const Natural& natural,
                          const int* bins, size_t nbins, const std::vector<uint32_t>& which,
                          std::vector<Probe>& seeds, const std::vector<uint32_t>& seed_bin,
                          double n_samples, double tolerance) {
    const int k = natural.axes();
    const int point_dim = domain.point_dim();
    const std::vector<Node> nodes = rule_pair(k);
    const size_t per_cell = nodes.size();
    // 1-D refinement halves one cell per level towards a singular point (x^-0.9 keeps 8% of
    // its mass below 1e-11), so it may go as deep as doubles resolve; so may a cell split
    // along one axis alone (a peak or a singular line across a bin). Split along every axis,
    // a line or a surface of cells doubles per level in 2-D and 3-D: their depth (the least
    // level over the axes) is bounded. Seeded cells follow one probe each.
    const int max_level = k == 1 ? 1100 : (k == 2 ? 12 : 7);
    const int max_seeded_level = k == 1 ? 1100 : (k == 2 ? 32 : 20);
    const int max_axis_level = 1100;
    const double measure = domain.measure();
    double bin_width[3] = {1.0, 1.0, 1.0};
    for (int j = 0; j < k; ++j) bin_width[j] = 1.0 / bins[j];
    // The threshold in probability of a cell that is a share f of the domain: tol' f^((k-1)/k)
    // with tol' = kIntegralAccuracy tol. A step across a square or cube crosses about
    // f^((1-k)/k) cells of share f, so the cells along it accept errors that sum to about tol'
    // per unit of its length or area, at every level; in 1D the few cells of a step cost
    // little, and theirs is tol' / 1e6.
    auto mass_threshold = [&](const Cell& cell) {
        int levels = 0;
        for (int j = 0; j < k; ++j) levels += cell.level[j];
        const double share = std::ldexp(1.0 / static_cast<double>(nbins), -levels);
        const double t = kIntegralAccuracy * tolerance;
        return k == 1 ? t * 1e-6 : t * std::pow(share, (k - 1.0) / k);
    };
    // A cell narrower than this share of its position cannot place distinct nodes.
    auto divisible = [&](const Cell& cell) {
        for (int j = 0; j < k; ++j) {
            const double w = std::ldexp(bin_width[j], -cell.level[j]);
            if (!(w > 1e-12 * (cell.lo[j] + w) && w > 1e-290)) return false;
        }
        return true;
    };

    Quadrature q;
    q.expected.assign(nbins, 0.0);
    q.expected_error.assign(nbins, 0.0);
    q.max_pdf.assign(nbins, 0.0);
    q.unresolved.assign(nbins, 0);
    std::vector<double> bin_estimate(nbins, 0.0);
    std::vector<Cell> cells(which.size());
    for (size_t c = 0; c < which.size(); ++c) {
        Cell& cell = cells[c];
        size_t r = which[c];
        for (int j = 0; j < 3; ++j) {
            cell.lo[j] = 0.0;
            if (j < k) {
                cell.lo[j] = static_cast<double>(r % size_t(bins[j])) * bin_width[j];
                r /= size_t(bins[j]);
            }
        }
        cell.bin = which[c];
        cell.level[0] = cell.level[1] = cell.level[2] = 0;
        cell.seeded = false;
        const auto range = std::equal_range(seed_bin.begin(), seed_bin.end(), which[c]);
        cell.seed_begin = static_cast<uint32_t>(range.first - seed_bin.begin());
        cell.seed_end = static_cast<uint32_t>(range.second - seed_bin.begin());
    }
    // A seed inside the cell with a pdf above kProbeRatio times all its nodes.
    auto probe_above = [&](const Cell& cell, double node_max) {
        for (uint32_t i = cell.seed_begin; i < cell.seed_end; ++i)
            if (seeds[i].pdf > kProbeRatio * node_max) return true;
        return false;
    };
    // The child (bit j: upper half along axis j, of the axes in `axes`) of a cell holding t.
    auto child_of = [&](const Cell& cell, unsigned axes, const double* t) {
        size_t child = 0;
        for (int j = 0; j < k; ++j)
            if ((axes >> j & 1u) &&
                t[j] >= cell.lo[j] + std::ldexp(bin_width[j], -cell.level[j] - 1))
                child |= size_t(1) << j;
        return child;
    };
    auto cell_volume = [&](const Cell& cell) {
        double volume = measure;
        for (int j = 0; j < k; ++j) volume *= std::ldexp(bin_width[j], -cell.level[j]);
        return volume;
    };

    PointBlock x;
    x.reset(point_dim, kBlockSize);
    double pdf[kBlockSize], w3[kBlockSize], w4[kBlockSize];
    uint32_t owner[kBlockSize];
    std::vector<double> q3, q4, qmax;
    // Per cell and axis, the Gauss rule's sums over its three node planes along that axis.
    std::vector<double> planes;
    uint16_t node_of[kBlockSize];
    NeumaierSum integral, error;
    while (!cells.empty()) {
        // The cells' two rules, their nodes through the pdf a block at a time.
        q3.assign(cells.size(), 0.0);
        q4.assign(cells.size(), 0.0);
        qmax.assign(cells.size(), 0.0);
        planes.assign(cells.size() * 9, 0.0);
        size_t fill = 0;
        auto flush = [&]() -> bool {
            x.n = fill;
            warp.pdf(x, pdf);
            q.evaluations += fill;
            for (size_t i = 0; i < fill; ++i) {
                if (!(pdf[i] >= 0.0) || !std::isfinite(pdf[i])) {
                    double at[3];
                    for (int j = 0; j < point_dim; ++j) at[j] = x.coord(j)[i];
                    q.error_message = "the pdf is " + fmt(pdf[i], 10) +
                                      " at x = " + tuple(at, point_dim) + " (in " +
                                      domain.describe() + "): a density must be finite and >= 0";
                    return false;
                }
                q3[owner[i]] += w3[i] * pdf[i];
                q4[owner[i]] += w4[i] * pdf[i];
                if (w3[i] != 0.0)
                    for (int j = 0, r = node_of[i]; j < k; ++j, r /= 3)
                        planes[owner[i] * 9 + size_t(j) * 3 + size_t(r % 3)] += w3[i] * pdf[i];
                qmax[owner[i]] = std::max(qmax[owner[i]], pdf[i]);
            }
            fill = 0;
            return true;
        };
        for (size_t c = 0; c < cells.size(); ++c) {
            const Cell& cell = cells[c];
            double width[3] = {1.0, 1.0, 1.0};
            for (int j = 0; j < k; ++j) width[j] = std::ldexp(bin_width[j], -cell.level[j]);
            for (size_t ni = 0; ni < nodes.size(); ++ni) {
                const Node& nd = nodes[ni];
                double t[3] = {0.5, 0.5, 0.5}, at[3];
                for (int j = 0; j < k; ++j) t[j] = cell.lo[j] + width[j] * nd.at[j];
                natural.forward(t, at);
                for (int j = 0; j < point_dim; ++j) x.coord(j)[fill] = at[j];
                w3[fill] = nd.w3;
                w4[fill] = nd.w4;
                owner[fill] = static_cast<uint32_t>(c);
                node_of[fill] = static_cast<uint16_t>(ni); // the Gauss rule's nodes come first
                if (++fill == kBlockSize && !flush()) return q;
            }
        }
        if (fill > 0 && !flush()) return q;

        // Accept the cells whose rules agree, or that may not be split further.
        struct Candidate {
            size_t cell;
            double err, priority;
            bool seed;
            unsigned axes; ///< bit j: split along axis j
        };
        // The axes along which the cell varies most (second differences and slopes of its
        // node planes' sums): all of them for a seed or a cell flat in the Gauss nodes.
        auto split_axes = [&](size_t c, bool seed) {
            const unsigned all = (1u << k) - 1u;
            if (seed || k == 1) return all;
            double v[3] = {0.0, 0.0, 0.0}, most = 0.0;
            for (int j = 0; j < k; ++j) {
                // Each plane's sum over its own weight along j (5/18, 8/18, 5/18): the mean of
                // the pdf over the plane, as the other axes' weights give it.
                const double* p = &planes[c * 9 + size_t(j) * 3];
                const double g[3] = {p[0] * 3.6, p[1] * 2.25, p[2] * 3.6};
                v[j] = std::fabs(g[2] - g[0]) + std::fabs(g[0] - 2.0 * g[1] + g[2]);
                most = std::max(most, v[j]);
            }
            if (!(most > 0.0)) return all;
            unsigned axes = 0;
            for (int j = 0; j < k; ++j)
                if (v[j] >= 0.25 * most && cells[c].level[j] < max_axis_level) axes |= 1u << j;
            return axes ? axes : all;
        };
        std::vector<Candidate> split;
        auto accept = [&](const Cell& cell, double mass, double err, bool seed) {
            q.expected[cell.bin] += n_samples * mass;
            q.expected_error[cell.bin] += n_samples * err;
            if (seed) q.unresolved[cell.bin] = 1;
            integral.add(mass);
            error.add(err);
        };
        for (size_t c = 0; c < cells.size(); ++c) {
            const Cell& cell = cells[c];
            q.max_pdf[cell.bin] = std::max(q.max_pdf[cell.bin], qmax[c]);
            const double volume = cell_volume(cell);
            const double m3 = volume * q3[c], m4 = volume * q4[c];
            const double err = kErrorSafety * std::fabs(m4 - m3);
            const int depth = *std::min_element(cell.level, cell.level + k);
            if (depth == 0 && *std::max_element(cell.level, cell.level + k) == 0)
                bin_estimate[cell.bin] = n_samples * m3;
            // Errors of every bin near this share of sqrt(expected) sum, in the statistic, to
            // a small part of one degree of freedom (see quadrature_chi_square).
            const double count_threshold =
                kCountAccuracy *
                std::sqrt(std::max(bin_estimate[cell.bin], 1.0) / static_cast<double>(nbins)) /
                n_samples;
            const bool seed = probe_above(cell, qmax[c]);
            const int deepest = cell.seeded || seed ? max_seeded_level : max_level;
            const bool can_split = depth < deepest && divisible(cell);
            const bool refine =
                can_split && (seed || err > std::min(count_threshold, mass_threshold(cell)));
            if (refine)
                split.push_back({c, err, seed ? HUGE_VAL : err, seed, split_axes(c, seed)});
            else
                accept(cell, m3, err, seed);
        }
        // Within the budget (pdf evaluations and cells per level), seeded cells and the
        // largest errors first; the rest are accepted as they are.
        const size_t children = size_t(1) << k;
        const uint64_t left = kMaxWarpTestPdfEvaluations > q.evaluations
                                  ? kMaxWarpTestPdfEvaluations - q.evaluations
                                  : 0;
        const size_t affordable = std::min(static_cast<size_t>(left / (children * per_cell)),
                                           kMaxCellsPerLevel / children);
        if (split.size() > affordable) {
            std::stable_sort(
                split.begin(), split.end(),
                [](const Candidate& a, const Candidate& b) { return a.priority > b.priority; });
            for (size_t s = affordable; s < split.size(); ++s) {
                const size_t c = split[s].cell;
                accept(cells[c], cell_volume(cells[c]) * q3[c], split[s].err, split[s].seed);
            }
            split.resize(affordable);
        }
        std::vector<Cell> next;
        next.reserve(split.size() * children);
        for (const Candidate& s : split) {
            const Cell& parent = cells[s.cell];
            // The parent's seeds in the order of its children.
            const auto first = seeds.begin() + parent.seed_begin;
            const auto last = seeds.begin() + parent.seed_end;
            std::stable_sort(first, last, [&](const Probe& a, const Probe& b) {
                return child_of(parent, s.axes, a.t) < child_of(parent, s.axes, b.t);
            });
            uint32_t at = parent.seed_begin;
            for (size_t child = 0; child < children; ++child) {
                if (child & ~size_t(s.axes)) continue; // a bit of an axis not split
                Cell c = parent;
                c.seeded = parent.seeded || s.seed;
                for (int j = 0; j < k; ++j) {
                    if (!(s.axes >> j & 1u)) continue;
                    c.level[j] = static_cast<uint16_t>(parent.level[j] + 1);
                    if (child >> j & 1u) c.lo[j] += std::ldexp(bin_width[j], -c.level[j]);
                }
                c.seed_begin = at;
                while (at < parent.seed_end && child_of(parent, s.axes, seeds[at].t) == child) ++at;
                c.seed_end = at;
                next.push_back(c);
            }
        }
        cells.swap(next);
    }
    q.integral = integral.value();
    q.error = error.value();
    return q;
}

std::string bin_text(const WarpTestResult& r, const WarpTestBin& b) {
    std::string s = "bin (";
    for (int j = 0; j < r.axes; ++j) s += (j ? ", " : "") + std::to_string(b.index[j]);
    s += "):";
    for (int j = 0; j < r.axes; ++j)
        s += (j ? "," : "") + std::string(" ") + r.axis_names[size_t(j)] + " in [" + fmt(b.lo[j]) +
             ", " + fmt(b.hi[j]) + ")";
    return s;
}

WarpTestBin describe_bin(const WarpTestResult& r, size_t flat) {
    WarpTestBin b;
    size_t rest = flat;
    for (int j = 0; j < r.axes; ++j) {
        b.index[j] = static_cast<int>(rest % size_t(r.bins[j]));
        rest /= size_t(r.bins[j]);
        b.lo[j] = static_cast<double>(b.index[j]) / r.bins[j];
        b.hi[j] = static_cast<double>(b.index[j] + 1) / r.bins[j];
    }
    b.observed = r.observed[flat];
    b.expected = r.expected[flat];
    const double diff = static_cast<double>(b.observed) - b.expected;
    b.residual =
        b.expected > 0.0 ? diff / std::sqrt(b.expected) : (b.observed > 0 ? HUGE_VAL : 0.0);
    return b;
}

/// The words for a natural axis's ranges: its low end, its high end and between; an azimuth
/// (periodic) has none, its ranges being quarter turns.
struct AxisWords {
    std::string low, high, middle;
    bool periodic = false;
};

AxisWords axis_words(const Domain& d, int axis, int axes) {
    auto point = [](Vec2 v) { return "(" + fmt(v.x) + ", " + fmt(v.y) + ")"; };
    switch (d.kind) {
    case DomainKind::Box: {
        const std::string name(1, "xyz"[axis]);
        const std::string side = axes == 1 ? "" : (axes == 2 ? "the edge " : "the face ");
        return {"near " + side + name + " = " + fmt(d.lo[size_t(axis)]),
                "near " + side + name + " = " + fmt(d.hi[size_t(axis)]),
                "in the middle of " + name + "'s range"};
    }
    case DomainKind::Disk:
        if (axis == 0) return {"near the centre", "near the rim", "between the centre and the rim"};
        break;
    case DomainKind::Sphere:
        if (axis == 0) return {"near the pole z = 1", "near the pole z = -1", "around the equator"};
        break;
    case DomainKind::Hemisphere:
        if (axis == 0)
            return {"near the pole z = 1", "near the horizon z = 0",
                    "between the pole and the horizon"};
        break;
    case DomainKind::Triangle: {
        const std::string v0 = point(d.v0), v1 = point(d.v1), v2 = point(d.v2);
        if (axis == 0)
            return {"near the vertex " + v0, "near the edge " + v1 + " " + v2,
                    "between the vertex " + v0 + " and the opposite edge"};
        return {"near the edge " + v0 + " " + v2, "near the edge " + v0 + " " + v1,
                "between the edges from " + v0};
    }
    }
    return {"", "", "", true};
}

/// WarpTestResult::where (see warp_test.h): "" when no range departs.
std::string mass_departures(const Domain& d, const WarpTestResult& r) {
    const size_t nbins = r.observed.size();
    double total_e = 0.0, total_d = 0.0, n = 0.0;
    for (size_t b = 0; b < nbins; ++b) {
        n += static_cast<double>(r.observed[b]);
        if (r.expected[b] > 0.0) {
            total_e += r.expected[b];
            total_d += r.expected_error[b];
        }
    }
    if (!(total_e > 0.0) || !(n > 0.0)) return "";
    const double scale = n / total_e; // p's shape: its expected counts summed to the samples'
    struct Range {
        std::string words;
        double observed = 0.0, expected = 0.0, error = 0.0;
    };
    std::vector<std::vector<Range>> axes(size_t(r.axes));
    size_t count = 0, stride = 1;
    for (int j = 0; j < r.axes; stride *= size_t(r.bins[j]), ++j) {
        const int nb = r.bins[j];
        if (nb < 2) continue;
        std::vector<double> o(size_t(nb), 0.0), e(size_t(nb), 0.0), err(size_t(nb), 0.0);
        for (size_t b = 0; b < nbins; ++b) {
            const size_t i = (b / stride) % size_t(nb);
            o[i] += static_cast<double>(r.observed[b]);
            e[i] += scale * r.expected[b];
            err[i] += scale * r.expected_error[b];
        }
        const AxisWords w = axis_words(d, j, r.axes);
        std::vector<std::pair<int, std::string>> starts; // first bin of each range, its words
        if (w.periodic) {
            const int g = std::min(nb, 4);
            for (int q = 0; q < g; ++q) {
                const int first = q * nb / g, last = (q + 1) * nb / g;
                starts.push_back({first, "at azimuths phi in [" + fmt(360.0 * first / nb, 3) +
                                             ", " + fmt(360.0 * last / nb, 3) + ") degrees"});
            }
        } else {
            const int edge = std::max(1, static_cast<int>(std::lround(nb / 4.0)));
            starts.push_back({0, w.low});
            if (edge < nb - edge) starts.push_back({edge, w.middle});
            starts.push_back({nb - edge, w.high});
        }
        for (size_t s = 0; s < starts.size(); ++s) {
            Range range;
            range.words = starts[s].second;
            const int end = s + 1 < starts.size() ? starts[s + 1].first : nb;
            for (int i = starts[s].first; i < end; ++i) {
                range.observed += o[size_t(i)];
                range.expected += e[size_t(i)];
                range.error += err[size_t(i)];
            }
            // the total's error moves every range's share
            range.error += range.expected * total_d / total_e;
            axes[size_t(j)].push_back(range);
            ++count;
        }
    }
    // Each range's count is binomial (n, E / n) when the samples follow p: a departure beyond
    // the quadrature's error is named at the level split over all the ranges.
    const double level = r.level / static_cast<double>(std::max<size_t>(count, 1));
    auto share = [&](double v) { return fmt(100.0 * v / n, 3) + "%"; };
    std::vector<std::string> sentences;
    bool radial = false, azimuthal = false;
    for (int j = 0; j < r.axes; ++j) {
        std::vector<std::string> many, few;
        for (const Range& g : axes[size_t(j)]) {
            const double excess = std::fabs(g.observed - g.expected) - g.error;
            const double sd = std::sqrt(g.expected * std::max(1.0 - g.expected / n, 0.0));
            if (!(excess > 0.0) || !(sd > 0.0)) continue;
            const double z = excess / sd;
            if (!(chi_square_sf(z * z, 1.0) < level)) continue;
            (g.observed > g.expected ? many : few)
                .push_back(g.words + " (" + share(g.observed) + " where p expects " +
                           share(g.expected) + ")");
        }
        if (many.empty() && few.empty()) continue;
        auto join = [](const std::vector<std::string>& v) {
            std::string s;
            for (size_t i = 0; i < v.size(); ++i) s += (i ? " and " : "") + v[i];
            return s;
        };
        std::string s;
        if (!many.empty()) s = "too many samples " + join(many);
        if (!few.empty()) s += (s.empty() ? "too few samples " : ", too few ") + join(few);
        (axis_words(d, j, r.axes).periodic ? azimuthal : radial) = true;
        sentences.push_back(s);
    }
    const bool round = d.kind == DomainKind::Disk || d.kind == DomainKind::Sphere ||
                       d.kind == DomainKind::Hemisphere;
    if (round && radial && !azimuthal) sentences[0] += ", in every direction";
    std::string out;
    for (size_t i = 0; i < sentences.size(); ++i) out += (i ? "; " : "") + sentences[i];
    return out;
}

std::string check_options(const WarpTestOptions& o, int axes) {
    if (o.samples < 1 || o.samples > kMaxWarpTestSamples)
        return "warp test: samples must be in 1.." + std::to_string(kMaxWarpTestSamples) +
               ", got " + std::to_string(o.samples);
    uint64_t total = 1;
    for (int j = 0; j < axes; ++j) {
        if (o.bins[j] < 0 || o.bins[j] > kMaxWarpTestBinsPerAxis)
            return "warp test: bins[" + std::to_string(j) + "] must be in 0.." +
                   std::to_string(kMaxWarpTestBinsPerAxis) + " (0: the default), got " +
                   std::to_string(o.bins[j]);
        total *= static_cast<uint64_t>(std::max(o.bins[j], 1));
    }
    if (total > static_cast<uint64_t>(kMaxWarpTestBins))
        return "warp test: at most " + std::to_string(kMaxWarpTestBins) + " bins in all, got " +
               std::to_string(total);
    if (!(o.significance > 0.0 && o.significance < 1.0))
        return "warp test: significance must be in (0, 1), got " + fmt(o.significance, 10);
    if (o.tests < 1 || o.tests > 1000000)
        return "warp test: tests must be in 1..1000000, got " + std::to_string(o.tests);
    if (o.worst < 0 || o.worst > 1000)
        return "warp test: worst must be in 0..1000, got " + std::to_string(o.worst);
    if (!(o.pdf_tolerance > 0.0 && o.pdf_tolerance < 1.0))
        return "warp test: pdf_tolerance must be in (0, 1), got " + fmt(o.pdf_tolerance, 10);
    return "";
}

} // namespace

double sidak_level(double alpha, int tests) {
    return -std::expm1(std::log1p(-alpha) / static_cast<double>(tests));
}

const char* warp_test_outcome_name(WarpTestOutcome o) {
    switch (o) {
    case WarpTestOutcome::Passed: return "passed";
    case WarpTestOutcome::Failed: return "failed";
    case WarpTestOutcome::Unverified: return "unverified";
    }
    return "unverified";
}

int default_warp_test_bins(uint64_t samples, int axes) {
    const double n = static_cast<double>(samples);
    const int per_axis = static_cast<int>(std::floor(0.25 * std::pow(n, 2.0 / (axes + 4.0)) + 0.5));
    int cap = kMaxWarpTestBinsPerAxis;
    while (axes > 1 && std::pow(static_cast<double>(cap), axes) > kMaxWarpTestBins) --cap;
    return std::min(std::max(per_axis, 2), cap);
}

void pooled_chi_square(const std::vector<uint64_t>& observed, const std::vector<double>& expected,
                       double* chi_square, int* cells, int* pooled_bins) {
    double error_chi = 0.0, max_relative = 0.0;
    pooled_chi_square(observed, expected, std::vector<double>(expected.size(), 0.0), chi_square,
                      cells, pooled_bins, &error_chi, &max_relative);
}

void pooled_chi_square(const std::vector<uint64_t>& observed, const std::vector<double>& expected,
                       const std::vector<double>& expected_error, double* chi_square, int* cells,
                       int* pooled_bins, double* error_chi_square, double* max_relative_error) {
    std::vector<size_t> order(expected.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::stable_sort(order.begin(), order.end(),
                     [&](size_t a, size_t b) { return expected[a] < expected[b]; });
    double chi = 0.0, pool_e = 0.0, pool_o = 0.0, pool_d = 0.0;
    double last_e = 0.0, last_o = 0.0, last_d = 0.0; // the last cell emitted, for a leftover
    double err_chi = 0.0, max_rel = 0.0;
    int count = 0, pooled = 0;
    bool pool_open = false;
    auto term = [](double o, double e) { return (o - e) * (o - e) / e; };
    auto emit = [&](double o, double e, double d) {
        chi += term(o, e);
        err_chi += d * d / e;
        max_rel = std::max(max_rel, d / e);
        last_e = e;
        last_o = o;
        last_d = d;
        ++count;
    };
    for (size_t i : order) {
        const double e = expected[i], o = static_cast<double>(observed[i]);
        const double d = expected_error[i];
        if (!(e > 0.0)) continue;
        if (e < kMinExpected || pool_open) {
            pool_e += e;
            pool_o += o;
            pool_d += d;
            ++pooled;
            pool_open = true;
            if (pool_e >= kMinExpected) {
                emit(pool_o, pool_e, pool_d);
                pool_e = pool_o = pool_d = 0.0;
                pool_open = false;
            }
            continue;
        }
        emit(o, e, d);
    }
    if (pool_open) {
        if (count > 0) { // the leftover joins the last cell: replace its terms
            chi -= term(last_o, last_e);
            err_chi -= last_d * last_d / last_e;
            --count;
            emit(last_o + pool_o, last_e + pool_e, last_d + pool_d);
        } else {
            emit(pool_o, pool_e, pool_d);
        }
    }
    *chi_square = chi;
    *cells = count;
    *pooled_bins = pooled;
    *error_chi_square = err_chi;
    *max_relative_error = max_rel;
}

namespace {

/// Checks the domain, the warp and the options, and resolves the bins per axis (1 for unused
/// axes). Returns an error or "".
std::string set_up(const Domain& domain, const Warp& warp, const WarpTestOptions& options,
                   int* bins) {
    const int point_dim = domain.point_dim();
    if (point_dim < 1 || point_dim > kMaxWarpDim)
        return "warp test: the domain has " + std::to_string(point_dim) + " coordinates; at most " +
               std::to_string(kMaxWarpDim);
    if (!warp.map || !warp.pdf) return "warp test: warp '" + warp.name + "' has no map or no pdf";
    if (warp.sample_dim != domain.sample_dim())
        return "warp test: warp '" + warp.name + "' reads " + std::to_string(warp.sample_dim) +
               " unit-cube coordinates, the domain " + domain.describe() + " is sampled from " +
               std::to_string(domain.sample_dim());
    const int axes = Natural(domain).axes();
    if (std::string e = check_options(options, axes); !e.empty()) return e;
    const int by_samples = default_warp_test_bins(options.samples, axes);
    for (int j = 0; j < 3; ++j)
        bins[j] = j >= axes ? 1 : (options.bins[j] > 0 ? options.bins[j] : by_samples);
    return "";
}

} // namespace

Made<WarpTestExpectation> expect_warp_counts(const Domain& domain, const Warp& warp,
                                             const WarpTestOptions& options) {
    WarpTestExpectation e;
    if (std::string error = set_up(domain, warp, options, e.bins); !error.empty())
        return made_error<WarpTestExpectation>(error);
    e.samples = options.samples;
    const size_t nbins = static_cast<size_t>(e.bins[0]) * e.bins[1] * e.bins[2];
    std::vector<uint32_t> all(nbins);
    std::iota(all.begin(), all.end(), uint32_t(0));
    std::vector<Probe> no_seeds;
    Quadrature q = integrate_bins(domain, warp, Natural(domain), e.bins, nbins, all, no_seeds, {},
                                  static_cast<double>(options.samples), options.pdf_tolerance);
    if (!q.error_message.empty()) return made_error<WarpTestExpectation>(q.error_message);
    e.expected = std::move(q.expected);
    e.expected_error = std::move(q.expected_error);
    e.max_pdf = std::move(q.max_pdf);
    e.pdf_integral = q.integral;
    e.pdf_integral_error = q.error;
    e.pdf_evaluations = q.evaluations;
    return {std::move(e), {}};
}

Made<WarpTestResult> run_warp_test(const Domain& domain, const Warp& warp,
                                   const WarpTestOptions& options) {
    Made<WarpTestExpectation> e = expect_warp_counts(domain, warp, options);
    if (!e.ok()) return made_error<WarpTestResult>(e.error);
    return run_warp_test(domain, warp, options, e.value);
}

Made<WarpTestResult> run_warp_test(const Domain& domain, const Warp& warp,
                                   const WarpTestOptions& options,
                                   const WarpTestExpectation& expectation) {
    WarpTestResult r;
    if (std::string e = set_up(domain, warp, options, r.bins); !e.empty())
        return made_error<WarpTestResult>(e);
    const size_t nbins = static_cast<size_t>(r.bins[0]) * r.bins[1] * r.bins[2];
    if (expectation.samples != options.samples ||
        !std::equal(r.bins, r.bins + 3, expectation.bins) || expectation.expected.size() != nbins ||
        expectation.expected_error.size() != nbins || expectation.max_pdf.size() != nbins)
        return made_error<WarpTestResult>(
            "warp test: the expected counts were computed for other samples or bins");
    const Natural natural(domain, r.bins);
    const int point_dim = domain.point_dim();
    r.axes = natural.axes();
    r.axis_names = natural.names();
    r.samples = options.samples;
    const double n_samples = static_cast<double>(options.samples);

    // Samples: PCG32 in the order sample by sample, coordinate by coordinate, a block at a
    // time to `visit(x, n, bins, first sample)`; the same seed draws them again.
    const int sd = warp.sample_dim;
    PointBlock u, xs;
    u.reset(sd, kBlockSize);
    xs.reset(point_dim, kBlockSize);
    uint32_t bin[kBlockSize];
    auto draw = [&](auto&& visit) -> std::string {
        Pcg32 rng(options.seed, kWarpTestStream);
        for (uint64_t start = 0; start < options.samples; start += kBlockSize) {
            const size_t n =
                static_cast<size_t>(std::min<uint64_t>(kBlockSize, options.samples - start));
            for (size_t i = 0; i < n; ++i)
                for (int j = 0; j < sd; ++j) u.coord(j)[i] = rng.next_double();
            u.n = n;
            xs.n = n;
            warp.map(u, xs);
            xs.n = n;
            const size_t bad = natural.bin_block(xs, n, r.bins, bin);
            if (bad < n) {
                double uu[kMaxWarpDim], xx[kMaxWarpDim];
                for (int j = 0; j < sd; ++j) uu[j] = u.coord(j)[bad];
                for (int j = 0; j < point_dim; ++j) xx[j] = xs.coord(j)[bad];
                return "sample " + std::to_string(start + bad) + " (u = " + tuple(uu, sd) +
                       ") maps to x = " + tuple(xx, point_dim) + ", outside the domain " +
                       domain.describe();
            }
            visit(n, start);
        }
        return "";
    };
    auto keep = [&](std::vector<Probe>& into, size_t i, uint64_t start) {
        Probe p;
        for (int j = 0; j < point_dim; ++j) p.x[j] = xs.coord(j)[i];
        p.sample = start + i;
        into.push_back(p);
    };
    // The pdf at probes, and their t; an error for a value no density takes.
    auto evaluate = [&](std::vector<Probe>& ps) -> std::string {
        PointBlock x;
        x.reset(point_dim, kBlockSize);
        double pdf[kBlockSize];
        for (size_t start = 0; start < ps.size(); start += kBlockSize) {
            const size_t n = std::min(kBlockSize, ps.size() - start);
            for (size_t i = 0; i < n; ++i)
                for (int j = 0; j < point_dim; ++j) x.coord(j)[i] = ps[start + i].x[j];
            x.n = n;
            warp.pdf(x, pdf);
            for (size_t i = 0; i < n; ++i) {
                Probe& p = ps[start + i];
                if (!(pdf[i] >= 0.0) || !std::isfinite(pdf[i]))
                    return "the pdf is " + fmt(pdf[i], 10) + " at x = " + tuple(p.x, point_dim) +
                           " (in " + domain.describe() + "): a density must be finite and >= 0";
                p.pdf = pdf[i];
                natural.backward(p.x, p.t);
            }
        }
        return "";
    };
    auto bin_of = [&](const Probe& p) {
        uint32_t flat = 0, stride = 1;
        for (int j = 0; j < r.axes; ++j) {
            const int b = std::min(static_cast<int>(p.t[j] * r.bins[j]), r.bins[j] - 1);
            flat += stride * static_cast<uint32_t>(b);
            stride *= static_cast<uint32_t>(r.bins[j]);
        }
        return flat;
    };

    // First pass: the counts, and the first kProbesPerBin samples of each bin as probes.
    r.observed.assign(nbins, 0);
    std::vector<Probe> kept;
    if (std::string e = draw([&](size_t n, uint64_t start) {
            for (size_t i = 0; i < n; ++i)
                if (r.observed[bin[i]]++ < kProbesPerBin) keep(kept, i, start);
        });
        !e.empty())
        return made_error<WarpTestResult>(e);
    if (std::string e = evaluate(kept); !e.empty()) return made_error<WarpTestResult>(e);
    const Probe* zero_probe = nullptr;
    for (const Probe& p : kept)
        if (p.pdf == 0.0) {
            ++r.zero_pdf_samples;
            if (!zero_probe || p.sample < zero_probe->sample) zero_probe = &p;
        }

    // Expected counts; bins where a probe stands far above every node (a peak or a part of
    // the support the nodes missed) are integrated again, refined around all their samples.
    r.expected = expectation.expected;
    r.expected_error = expectation.expected_error;
    r.pdf_evaluations = expectation.pdf_evaluations;
    std::vector<uint8_t> flagged(nbins, 0);
    std::vector<uint32_t> again;
    for (const Probe& p : kept) {
        const uint32_t b = bin_of(p);
        if (p.pdf > kProbeRatio * expectation.max_pdf[b] && !flagged[b]) {
            flagged[b] = 1;
            again.push_back(b);
        }
    }
    std::sort(again.begin(), again.end());
    NeumaierSum integral, error;
    integral.add(expectation.pdf_integral);
    error.add(expectation.pdf_integral_error);
    if (!again.empty()) {
        // Second pass: the samples of those bins (up to kSeedsPerBin each) seed the refinement.
        std::vector<Probe> seeds;
        std::vector<uint64_t> taken(nbins, 0);
        draw([&](size_t n, uint64_t start) {
            for (size_t i = 0; i < n; ++i)
                if (flagged[bin[i]] && taken[bin[i]]++ < kSeedsPerBin) keep(seeds, i, start);
        });
        if (std::string e = evaluate(seeds); !e.empty()) return made_error<WarpTestResult>(e);
        std::vector<uint32_t> seed_bin;
        {
            std::vector<std::pair<uint32_t, size_t>> order;
            for (size_t i = 0; i < seeds.size(); ++i)
                if (flagged[bin_of(seeds[i])]) order.push_back({bin_of(seeds[i]), i});
            std::stable_sort(order.begin(), order.end(),
                             [](const auto& a, const auto& b) { return a.first < b.first; });
            std::vector<Probe> sorted;
            sorted.reserve(order.size());
            for (const auto& o : order) {
                sorted.push_back(seeds[o.second]);
                seed_bin.push_back(o.first);
            }
            seeds.swap(sorted);
        }
        Quadrature q = integrate_bins(domain, warp, natural, r.bins, nbins, again, seeds, seed_bin,
                                      n_samples, options.pdf_tolerance);
        if (!q.error_message.empty()) return made_error<WarpTestResult>(q.error_message);
        for (uint32_t b : again) {
            integral.add((q.expected[b] - r.expected[b]) / n_samples);
            error.add((q.expected_error[b] - r.expected_error[b]) / n_samples);
            r.expected[b] = q.expected[b];
            r.expected_error[b] = q.expected_error[b];
            if (q.unresolved[b]) { // any count is possible
                r.expected_error[b] = std::max(r.expected_error[b], n_samples);
                error.add(1.0);
                ++r.unresolved_bins;
            }
        }
        r.probed_bins = static_cast<int>(again.size());
        r.pdf_evaluations += q.evaluations;
    }
    r.pdf_integral = integral.value();
    r.pdf_integral_error = error.value();
    // Not 1 whatever the quadrature's error, or 1 to within the tolerance beyond doubt.
    const double off = std::fabs(r.pdf_integral - 1.0);
    const bool integral_wrong = off > options.pdf_tolerance + r.pdf_integral_error;
    r.pdf_integral_ok =
        off <= options.pdf_tolerance && r.pdf_integral_error <= options.pdf_tolerance;

    // The statistic; its range under the quadrature's errors d_c of the cells' expected counts
    // E_c. With E'_c = E_c + e_c, |e_c| <= d_c, Cauchy-Schwarz bounds the cross term:
    // sum (O - E')^2 / E = X^2 - 2 sum (O - E) e / E + sum e^2 / E lies within
    // (sqrt(X^2) -+ sqrt(D))^2, D = sum d^2 / E; dividing by E' rather than E scales it by
    // at most 1 / (1 -+ max d / E).
    double max_relative = 0.0;
    pooled_chi_square(r.observed, r.expected, r.expected_error, &r.chi_square, &r.cells,
                      &r.pooled_bins, &r.quadrature_chi_square, &max_relative);
    r.dof = r.cells - 1;
    r.p_value = r.dof >= 1 ? chi_square_sf(r.chi_square, r.dof) : 1.0;
    r.p_value_low = r.p_value_high = r.p_value;
    if (r.dof >= 1 && r.quadrature_chi_square > 0.0) {
        const double root = std::sqrt(r.chi_square), d = std::sqrt(r.quadrature_chi_square);
        const double high =
            max_relative < 1.0 ? (root + d) * (root + d) / (1.0 - max_relative) : HUGE_VAL;
        const double low = std::max(root - d, 0.0) * std::max(root - d, 0.0) / (1.0 + max_relative);
        r.p_value_low = std::isfinite(high) ? chi_square_sf(high, r.dof) : 0.0;
        r.p_value_high = chi_square_sf(low, r.dof);
    }
    r.level = sidak_level(options.significance, options.tests);
    size_t first_zero = nbins;
    uint64_t zero_samples = 0;
    for (size_t b = 0; b < nbins; ++b)
        if (r.expected[b] == 0.0 && r.observed[b] > 0) {
            ++r.zero_bins_hit;
            zero_samples += r.observed[b];
            if (first_zero == nbins) first_zero = b;
        }

    std::vector<size_t> order(nbins);
    std::iota(order.begin(), order.end(), size_t(0));
    std::vector<double> key(nbins);
    for (size_t b = 0; b < nbins; ++b) key[b] = std::fabs(describe_bin(r, b).residual);
    const size_t shown = std::min(nbins, static_cast<size_t>(options.worst));
    std::partial_sort(
        order.begin(), order.begin() + static_cast<std::ptrdiff_t>(shown), order.end(),
        [&](size_t a, size_t b) { return key[a] > key[b] || (key[a] == key[b] && a < b); });
    for (size_t s = 0; s < shown; ++s) r.worst.push_back(describe_bin(r, order[s]));

    const std::string stat = "chi-square " + fmt(r.chi_square, 6) + " on " + std::to_string(r.dof) +
                             " degrees of freedom, " + p_value_text(r.p_value, 3);
    const std::string range = "p between " + fmt(r.p_value_low, 3) + " and " +
                              fmt(r.p_value_high, 3) +
                              " over the expected counts within the "
                              "quadrature's error";
    const std::string integral_text = "the pdf integrates to " + fmt(r.pdf_integral, 7) + " (+- " +
                                      fmt(r.pdf_integral_error, 2) + ")";
    // The statistic over the bins whose expected counts the quadrature settled (error under
    // kTrustedError sqrt(expected)), given the samples they hold: multinomial with the bins'
    // shares of their expectation, whatever the other bins' counts or the pdf's integral (so
    // it tests p's shape). `p_high`: its largest p-value over the quadrature's error.
    struct Shape {
        bool ok = false;
        double chi = 0.0, p_high = 1.0;
        int dof = 0;
        size_t bins = 0;
        uint64_t samples = 0;
    };
    auto settled_shape = [&]() {
        Shape sh;
        std::vector<size_t> trusted;
        double e_sum = 0.0, d_sum = 0.0;
        for (size_t b = 0; b < nbins; ++b)
            if (r.expected[b] > 0.0 &&
                r.expected_error[b] <= kTrustedError * std::sqrt(r.expected[b])) {
                trusted.push_back(b);
                e_sum += r.expected[b];
                d_sum += r.expected_error[b];
                sh.samples += r.observed[b];
            }
        sh.bins = trusted.size();
        if (trusted.size() < 2 || sh.samples == 0 || !(e_sum > d_sum)) return sh;
        const double scale = static_cast<double>(sh.samples) / e_sum;
        std::vector<uint64_t> o;
        std::vector<double> e, d;
        for (size_t b : trusted) {
            o.push_back(r.observed[b]);
            e.push_back(scale * r.expected[b]);
            // The share's error: the bin's own and the total's.
            d.push_back(scale * (r.expected_error[b] + r.expected[b] * d_sum / (e_sum - d_sum)));
        }
        double err_chi = 0.0, max_rel = 0.0;
        int cells = 0, pooled = 0;
        pooled_chi_square(o, e, d, &sh.chi, &cells, &pooled, &err_chi, &max_rel);
        if (cells < 2 || !(max_rel < 1.0)) return sh;
        const double root = std::sqrt(sh.chi), dd = std::sqrt(err_chi);
        const double low = std::max(root - dd, 0.0) * std::max(root - dd, 0.0) / (1.0 + max_rel);
        sh.dof = cells - 1;
        sh.p_high = chi_square_sf(low, sh.dof);
        sh.ok = true;
        return sh;
    };
    auto shape_text = [&](const Shape& sh) {
        return "chi-square " + fmt(sh.chi, 6) + " on " + std::to_string(sh.dof) +
               " degrees of freedom against p's shape, " + p_value_text(sh.p_high, 3) + " at most";
    };
    // Where the mass is wrong, in words; a local departure names its most deviant bin.
    auto where_text = [&]() {
        std::string w = mass_departures(domain, r);
        if (w.empty() && !r.worst.empty())
            w = "the departure is local (no quarter of a coordinate's range holds too many or "
                "too few samples): the most deviant " +
                bin_text(r, r.worst[0]) + " has " + std::to_string(r.worst[0].observed) +
                " samples where " + fmt(r.worst[0].expected, 6) + " are expected";
        return w;
    };
    auto settled_bins_reject = [&](std::string* text) {
        const Shape sh = settled_shape();
        if (!sh.ok || !(sh.p_high < r.level)) return false;
        r.where = where_text();
        *text = "rejected: the samples do not follow the pdf on the " + std::to_string(sh.bins) +
                " of " + std::to_string(nbins) +
                " bins whose expected counts the quadrature settled (" +
                std::to_string(sh.samples) + " samples): " + shape_text(sh) + " < level " +
                fmt(r.level, 3) + "; " + r.where;
        return true;
    };
    std::string why_not; // why the test could not verify the warp, if it could not
    r.outcome = WarpTestOutcome::Failed;
    if (zero_probe) {
        r.reason = "rejected: " + std::to_string(r.zero_pdf_samples) +
                   " sample(s) fell where the pdf is 0, the first sample " +
                   std::to_string(zero_probe->sample) +
                   " at x = " + tuple(zero_probe->x, point_dim) +
                   ": the warp lands where its pdf says it cannot";
    } else if (integral_wrong) {
        // A constant factor alone, or a wrong shape besides.
        const Shape sh = settled_shape();
        r.off_by_constant = sh.ok && sh.p_high >= r.level;
        if (r.off_by_constant) {
            r.reason = "rejected: the pdf is off by a constant factor " + fmt(r.pdf_integral, 4) +
                       " (it integrates to " + fmt(r.pdf_integral, 7) + " +- " +
                       fmt(r.pdf_integral_error, 2) + ", tolerance " +
                       fmt(options.pdf_tolerance, 3) + "): the samples follow its shape (" +
                       shape_text(sh) + ")";
        } else {
            r.where = where_text();
            r.reason =
                "rejected: " + integral_text + " over the domain, not 1 (tolerance " +
                fmt(options.pdf_tolerance, 3) + ")" +
                (sh.ok ? ", and the samples do not follow its shape either (" + shape_text(sh) + ")"
                       : "; " + stat) +
                (r.where.empty() ? "" : "; " + r.where);
        }
    } else if (r.dof >= 1 && !(r.p_value_high >= r.level)) {
        r.where = where_text();
        r.reason =
            "rejected: the samples do not follow the pdf: " + stat + " < level " + fmt(r.level, 3);
        if (r.p_value_high > r.p_value) r.reason += " (" + range + ")";
        if (!r.where.empty()) r.reason += "; " + r.where;
    } else if (r.unresolved_bins > 0) {
        why_not = std::to_string(r.unresolved_bins) +
                  " bin(s) hold samples where the pdf is far above every quadrature node "
                  "around them, a peak the quadrature could not resolve; " +
                  integral_text;
    } else if (r.zero_bins_hit > 0) {
        const WarpTestBin b = describe_bin(r, first_zero);
        why_not = std::to_string(zero_samples) + " samples fell in " +
                  std::to_string(r.zero_bins_hit) +
                  " bins where the quadrature found no mass though the pdf is positive at "
                  "them, the first " +
                  bin_text(r, b);
    } else if (!r.pdf_integral_ok) {
        why_not = "the quadrature could not settle the pdf's integral: " + integral_text +
                  ", tolerance " + fmt(options.pdf_tolerance, 3) + "; " + stat;
    } else if (r.dof < 1) {
        why_not = std::to_string(r.cells) +
                  " cell(s) after pooling bins of expected count under 5; take more samples "
                  "or fewer bins";
    } else if (!(r.p_value_low >= r.level)) {
        why_not = "the quadrature's error on the expected counts decides the test: " + stat + ", " +
                  range + ", level " + fmt(r.level, 3);
    } else {
        r.outcome = WarpTestOutcome::Passed;
        r.reason = "passed: " + stat + " >= level " + fmt(r.level, 3) + "; " + integral_text;
    }
    if (!why_not.empty() && !settled_bins_reject(&r.reason)) {
        r.outcome = WarpTestOutcome::Unverified;
        r.reason = "could not verify: " + why_not;
    }
    r.passed = r.outcome == WarpTestOutcome::Passed;
    return {std::move(r), {}};
}

} // namespace mcp
