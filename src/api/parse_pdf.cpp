// Scene parsing, pdfs: the "pdf" object of an estimator (1D families, tables, products, 2D
// tables, the cosine hemisphere, expressions tabulated into tables; docs/scene-format.md). Part
// of the scene parsers (api/scene_parsers.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include "api/scene_parsers.h"
#include "core/special.h"
#include "integrands/expression.h"

namespace mcp {
namespace {

// --- pdfs --------------------------------------------------------------------------------

constexpr int kMaxBins = 1 << 20;      // bins of a 1D table
constexpr int kMaxBinsPerAxis = 4096;  // bins per axis of a 2D table
constexpr size_t kMaxCells = 1u << 20; // cells of a 2D table
constexpr int kSubSamples = 4;         // shape evaluations per bin and axis when tabulating
constexpr size_t kMaxTabulationPoints = size_t(1) << 24; // shape evaluations per table
constexpr int kExpressionBins1D = 1024;
constexpr int kExpressionBins2D = 64;

// Tabulation values: explicit "values", or |shape| averaged over kSubSamples^d points per cell.
// Every count is checked before any array is converted or any shape evaluated.
bool table_values(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
                  const std::vector<int>& bins, const std::vector<double>& lo,
                  const std::vector<double>& hi, std::vector<double>* values) {
    size_t cells = 1;
    for (int b : bins) cells *= static_cast<size_t>(b); // b <= 2^20, at most two axes
    if (const Json* v = find(j, "values")) {
        const size_t given = v->is_array() ? v->size() : 1;
        if (given != cells)
            return c.fail(sub(path, "values"), "has " + std::to_string(given) +
                                                   " entries, bins ask for " +
                                                   std::to_string(cells));
        if (!to_numbers(c, *v, sub(path, "values"), values)) return false;
        return true;
    }
    const Json* shape = find(j, "shape");
    if (!shape) return c.fail(path, "a tabulated pdf needs \"values\" or \"shape\"");
    const int dim = static_cast<int>(bins.size());
    const size_t sub_count = dim == 1 ? kSubSamples : kSubSamples * kSubSamples;
    const size_t total = cells * sub_count;
    if (total > kMaxTabulationPoints)
        return c.fail(sub(path, "bins"), std::to_string(cells) + " cells of " +
                                             std::to_string(sub_count) + " points each are " +
                                             std::to_string(total) +
                                             " shape evaluations, more "
                                             "than the limit of " +
                                             std::to_string(kMaxTabulationPoints));
    Integrand f;
    // The integrand's shape is tabulated as |f| (the density proportional to |f| is the best one
    // [Owen13, 9.1]); a shape the user gives is a density and must not be negative: silently
    // taking |p| would sample from something else than what was typed.
    const bool from_integrand = shape->is_string() && shape->get<std::string>() == "integrand";
    if (from_integrand) {
        if (problem.integrand.dim != dim)
            return c.fail(sub(path, "shape"), "the integrand has " +
                                                  std::to_string(problem.integrand.dim) +
                                                  " dimensions, the table " + std::to_string(dim));
        f = problem.integrand;
    } else if (!parse_integrand(c, *shape, sub(path, "shape"), dim, &f)) {
        return false;
    }
    values->assign(cells, 0.0);
    // kSubSamples^d points per cell, evaluated a block at a time (cell-major, so each cell's
    // points are summed in order); x fastest over the cells, matching make_tabulated_2d.
    PointBlock block;
    block.reset(dim, kBlockSize);
    std::vector<double> v(kBlockSize);
    size_t bad = 0, negative = 0;
    double bad_x = 0.0, bad_y = 0.0, bad_value = 0.0;
    double neg_x = 0.0, neg_y = 0.0, neg_value = 0.0;
    for (size_t first = 0; first < total; first += kBlockSize) {
        block.n = std::min(kBlockSize, total - first);
        for (size_t i = 0; i < block.n; ++i) {
            const size_t cell = (first + i) / sub_count, sub = (first + i) % sub_count;
            const size_t ix = cell % static_cast<size_t>(bins[0]);
            const size_t iy = dim == 2 ? cell / static_cast<size_t>(bins[0]) : 0;
            const size_t sx = sub % kSubSamples, sy = sub / kSubSamples;
            block.coord(0)[i] = lo[0] + (hi[0] - lo[0]) * (ix + (sx + 0.5) / kSubSamples) / bins[0];
            if (dim == 2)
                block.coord(1)[i] =
                    lo[1] + (hi[1] - lo[1]) * (iy + (sy + 0.5) / kSubSamples) / bins[1];
        }
        evaluate_block(f, block, v.data());
        for (size_t i = 0; i < block.n; ++i) {
            const double a = std::fabs(v[i]);
            if (!std::isfinite(a)) { // counted and reported, never dropped
                if (bad++ == 0) {
                    bad_x = block.coord(0)[i];
                    bad_y = dim == 2 ? block.coord(1)[i] : 0.0;
                    bad_value = v[i];
                }
                continue;
            }
            if (v[i] < 0.0 && !from_integrand && negative++ == 0) {
                neg_x = block.coord(0)[i];
                neg_y = dim == 2 ? block.coord(1)[i] : 0.0;
                neg_value = v[i];
            }
            (*values)[(first + i) / sub_count] += a;
        }
    }
    if (bad > 0) {
        return c.fail(sub(path, "shape"),
                      "the pdf shape is NaN or infinite at " + std::to_string(bad) + " of " +
                          std::to_string(total) + " tabulation points (first " +
                          number_text(bad_value) + " at " +
                          (dim == 2
                               ? "(x, y) = (" + number_text(bad_x) + ", " + number_text(bad_y) + ")"
                               : "x = " + number_text(bad_x)) +
                          "); a pdf shape must be finite on the whole domain");
    }
    auto where = [dim](double x, double y) {
        return dim == 2 ? "(x, y) = (" + number_text(x) + ", " + number_text(y) + ")"
                        : "x = " + number_text(x);
    };
    if (negative > 0)
        return c.fail(sub(path, "shape"),
                      "a density must be >= 0, and this one is negative at " +
                          std::to_string(negative) + " of " + std::to_string(total) +
                          " tabulation points (first " + number_text(neg_value) + " at " +
                          where(neg_x, neg_y) + "); write abs(...) if |p| is meant");
    bool all_zero = true;
    for (double value : *values) all_zero = all_zero && value == 0.0;
    if (all_zero)
        return c.fail(sub(path, "shape"), "the density is 0 at every one of the " +
                                              std::to_string(total) +
                                              " tabulation points: it samples nothing");
    for (double& value : *values) value /= static_cast<double>(sub_count);
    return true;
}

bool parse_pdf_1d(Ctx& c, const Json& j, const std::string& path, const Problem& problem, double a,
                  double b, Distribution1D* out) {
    if (!check_keys(c, j, path,
                    {"type", "k", "rate", "mu", "sigma", "omega", "x0", "bins", "values", "shape"}))
        return false;
    std::string type;
    if (!get_string(c, j, "type", path, &type)) return false;
    Made<Distribution1D> d;
    if (type == "uniform") {
        d = make_uniform(a, b);
    } else if (type == "power" || type == "linear") {
        double k = 1.0;
        if (!get_number(c, j, "k", path, &k)) return false;
        d = make_power(a, b, k);
    } else if (type == "exponential") {
        double rate = 1.0;
        if (!get_number(c, j, "rate", path, &rate)) return false;
        d = make_exponential(a, b, rate);
    } else if (type == "gaussian" || type == "truncated_gaussian") {
        double mu = 0.5 * (a + b), sigma = 0.25 * (b - a);
        if (!get_number(c, j, "mu", path, &mu) || !get_number(c, j, "sigma", path, &sigma))
            return false;
        d = make_truncated_gaussian(a, b, mu, sigma);
    } else if (type == "cosine") {
        double omega = 1.0, x0 = 0.0;
        if (!get_number(c, j, "omega", path, &omega) || !get_number(c, j, "x0", path, &x0))
            return false;
        d = make_cosine(a, b, omega, x0);
    } else if (type == "tabulated") {
        uint64_t bins = 64;
        if (!get_count(c, j, "bins", path, &bins)) return false;
        if (bins < 1 || bins > static_cast<uint64_t>(kMaxBins))
            return c.fail(sub(path, "bins"), "must be in 1.." + std::to_string(kMaxBins) +
                                                 ", got " + std::to_string(bins));
        if (const Json* v = find(j, "values"); v && !find(j, "bins")) {
            // Without "bins", the values set the count: the same limit, checked before reading.
            const size_t given = v->is_array() ? v->size() : 1;
            if (given < 1 || given > static_cast<size_t>(kMaxBins))
                return c.fail(sub(path, "values"), "has " + std::to_string(given) +
                                                       " entries; a tabulated pdf has 1.." +
                                                       std::to_string(kMaxBins) + " bins");
            bins = given;
        }
        std::vector<double> values;
        if (!table_values(c, j, path, problem, {static_cast<int>(bins)}, {a}, {b}, &values))
            return false;
        d = make_tabulated(a, b, values);
    } else {
        return c.fail(sub(path, "type"),
                      "unknown 1D pdf '" + type +
                          "' (known: uniform, power, exponential, gaussian, cosine, tabulated)");
    }
    if (!d.ok()) return c.fail(path, d.error);
    *out = d.value;
    return true;
}

} // namespace

bool parse_pdf(Ctx& c, const Json& j, const std::string& path, const Problem& problem,
               Proposal* out) {
    const Domain& dom = problem.domain;
    // A pdf expression is an unnormalised shape, tabulated into a piecewise-constant density:
    // "pdf": "x^2" or {"type": "expression", "p": "x^2", "bins": 256}.
    if (j.is_string() || (j.is_object() && find(j, "type") && *find(j, "type") == "expression")) {
        if (dom.kind != DomainKind::Box || dom.lo.size() > 2)
            return c.fail(path, "pdf expressions are tabulated on 1- or 2-dimensional boxes; the "
                                "domain is a " +
                                    dom.describe());
        Json table = {{"shape", j.is_string() ? j : Json(nullptr)}};
        if (j.is_object()) {
            if (!check_keys(c, j, path, {"type", "p", "bins"})) return false;
            const Json* p = find(j, "p");
            if (!p) return c.fail(path, "an expression pdf needs \"p\": \"...\"");
            table["shape"] = *p;
            if (const Json* b = find(j, "bins")) table["bins"] = *b;
        }
        if (!table["shape"].is_string())
            return c.fail(sub(path, "p"),
                          "expected an expression string, got " + type_of(table["shape"]));
        const bool one_d = dom.lo.size() == 1;
        table["type"] = one_d ? "tabulated" : "tabulated_2d";
        if (!table.contains("bins"))
            table["bins"] = one_d ? Json(kExpressionBins1D) : Json(kExpressionBins2D);
        return parse_pdf(c, table, path, problem, out);
    }
    std::string type;
    if (!j.is_object())
        return c.fail(path, "expected a pdf object or expression string, got " + type_of(j));
    if (!get_string(c, j, "type", path, &type)) return false;
    if (type.empty()) return c.fail(path, "missing \"type\"");
    out->importance = true;
    if (type == "cosine_hemisphere") {
        if (!check_keys(c, j, path, {"type"})) return false;
        out->kind = ProposalKind::CosineHemisphere;
    } else if (type == "warp") {
        // A warp as the importance density: its map draws the points, its p weighs them.
        if (!check_keys(c, j, path, {"type", "warp"})) return false;
        const Json* w = find(j, "warp");
        if (!w) return c.fail(path, "a warp pdf needs \"warp\": a warp name or object");
        NamedWarp warp;
        if (!parse_warp(c, *w, sub(path, "warp"), &warp)) return false;
        *out = warp_proposal(std::make_shared<const Warp>(std::move(warp.warp)), warp.domain);
    } else if (type == "tabulated_2d") {
        if (!check_keys(c, j, path, {"type", "bins", "values", "shape"})) return false;
        if (dom.kind != DomainKind::Box || dom.lo.size() != 2)
            return c.fail(path, "tabulated_2d needs a 2-dimensional box domain");
        std::vector<double> bins{32, 32};
        if (!get_numbers(c, j, "bins", path, &bins)) return false;
        if (bins.size() == 1) bins.push_back(bins[0]);
        if (bins.size() != 2) return c.fail(sub(path, "bins"), "expected [nx, ny]");
        for (double b : bins)
            if (!(b >= 1 && b <= kMaxBinsPerAxis && b == std::floor(b)))
                return c.fail(sub(path, "bins"), "each count must be a whole number in 1.." +
                                                     std::to_string(kMaxBinsPerAxis) + ", got " +
                                                     number_text(b));
        std::vector<int> nb{static_cast<int>(bins[0]), static_cast<int>(bins[1])};
        const size_t cells = size_t(nb[0]) * size_t(nb[1]);
        if (cells > kMaxCells)
            return c.fail(sub(path, "bins"), std::to_string(nb[0]) + " x " + std::to_string(nb[1]) +
                                                 " = " + std::to_string(cells) +
                                                 " cells, more than the limit of " +
                                                 std::to_string(kMaxCells));
        std::vector<double> values;
        if (!table_values(c, j, path, problem, nb, dom.lo, dom.hi, &values)) return false;
        Made<TabulatedDistribution2D> t =
            make_tabulated_2d(dom.lo[0], dom.hi[0], dom.lo[1], dom.hi[1], nb[0], nb[1], values);
        if (!t.ok()) return c.fail(path, t.error);
        out->kind = ProposalKind::Tabulated2D;
        out->table = t.value;
    } else {
        if (dom.kind != DomainKind::Box)
            return c.fail(
                path, "pdf '" + type + "' samples box axes, the domain is a " +
                          domain_kind_name(dom.kind) +
                          (dom.kind == DomainKind::Hemisphere ? " (use cosine_hemisphere)" : ""));
        out->kind = ProposalKind::Product1D;
        out->marginals.clear();
        const size_t dim = dom.lo.size();
        if (type == "product") {
            if (!check_keys(c, j, path, {"type", "factors"})) return false;
            const Json* f = find(j, "factors");
            if (!f || !f->is_array())
                return c.fail(sub(path, "factors"), "expected an array with one 1D pdf per axis");
            if (f->size() != dim)
                return c.fail(sub(path, "factors"), "has " + std::to_string(f->size()) +
                                                        " entries, the box has " +
                                                        std::to_string(dim) + " axes");
            for (size_t a = 0; a < dim; ++a) {
                Distribution1D d;
                if (!parse_pdf_1d(c, (*f)[a], sub(path, "factors") + "[" + std::to_string(a) + "]",
                                  problem, dom.lo[a], dom.hi[a], &d))
                    return false;
                out->marginals.push_back(d);
            }
        } else {
            if (type == "tabulated" && dim != 1)
                return c.fail(path, "tabulated is 1D: use tabulated_2d, or a product of 1D pdfs");
            for (size_t a = 0; a < dim; ++a) {
                Distribution1D d;
                if (!parse_pdf_1d(c, j, path, problem, dom.lo[a], dom.hi[a], &d)) return false;
                out->marginals.push_back(d);
            }
        }
    }
    std::string mismatch = check_proposal(*out, dom);
    if (!mismatch.empty()) return c.fail(path, mismatch);
    return true;
}

} // namespace mcp
