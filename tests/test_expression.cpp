// User-typed expressions: grammar (precedence, associativity, signs), every function against
// std::, variables and dimensions, constant folding, block evaluation equal to point
// evaluation, exact error messages for malformed input, limits, and concurrent evaluation.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#if !(defined(__EMSCRIPTEN__) && !defined(__EMSCRIPTEN_PTHREADS__))
#include <thread>
#define MCP_TEST_THREADS 1
#endif

#include "core/exp_block.h"
#include "core/rng.h"
#include "core/special.h"
#include "integrands/expression.h"

using namespace mcp;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();

/// Bitwise-equal doubles, any NaN equal to any NaN.
bool same(double a, double b) {
    if (std::isnan(a) || std::isnan(b)) return std::isnan(a) && std::isnan(b);
    return a == b && std::signbit(a) == std::signbit(b);
}

std::shared_ptr<const ExprProgram> compile_ok(const std::string& text, int dim) {
    auto made = compile_expression(text, dim);
    EXPECT_TRUE(made.ok()) << "'" << text << "': " << made.error;
    return made.value;
}

/// Value at one point via evaluate_point, after checking that block evaluation at that
/// point agrees.
double eval(const std::string& text, std::vector<double> x) {
    const int dim = static_cast<int>(x.size());
    auto p = compile_ok(text, dim);
    if (!p) return kNaN;
    const double v = p->evaluate_point(x.data());
    std::vector<const double*> vars;
    for (int j = 0; j < dim; ++j) vars.push_back(&x[j]);
    double block = -1.0;
    p->evaluate(vars.data(), 1, &block);
    EXPECT_TRUE(same(v, block)) << text;
    return v;
}

double eval1(const std::string& text, double x) {
    return eval(text, {x});
}

std::string error_of(const std::string& text, int dim) {
    auto made = compile_expression(text, dim);
    return made.ok() ? std::string("(no error)") : made.error;
}

} // namespace

// ---------------------------------------------------------------------------
// Grammar

TEST(Expression, PrecedenceAndAssociativity) {
    struct Case {
        const char* text;
        double expected;
    };
    const Case cases[] = {
        {"1+2*3", 7.0},
        {"(1+2)*3", 9.0},
        {"2^3^2", 512.0},
        {"(2^3)^2", 64.0},
        {"-2^2", -4.0},
        {"(-2)^2", 4.0},
        {"2^-1", 0.5},
        {"-2^-2", -0.25},
        {"2*3^2", 18.0},
        {"8/4/2", 1.0},
        {"1-2-3", -4.0},
        {"12/3*2", 8.0},
        {"--2", 2.0},
        {"---2", -2.0},
        {"+2", 2.0},
        {"+-+2", -2.0},
        {"1--2", 3.0},
        {"2*-3", -6.0},
        {"2^--1", 2.0},
        {"-(1+2)*4", -12.0},
        {"1+2-3*4/6", 1.0},
        {".5+.5", 1.0},
        {"1.", 1.0},
        {"1e-3*1e3", 1.0},
        {"2.5E+8", 2.5e8},
        {"2.5e8", 2.5e8},
        {"1E2", 100.0},
        {" ( 1 +\t2 ) * 3 ", 9.0},
        {"2^0.5", std::sqrt(2.0)},
        {"((((7))))", 7.0},
    };
    for (const Case& c : cases) EXPECT_EQ(eval1(c.text, 0.0), c.expected) << c.text;
}

TEST(Expression, PrecedenceWithVariables) {
    // The same rules when nothing can be folded away.
    EXPECT_EQ(eval1("-x", 3.0), -3.0);
    EXPECT_EQ(eval1("+x", 3.0), 3.0);
    EXPECT_EQ(eval1("--x", 3.0), 3.0);
    EXPECT_EQ(eval1("-(-x)", 3.0), 3.0);
    EXPECT_EQ(eval1("-x^2", 3.0), -9.0);
    EXPECT_EQ(eval1("(-x)^2", 3.0), 9.0);
    EXPECT_EQ(eval1("2^-x", 1.0), 0.5);
    EXPECT_EQ(eval1("2^-x^2", 2.0), 1.0 / 16.0);
    EXPECT_EQ(eval1("x-1-2", 10.0), 7.0);
    EXPECT_EQ(eval1("x/2/5", 10.0), 1.0);
    EXPECT_EQ(eval1("2*-x", 3.0), -6.0);
    EXPECT_EQ(eval1("-x*3", 3.0), -9.0);
    EXPECT_EQ(eval1("6/-x", 3.0), -2.0);
    EXPECT_EQ(eval1("-x/-x", 3.0), 1.0);
    EXPECT_EQ(eval("x+y*z", {1.0, 2.0, 3.0}), 7.0);
    EXPECT_EQ(eval("(x+y)*z", {1.0, 2.0, 3.0}), 9.0);
    EXPECT_EQ(eval("x^y^z", {2.0, 3.0, 2.0}), 512.0);
    EXPECT_EQ(eval("-x^y", {2.0, 2.0}), -4.0);
    EXPECT_EQ(eval("x-y-z", {1.0, 2.0, 3.0}), -4.0);
    EXPECT_EQ(eval("x/y/z", {8.0, 4.0, 2.0}), 1.0);
}

TEST(Expression, ConstantsAndWhitespace) {
    EXPECT_EQ(eval1("pi", 0.0), kPi);
    EXPECT_EQ(eval1("e", 0.0), std::exp(1.0));
    EXPECT_EQ(eval1("2*pi*x", 0.25), 2.0 * kPi * 0.25);
    EXPECT_EQ(eval1("\n x \t* \r 2 ", 4.0), 8.0);
    EXPECT_EQ(eval1("sin ( x )", 0.5), std::sin(0.5));
    EXPECT_EQ(eval1("pow( x , 2 )", 3.0), 9.0);
}

// ---------------------------------------------------------------------------
// Functions

TEST(Expression, OneArgumentFunctionsMatchStd) {
    struct Fn {
        const char* name;
        double (*f)(double);
    };
    const Fn fns[] = {
        {"sin", [](double t) { return std::sin(t); }},
        {"cos", [](double t) { return std::cos(t); }},
        {"tan", [](double t) { return std::tan(t); }},
        {"asin", [](double t) { return std::asin(t); }},
        {"acos", [](double t) { return std::acos(t); }},
        {"atan", [](double t) { return std::atan(t); }},
        {"sinh", [](double t) { return std::sinh(t); }},
        {"cosh", [](double t) { return std::cosh(t); }},
        {"tanh", [](double t) { return std::tanh(t); }},
        {"exp", [](double t) { return exp_tang(t); }}, // core/exp_block.h
        {"log", [](double t) { return std::log(t); }},
        {"log10", [](double t) { return std::log10(t); }},
        {"sqrt", [](double t) { return std::sqrt(t); }},
        {"abs", [](double t) { return std::fabs(t); }},
        {"floor", [](double t) { return std::floor(t); }},
        {"ceil", [](double t) { return std::ceil(t); }},
        {"erf", [](double t) { return std::erf(t); }},
    };
    const double points[] = {-3.7, -1.0, -0.5, -0.0, 0.0, 0.3, 0.5, 1.0, 2.5, 12.0};
    for (const Fn& fn : fns) {
        const std::string text = std::string(fn.name) + "(x)";
        auto p = compile_ok(text, 1);
        ASSERT_TRUE(p);
        EXPECT_EQ(p->instruction_count(), 1u) << text;
        for (double t : points) {
            EXPECT_TRUE(same(p->evaluate_point(&t), fn.f(t))) << text << " at " << t;
            // Folded at compile time: the same value.
            char buf[64];
            std::snprintf(buf, sizeof buf, "%s(%.17g)", fn.name, t);
            if (!std::isfinite(fn.f(t))) { // a non-finite constant is refused (issue 10)
                const std::string err = error_of(buf, 1);
                EXPECT_NE(err.find("constants must be finite"), std::string::npos) << buf << err;
                continue;
            }
            auto c = compile_ok(buf, 1);
            ASSERT_TRUE(c);
            EXPECT_EQ(c->instruction_count(), 0u) << buf;
            EXPECT_TRUE(same(c->evaluate_point(&t), fn.f(t))) << buf;
        }
    }
}

TEST(Expression, StepSignMinMax) {
    // step is the Heaviside function with step(0) = 1.
    EXPECT_EQ(eval1("step(x)", -2.0), 0.0);
    EXPECT_EQ(eval1("step(x)", -1e-300), 0.0);
    EXPECT_EQ(eval1("step(x)", 0.0), 1.0);
    EXPECT_EQ(eval1("step(x)", -0.0), 1.0);
    EXPECT_EQ(eval1("step(x)", 1e-300), 1.0);
    EXPECT_EQ(eval1("step(x)", 5.0), 1.0);
    EXPECT_EQ(eval1("step(x-0.3)", 0.3), 1.0);
    EXPECT_EQ(eval1("step(x-0.3)", 0.2), 0.0);
    EXPECT_TRUE(std::isnan(eval1("step(x)", kNaN))); // NaN stays visible
    EXPECT_EQ(eval1("step(0)", 1.0), 1.0);
    EXPECT_EQ(eval1("step(-1)", 1.0), 0.0);

    EXPECT_EQ(eval1("sign(x)", -2.5), -1.0);
    EXPECT_EQ(eval1("sign(x)", 2.5), 1.0);
    EXPECT_EQ(eval1("sign(x)", 0.0), 0.0);
    EXPECT_TRUE(std::isnan(eval1("sign(x)", kNaN)));

    for (double a : {-2.0, -0.5, 0.0, 0.5, 3.0})
        for (double b : {-1.0, 0.25, 3.0}) {
            EXPECT_EQ(eval("min(x, y)", {a, b}), std::fmin(a, b));
            EXPECT_EQ(eval("max(x, y)", {a, b}), std::fmax(a, b));
            EXPECT_EQ(eval("min(x, 0.25)", {a}), std::fmin(a, 0.25));
            EXPECT_EQ(eval("max(0.25, x)", {a}), std::fmax(0.25, a));
        }
    // Unlike std::fmin/fmax, a NaN argument gives NaN (so the caller can count it).
    EXPECT_TRUE(std::isnan(eval("min(x, y)", {kNaN, 1.0})));
    EXPECT_TRUE(std::isnan(eval("min(x, y)", {1.0, kNaN})));
    EXPECT_TRUE(std::isnan(eval("max(x, y)", {kNaN, 1.0})));
    EXPECT_TRUE(std::isnan(eval("max(x, y)", {1.0, kNaN})));
    EXPECT_EQ(eval1("min(2, 3) + max(2, 3)", 0.0), 5.0);
}

TEST(Expression, Powers) {
    // General exponents call std::pow.
    for (double a : {0.3, 1.7, 4.0})
        for (double b : {-2.5, -0.3, 0.7, 2.5, 3.1}) {
            EXPECT_EQ(eval("pow(x, y)", {a, b}), std::pow(a, b));
            EXPECT_EQ(eval("x^y", {a, b}), std::pow(a, b));
            char buf[64];
            std::snprintf(buf, sizeof buf, "x^%.17g", b);
            EXPECT_EQ(eval1(buf, a), std::pow(a, b)) << buf;
        }
    EXPECT_EQ(eval1("2^x", 3.0), 8.0);
    // Small integer exponents by repeated multiplication (x^8 = ((x^2)^2)^2: rounding errors
    // of up to 7 + 1 (the reciprocal) half-ulps), close to pow.
    for (int k = -8; k <= 8; ++k)
        for (double a : {-1.3, 0.7, 1.9, 3.0}) {
            const std::string text = "x^" + std::to_string(k);
            const double v = eval1(text, a);
            EXPECT_NEAR(v, std::pow(a, k), 1e-15 * std::fabs(std::pow(a, k))) << text << " " << a;
            EXPECT_EQ(eval1("pow(x, " + std::to_string(k) + ")", a), v);
            EXPECT_EQ(eval1("x^(" + std::to_string(k) + ")", a), v);
        }
    EXPECT_EQ(eval1("x^2", 1.1), 1.1 * 1.1);
    EXPECT_EQ(eval1("x^3", 1.1), 1.1 * 1.1 * 1.1);
    EXPECT_EQ(eval1("x^-1", 4.0), 0.25);
    EXPECT_EQ(eval1("x^0", kNaN), 1.0); // as std::pow(NaN, 0)
    EXPECT_EQ(eval1("x^1", 1.1), 1.1);
    EXPECT_EQ(eval1("x^0.5", 2.0), std::sqrt(2.0));
    EXPECT_EQ(eval1("x^2", -3.0), 9.0);
    EXPECT_TRUE(std::isnan(eval1("x^0.5", -1.0)));
    // A folded constant power equals the same power computed at run time.
    EXPECT_EQ(eval1("1.1^3", 0.0), eval1("x^3", 1.1));
    EXPECT_EQ(eval1("1.1^2.5", 0.0), eval1("x^2.5", 1.1));
}

TEST(Expression, IeeeSpecialValues) {
    EXPECT_TRUE(std::isnan(eval1("log(x)", -1.0)));
    EXPECT_TRUE(std::isnan(eval1("sqrt(x)", -1.0)));
    EXPECT_TRUE(std::isnan(eval1("asin(x)", 2.0)));
    EXPECT_EQ(eval1("1/x", 0.0), kInf);
    EXPECT_EQ(eval1("-1/x", 0.0), -kInf);
    EXPECT_EQ(eval1("log(x)", 0.0), -kInf);
    EXPECT_TRUE(std::isnan(eval1("x/x", 0.0)));
    EXPECT_TRUE(std::isnan(eval1("0*x", kInf))); // 0*x is not folded to 0
    EXPECT_EQ(eval1("exp(x)", 1000.0), kInf);
    EXPECT_EQ(eval1("1e-999", 0.0), 0.0); // underflow is allowed
}

// ---------------------------------------------------------------------------
// Variables

TEST(Expression, VariablesByNameAndIndex) {
    const std::vector<double> x = {1.0, 2.0, 3.0, 4.0, 5.0};
    EXPECT_EQ(eval("x1 + 10*x2 + 100*x3 + 1000*x4 + 10000*x5", x), 54321.0);
    EXPECT_EQ(eval("x + 10*y + 100*z", x), 321.0);
    EXPECT_EQ(eval("x - x1 + y - x2 + z - x3", x), 0.0);
    EXPECT_EQ(eval("x5", x), 5.0);
    EXPECT_EQ(eval1("x", 0.75), 0.75);
    EXPECT_EQ(eval1("x1", 0.75), 0.75);
    std::vector<double> big(64);
    for (int j = 0; j < 64; ++j) big[j] = j + 1.0;
    EXPECT_EQ(eval("x64 - x63", big), 1.0);

    EXPECT_EQ(error_of("x4", 3), "at position 1: variable 'x4' is beyond the domain's dimension "
                                 "(variables: x, y, z, x1, x2, x3 for a 3-dimensional domain)");
    EXPECT_EQ(error_of("y", 1), "at position 1: variable 'y' is beyond the domain's dimension "
                                "(variables: x, x1 for a 1-dimensional domain)");
    EXPECT_EQ(error_of("x+z", 2), "at position 3: variable 'z' is beyond the domain's dimension "
                                  "(variables: x, y, x1, x2 for a 2-dimensional domain)");
    EXPECT_EQ(error_of("x6", 5), "at position 1: variable 'x6' is beyond the domain's dimension "
                                 "(variables: x, y, z, x1..x5 for a 5-dimensional domain)");
    EXPECT_EQ(error_of("x0", 2), "at position 1: unknown variable 'x0' "
                                 "(variables: x, y, x1, x2 for a 2-dimensional domain)");
    EXPECT_EQ(error_of("X", 1), "at position 1: unknown variable 'X' "
                                "(variables: x, x1 for a 1-dimensional domain)");
}

// Warps read the unit cube's coordinates as u, u1 .. u<dim> (ExprVariables::Unit); there x, y,
// z are unknown, and in a domain's expressions u is.
TEST(Expression, UnitCubeVariables) {
    auto unit = [](const std::string& text, int dim) {
        return compile_expression(text, dim, ExprVariables::Unit);
    };
    auto p = unit("u1 + 10*u2 + 100*u3 - u", 3);
    ASSERT_TRUE(p.ok()) << p.error;
    const double u[3] = {0.25, 2.0, 3.0};
    EXPECT_EQ(p.value->evaluate_point(u), 320.0);
    auto one = unit("sqrt(u)", 1);
    ASSERT_TRUE(one.ok()) << one.error;
    const double quarter = 0.25;
    EXPECT_EQ(one.value->evaluate_point(&quarter), 0.5);

    EXPECT_EQ(unit("u3", 2).error, "at position 1: variable 'u3' is beyond the unit cube's "
                                   "dimension (variables: u, u1, u2 for a 2-dimensional unit "
                                   "cube)");
    EXPECT_EQ(unit("u1 + x", 2).error, "at position 6: unknown variable 'x' (variables: u, u1, "
                                       "u2 for a 2-dimensional unit cube)");
    EXPECT_EQ(unit("u0", 4).error, "at position 1: unknown variable 'u0' (variables: u, "
                                   "u1..u4 for a 4-dimensional unit cube)");
    EXPECT_EQ(unit("u(2)", 1).error,
              "at position 1: 'u' is a variable, not a function (write u*(...) to multiply)");
    EXPECT_EQ(error_of("u", 1), "at position 1: unknown variable 'u' "
                                "(variables: x, x1 for a 1-dimensional domain)");
}

TEST(Expression, DimensionAndSource) {
    auto p = compile_ok("x3 * 2", 4);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->dimension(), 4);
    EXPECT_EQ(p->source(), "x3 * 2");
    EXPECT_EQ(error_of("x", 0), "expression: dimension must be in 1..64, got 0");
    EXPECT_EQ(error_of("x", 65), "expression: dimension must be in 1..64, got 65");
}

// ---------------------------------------------------------------------------
// Compilation

TEST(Expression, ConstantFolding) {
    auto p = compile_ok("2*pi*3", 1);
    ASSERT_TRUE(p);
    EXPECT_EQ(p->instruction_count(), 0u);
    const double x = 0.0;
    EXPECT_EQ(p->evaluate_point(&x), 2.0 * kPi * 3.0);

    struct Case {
        const char* text;
        size_t max_instructions;
    };
    const Case cases[] = {
        {"exp(-(x-0.5)^2/0.01)", 4}, // x-0.5, square, divide by -0.01, exp
        {"x", 0},
        {"sin(pi/2) + sqrt(4) * x", 2},
        {"x*x", 1},
        {"x^2", 1},
        {"x^1", 0},
        {"--x", 0},
        {"-(-x)", 0},
        {"sin(x)^0", 0},
        {"pow(exp(x), 0) + 1", 0},
        {"x1*x2 + sin(pi*y)", 4},
        {"max(1, 2) * min(x, 3)", 2},
        {"(1+2)*(3+4)*x", 1},
    };
    for (const Case& c : cases) {
        auto q = compile_ok(c.text, 2);
        ASSERT_TRUE(q);
        EXPECT_LE(q->instruction_count(), c.max_instructions) << c.text;
    }
    // Folded programs still fill every output.
    auto one = compile_ok("sin(x)^0", 1);
    std::vector<double> in(300, 0.5), out(300, -1.0);
    const double* vars[] = {in.data()};
    one->evaluate(vars, in.size(), out.data());
    for (double v : out) EXPECT_EQ(v, 1.0);
}

TEST(Expression, FusedArithmeticKeepsOrderAndRounding) {
    // Pairs of arithmetic operations run in one loop must round exactly like two loops, and
    // keep the operand order of - and /.
    struct Case {
        const char* text;
        double (*f)(double, double, double);
    };
    const Case cases[] = {
        {"x*y + 3*x - y*y", [](double x, double y, double) { return x * y + 3 * x - y * y; }},
        {"2 - x/y", [](double x, double y, double) { return 2 - x / y; }},
        {"(x - y)/3", [](double x, double y, double) { return (x - y) / 3; }},
        {"3/(x*y)", [](double x, double y, double) { return 3 / (x * y); }},
        {"x - (y - z)", [](double x, double y, double z) { return x - (y - z); }},
        {"(1 - x) - y", [](double x, double y, double) { return (1 - x) - y; }},
        {"z/(x+y)", [](double x, double y, double z) { return z / (x + y); }},
        {"(x+y)/z", [](double x, double y, double z) { return (x + y) / z; }},
        {"0.1*x + 0.2*y + 0.3*z + 0.7",
         [](double x, double y, double z) { return 0.1 * x + 0.2 * y + 0.3 * z + 0.7; }},
        {"(x*y - z)*(x + z)/(y - 0.5)",
         [](double x, double y, double z) { return (x * y - z) * (x + z) / (y - 0.5); }},
        {"-(x*y)*3", [](double x, double y, double) { return -(x * y) * 3; }},
    };
    Pcg32 rng(77u, 5u);
    const size_t n = 700;
    std::vector<double> cols[3];
    for (auto& col : cols) {
        col.resize(n);
        for (double& v : col) v = rng.next_double();
    }
    const double* vars[] = {cols[0].data(), cols[1].data(), cols[2].data()};
    std::vector<double> out(n);
    for (const Case& c : cases) {
        auto p = compile_ok(c.text, 3);
        ASSERT_TRUE(p);
        p->evaluate(vars, n, out.data());
        for (size_t i = 0; i < n; ++i)
            ASSERT_TRUE(same(out[i], c.f(cols[0][i], cols[1][i], cols[2][i])))
                << c.text << " at " << i;
    }
    auto poly = compile_ok("x*y + 3*x - y*y", 2);
    EXPECT_LE(poly->instruction_count(), 3u);
    // More distinct constants than fused operations may hold in splat arrays: still exact.
    std::string many = "x";
    const double x = 0.7;
    double expected = x;
    for (int i = 1; i <= 100; ++i) {
        const double c = i + 0.25;
        many += " + x*" + std::to_string(c);
        expected = expected + x * c;
    }
    EXPECT_EQ(eval1(many, x), expected);
}

TEST(Expression, MatchesHandWrittenCpp) {
    auto p = compile_ok("exp(-(x-0.5)^2/0.01)", 1);
    ASSERT_TRUE(p);
    Pcg32 rng(11u, 3u);
    std::vector<double> x(1000), out(1000);
    for (double& v : x) v = rng.next_double();
    const double* vars[] = {x.data()};
    p->evaluate(vars, x.size(), out.data());
    for (size_t i = 0; i < x.size(); ++i) {
        const double d = x[i] - 0.5;
        EXPECT_EQ(out[i], exp_tang(-(d * d) / 0.01)) << x[i];
    }
}

TEST(Expression, BlockEvaluationEqualsPointEvaluation) {
    const char* texts[] = {
        "exp(-(x-0.5)^2/0.01)",
        "x1*x2 + sin(pi*y)",
        "step(x-0.3) * (1 + z)",
        "((x*y+z)*(x-y)+(y*z-x))/(1+x*x+y*y)",
        "log(x - 0.5) + sqrt(y - 0.5)", // NaN on part of the domain
        "pow(x, y) + x^z + 2^x + x^-3 + x^2.5 + y^0.5",
        "max(min(x, y), z) - abs(x - y) + floor(10*x) + ceil(10*y) + sign(x - z)",
        "erf(3*(x-y)) * atan(z/x) / tanh(y) + cosh(x) - sinh(z) + log10(y) + tan(x)",
        "asin(2*x-1) + acos(2*y-1) + 1/(x-y)",
        "-y",
        "y",
        "2*pi*3",
        "sin(x*(y*(z*(x*(y*(z+1)+1)+1)+1)+1))",
        "-(x*y) / 3 + -(z) * 2 + 4 / -(x)",
    };
    Pcg32 rng(2024u, 7u);
    for (size_t n : {size_t(1), size_t(7), size_t(256), size_t(1000)}) {
        std::vector<std::vector<double>> cols(3, std::vector<double>(n));
        for (size_t i = 0; i < n; ++i)
            for (int j = 0; j < 3; ++j) cols[j][i] = rng.next_double();
        const double* vars[] = {cols[0].data(), cols[1].data(), cols[2].data()};
        for (const char* text : texts) {
            auto p = compile_ok(text, 3);
            ASSERT_TRUE(p);
            std::vector<double> out(n + 1, -7.0);
            p->evaluate(vars, n, out.data());
            EXPECT_EQ(out[n], -7.0) << text << ": wrote past n";
            for (size_t i = 0; i < n; ++i) {
                const double pt[] = {cols[0][i], cols[1][i], cols[2][i]};
                ASSERT_TRUE(same(out[i], p->evaluate_point(pt)))
                    << text << " n=" << n << " i=" << i << ": " << out[i] << " vs "
                    << p->evaluate_point(pt);
            }
        }
    }
}

namespace {

/// A random expression tree, printed fully parenthesised and evaluated directly (the
/// reference for the compiler's folding, fusion, peepholes and register allocation).
struct Node {
    enum Kind { Const, Var, Neg, Unary, Binary, Pow } kind = Const;
    double value = 0.0;
    int var = 0;
    int fn = 0; ///< index into the function or operator names
    std::unique_ptr<Node> a, b;
};

const char* const kUnaryNames[] = {"sin", "exp", "log", "sqrt", "abs", "floor", "step", "atan"};
const char kBinaryOps[] = {'+', '-', '*', '/'};

std::unique_ptr<Node> random_tree(Pcg32& rng, int depth) {
    auto n = std::make_unique<Node>();
    const uint32_t pick = depth <= 0 ? rng.next_below(2) : rng.next_below(9);
    if (pick == 0) {
        const double consts[] = {0.5, 2.0, 3.0, 0.25, 1.5, 10.0};
        n->kind = Node::Const;
        n->value = consts[rng.next_below(6)];
    } else if (pick == 1) {
        n->kind = Node::Var;
        n->var = static_cast<int>(rng.next_below(3));
    } else if (pick == 2) {
        n->kind = Node::Neg;
        n->a = random_tree(rng, depth - 1);
    } else if (pick == 3) {
        n->kind = Node::Unary;
        n->fn = static_cast<int>(rng.next_below(8));
        n->a = random_tree(rng, depth - 1);
    } else if (pick == 4) {
        n->kind = Node::Pow;
        n->a = random_tree(rng, depth - 1);
        n->b = random_tree(rng, rng.next_below(2) ? 0 : depth - 1);
    } else {
        n->kind = Node::Binary;
        n->fn = static_cast<int>(rng.next_below(4 + 2)); // + - * / min max
        n->a = random_tree(rng, depth - 1);
        n->b = random_tree(rng, depth - 1);
    }
    return n;
}

std::string print(const Node& n) {
    char buf[32];
    switch (n.kind) {
    case Node::Const: std::snprintf(buf, sizeof buf, "%g", n.value); return buf;
    case Node::Var: return n.var == 0 ? "x" : (n.var == 1 ? "y" : "x3");
    case Node::Neg: return "-(" + print(*n.a) + ")";
    case Node::Unary: return std::string(kUnaryNames[n.fn]) + "(" + print(*n.a) + ")";
    case Node::Pow: return "(" + print(*n.a) + ")^(" + print(*n.b) + ")";
    case Node::Binary:
        if (n.fn >= 4)
            return (n.fn == 4 ? "min(" : "max(") + print(*n.a) + ", " + print(*n.b) + ")";
        return "(" + print(*n.a) + " " + kBinaryOps[n.fn] + " " + print(*n.b) + ")";
    }
    return "";
}

bool has_var(const Node& n) {
    return n.kind == Node::Var || (n.a && has_var(*n.a)) || (n.b && has_var(*n.b));
}

double int_power(double a, int k) { // as the compiler specialises a^k, |k| <= 8
    const int m = k < 0 ? -k : k;
    double p;
    if (m == 1) {
        p = a;
    } else if (m == 2) {
        p = a * a;
    } else if (m == 3) {
        p = a * a * a;
    } else {
        const double t = a * a;
        p = m == 4   ? t * t
            : m == 5 ? t * t * a
            : m == 6 ? t * t * t
            : m == 7 ? t * t * t * a
                     : (t * t) * (t * t);
    }
    return k < 0 ? 1.0 / p : p;
}

double reference(const Node& n, const double* x) {
    switch (n.kind) {
    case Node::Const: return n.value;
    case Node::Var: return x[n.var];
    case Node::Neg: return -reference(*n.a, x);
    case Node::Unary: {
        const double t = reference(*n.a, x);
        switch (n.fn) {
        case 0: return std::sin(t);
        case 1: return exp_tang(t);
        case 2: return std::log(t);
        case 3: return std::sqrt(t);
        case 4: return std::fabs(t);
        case 5: return std::floor(t);
        case 6: return t >= 0 ? 1.0 : (t < 0 ? 0.0 : t);
        default: return std::atan(t);
        }
    }
    case Node::Pow: {
        const double a = reference(*n.a, x), b = reference(*n.b, x);
        if (has_var(*n.b)) return std::pow(a, b);
        // A constant exponent: specialised at compile time.
        if (b == 0.0) return 1.0;
        if (b == 1.0) return a;
        if (b == std::floor(b) && std::fabs(b) <= 8) return int_power(a, static_cast<int>(b));
        if (b == 0.5) return std::sqrt(a);
        return std::pow(a, b);
    }
    case Node::Binary: {
        const double a = reference(*n.a, x), b = reference(*n.b, x);
        switch (n.fn) {
        case 0: return a + b;
        case 1: return a - b;
        case 2: return a * b;
        case 3: return a / b;
        case 4: return (a < b || std::isnan(a)) ? a : b;
        default: return (a > b || std::isnan(a)) ? a : b;
        }
    }
    }
    return 0.0;
}

} // namespace

/// True when some variable-free subtree evaluates to a non-finite value: the compiler folds
/// it to a constant and refuses it (issue 10).
bool has_nonfinite_constant(const Node& n) {
    if ((n.a && has_nonfinite_constant(*n.a)) || (n.b && has_nonfinite_constant(*n.b))) return true;
    return !has_var(n) && !std::isfinite(reference(n, nullptr));
}

TEST(Expression, RandomExpressionsMatchDirectEvaluation) {
    Pcg32 rng(99u, 4u);
    const size_t n = 300;
    std::vector<double> cols[3];
    for (auto& col : cols) {
        col.resize(n);
        for (double& v : col) v = 4.0 * rng.next_double() - 2.0;
    }
    cols[0][0] = 0.0; // and a few special points
    cols[1][1] = -0.0;
    cols[2][2] = 1.0;
    const double* vars[] = {cols[0].data(), cols[1].data(), cols[2].data()};
    std::vector<double> out(n);
    for (int t = 0; t < 400; ++t) {
        auto tree = random_tree(rng, 1 + static_cast<int>(rng.next_below(6)));
        const std::string text = print(*tree);
        if (has_nonfinite_constant(*tree)) {
            const std::string err = error_of(text, 3);
            EXPECT_NE(err.find("constants must be finite"), std::string::npos) << text << err;
            continue;
        }
        auto p = compile_ok(text, 3);
        ASSERT_TRUE(p);
        p->evaluate(vars, n, out.data());
        for (size_t i = 0; i < n; ++i) {
            const double pt[] = {cols[0][i], cols[1][i], cols[2][i]};
            const double want = reference(*tree, pt);
            ASSERT_TRUE(same(out[i], want)) << text << " at (" << pt[0] << ", " << pt[1] << ", "
                                            << pt[2] << "): " << out[i] << " vs " << want;
        }
    }
}

TEST(Expression, EvaluateInPlaceAndEmpty) {
    auto p = compile_ok("x*x + x", 1);
    ASSERT_TRUE(p);
    std::vector<double> x(600);
    for (size_t i = 0; i < x.size(); ++i) x[i] = 0.01 * static_cast<double>(i);
    std::vector<double> expected = x;
    for (double& v : expected) v = v * v + v;
    const double* vars[] = {x.data()};
    p->evaluate(vars, x.size(), x.data()); // out is the variable's own array
    EXPECT_EQ(x, expected);
    p->evaluate(vars, 0, x.data()); // n = 0: nothing to do
    EXPECT_EQ(x, expected);
}

// ---------------------------------------------------------------------------
// Errors

TEST(Expression, MalformedInputGivesExactMessages) {
    struct Case {
        std::string text;
        int dim;
        std::string message;
    };
    const std::string long_text(10001, '1');
    const std::string nested = std::string(300, '(') + "x" + std::string(300, ')');
    const Case cases[] = {
        {"", 1, "at position 1: empty expression"},
        {"   ", 1, "at position 1: empty expression"},
        {"1+", 1, "at position 3: expected an expression, got end of input"},
        {"(1+2", 1, "at position 5: expected ')' to close the '(' at position 1"},
        {"(1 2)", 1, "at position 4: expected ')' to close the '(' at position 1"},
        {"1+2)", 1, "at position 4: unexpected ')'"},
        {"(1+2))", 1, "at position 6: unexpected ')'"},
        {"sin(", 1, "at position 5: expected an expression, got end of input"},
        {"sin()", 1, "at position 5: sin takes 1 argument, got 0"},
        {"sin(1,2)", 1, "at position 7: sin takes 1 argument, got 2"},
        {"pow(1)", 1, "at position 6: pow takes 2 arguments, got 1"},
        {"max(1,2,3)", 1, "at position 9: max takes 2 arguments, got 3"},
        {"sin(1 2)", 1, "at position 7: expected ')' to close the '(' at position 4"},
        {"pow(x 2)", 1, "at position 7: expected ',' or ')' to close the '(' at position 4"},
        {"foo(x)", 1, "at position 1: unknown function 'foo'"},
        {"1+sinn(x)", 1, "at position 3: unknown function 'sinn'"},
        {"Sin(x)", 1,
         "at position 1: unknown function 'Sin' (names are case-sensitive: did you mean 'sin'?)"},
        {"w", 1,
         "at position 1: unknown variable 'w' (variables: x, x1 for a 1-dimensional domain)"},
        {"x4", 3,
         "at position 1: variable 'x4' is beyond the domain's dimension (variables: x, y, z, x1, "
         "x2, x3 for a 3-dimensional domain)"},
        {"sin", 1,
         "at position 1: function 'sin' needs its arguments in parentheses, as in sin(x)"},
        {"x(2)", 1, "at position 1: 'x' is a variable, not a function (write x*(...) to multiply)"},
        {"pi(2)", 1,
         "at position 1: 'pi' is a constant, not a function (write pi*(...) to multiply)"},
        {"1..2", 1, "at position 1: malformed number '1..2'"},
        {"x+1.2.3", 1, "at position 3: malformed number '1.2.3'"},
        {"1e", 1, "at position 1: malformed number '1e': the exponent has no digits"},
        {"2*1e+", 1, "at position 3: malformed number '1e+': the exponent has no digits"},
        {"2x", 1,
         "at position 2: expected an operator or end of input, got 'x' (implicit "
         "multiplication is not supported: write '2*x')"},
        {"3(x+1)", 1,
         "at position 2: expected an operator or end of input, got '(' (implicit "
         "multiplication is not supported: write '3*(')"},
        {"x^", 1, "at position 3: expected an expression, got end of input"},
        {"*2", 1, "at position 1: expected an expression, got '*'"},
        {"1 2", 1, "at position 3: expected an operator or end of input, got '2'"},
        {"x y", 2, "at position 3: expected an operator or end of input, got 'y'"},
        {"1,2", 1, "at position 2: expected an operator or end of input, got ','"},
        {"#", 1, "at position 1: unexpected character '#'"},
        {"x$y", 2, "at position 2: unexpected character '$'"},
        {".", 1, "at position 1: unexpected character '.'"},
        {"x+\xC3\xA9", 1, "at position 3: unexpected character '\xC3\xA9'"},
        {"\xC3\xA9+#", 1, "at position 1: unexpected character '\xC3\xA9'"},
        {"x + \x01", 1, "at position 5: unexpected character (byte 0x01)"},
        {"max(1,)", 1, "at position 7: expected an expression, got ')'"},
        {"(,)", 1, "at position 2: expected an expression, got ','"},
        {"()", 1, "at position 2: expected an expression, got ')'"},
        {"1e999", 1, "at position 1: number '1e999' is too large (it overflows to infinity)"},
        {"x*-1E400", 1, "at position 4: number '1E400' is too large (it overflows to infinity)"},
        {long_text, 1, "at position 10001: expression is longer than 10000 characters"},
        {nested, 1, "at position 201: expression nested too deeply (more than 200 levels)"},
    };
    for (const Case& c : cases)
        EXPECT_EQ(error_of(c.text, c.dim), c.message)
            << "input: '" << (c.text.size() > 40 ? c.text.substr(0, 40) + "..." : c.text) << "'";
}

// Issue 10: a folded constant that is not finite is refused like the literal "1e400" (before,
// "10^400" compiled to +inf while "1e400" was an error).
TEST(Expression, NonFiniteConstantsAreRefusedAfterFolding) {
    struct Case {
        std::string text;
        std::string message;
    };
    const Case cases[] = {
        {"10^400", "at position 1: the constant '10^400' is +infinite (it overflows); constants "
                   "must be finite"},
        {"x + 10^400", "at position 5: the constant '10^400' is +infinite (it overflows); "
                       "constants must be finite"},
        {"x*(1/0)", "at position 4: the constant '1/0' is +infinite (it overflows); constants "
                    "must be finite"},
        {"x - -1/0", "at position 5: the constant '-1/0' is -infinite (it overflows); constants "
                     "must be finite"},
        {"1e308 + 1e308", "at position 1: the constant '1e308 + 1e308' is +infinite (it "
                          "overflows); constants must be finite"},
        {"x + log(-1)", "at position 5: the constant 'log(-1)' is NaN (not a number); constants "
                        "must be finite"},
        {"0/0 + x", "at position 1: the constant '0/0' is NaN (not a number); constants must be "
                    "finite"},
        {"exp(1000)*x", "at position 1: the constant 'exp(1000)' is +infinite (it overflows); "
                        "constants must be finite"},
        {"pow(10, 400)", "at position 1: the constant 'pow(10, 400)' is +infinite (it "
                         "overflows); constants must be finite"},
        {"x*2^(2^11)", "at position 3: the constant '2^(2^11)' is +infinite (it overflows); "
                       "constants must be finite"},
        // The first non-finite sub-expression is named, even if a later step would fold it away.
        {"1/(1/0)", "at position 4: the constant '1/0' is +infinite (it overflows); constants "
                    "must be finite"},
        {"(1/0)^0", "at position 2: the constant '1/0' is +infinite (it overflows); constants "
                    "must be finite"},
    };
    for (const Case& c : cases) EXPECT_EQ(error_of(c.text, 1), c.message) << c.text;
    // A long constant is named by its first 37 characters.
    const std::string long_constant = "1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1e308 + 1e308";
    EXPECT_EQ(error_of(long_constant, 1),
              "at position 1: the constant '1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1 + 1...' is "
              "+infinite (it overflows); constants must be finite");
    // Finite folds, underflow to 0, and non-finite values at run time are fine.
    EXPECT_EQ(eval1("10^300 * x", 1.0), 1e300);
    EXPECT_EQ(eval1("10^-400 + x", 1.0), 1.0);
    EXPECT_EQ(eval1("x * 1e308 * 10", 1.0), kInf); // not a constant: (x * 1e308) * 10
    EXPECT_TRUE(std::isnan(eval1("log(-x)", 1.0)));
}

TEST(Expression, ErrorsReportTheFirstProblemInReadingOrder) {
    EXPECT_EQ(error_of("foo(1) + #", 1), "at position 1: unknown function 'foo'");
    EXPECT_EQ(error_of("1 + # + foo(1)", 1), "at position 5: unexpected character '#'");
    EXPECT_EQ(error_of("sin(1, w)", 1),
              "at position 8: unknown variable 'w' (variables: x, x1 for a 1-dimensional domain)");
}

TEST(Expression, LimitsOnSizeAndNesting) {
    // 200 levels of parentheses, function calls or powers are fine; 201 are not.
    const std::string ok_parens = std::string(200, '(') + "x" + std::string(200, ')');
    EXPECT_EQ(eval1(ok_parens, 0.5), 0.5);
    EXPECT_EQ(error_of(std::string(201, '(') + "x" + std::string(201, ')'), 1),
              "at position 201: expression nested too deeply (more than 200 levels)");
    std::string calls = "x";
    for (int i = 0; i < 200; ++i) calls = "abs(" + calls + ")";
    EXPECT_EQ(eval1(calls, -0.5), 0.5);
    EXPECT_EQ(error_of("abs(" + calls + ")", 1),
              "at position 804: expression nested too deeply (more than 200 levels)");
    std::string powers = "x";
    for (int i = 0; i < 200; ++i) powers += "^1";
    EXPECT_EQ(eval1(powers, 0.5), 0.5);
    EXPECT_EQ(error_of(powers + "^1", 1),
              "at position 402: expression nested too deeply (more than 200 levels)");
    // Deep nesting of another kind: 300 nested function calls.
    std::string deep_calls;
    for (int i = 0; i < 300; ++i) deep_calls += "sin(";
    deep_calls += "x" + std::string(300, ')');
    EXPECT_EQ(error_of(deep_calls, 1),
              "at position 804: expression nested too deeply (more than 200 levels)");

    // Long flat input is not nesting: 10000 characters compile (left-associative chains and
    // runs of signs are loops, not recursion).
    std::string sum = "x";
    while (sum.size() + 2 <= 10000) sum += "+x";
    sum.resize(10000, ' ');
    EXPECT_EQ(eval1(sum, 1.0), 5000.0);
    std::string signs(9999, '-');
    EXPECT_EQ(eval1(signs + "x", 2.0), -2.0);
    std::string product = "x";
    while (product.size() + 4 <= 10000) product += "*1.0";
    EXPECT_EQ(eval1(product, 3.0), 3.0);
    // Issue 10: hostile sizes fail fast with the limit's message, never with a stack overflow:
    // 100000 parentheses (the length limit is checked before any parsing), 200 levels inside
    // the length limit, a 10 MB text, and 100000 signs.
    const std::string deep_parens = std::string(100000, '(') + "x" + std::string(100000, ')');
    EXPECT_EQ(error_of(deep_parens, 1),
              "at position 10001: expression is longer than 10000 characters");
    const std::string deep_in_limit = std::string(4999, '(') + "x" + std::string(4999, ')');
    EXPECT_EQ(error_of(deep_in_limit, 1),
              "at position 201: expression nested too deeply (more than 200 levels)");
    std::string deep_powers = "x";
    for (int i = 0; i < 4000; ++i) deep_powers += "^x";
    EXPECT_EQ(error_of(deep_powers, 1),
              "at position 402: expression nested too deeply (more than 200 levels)");
    EXPECT_EQ(error_of(std::string(10u << 20, 'x'), 1),
              "at position 10001: expression is longer than 10000 characters");
    EXPECT_EQ(error_of(std::string(100000, '-') + "x", 1),
              "at position 10001: expression is longer than 10000 characters");
    // Many registers at once: a right-nested chain of products of variables.
    std::string chain = "x";
    for (int i = 0; i < 150; ++i) chain = "x*y+(" + chain + ")";
    auto p = compile_ok(chain, 2);
    ASSERT_TRUE(p);
    const double pt[] = {0.5, 0.0};
    EXPECT_EQ(p->evaluate_point(pt), 0.5);
}

// ---------------------------------------------------------------------------
// Threads

TEST(Expression, ConcurrentEvaluationMatchesSingleThread) {
    auto p = compile_ok("exp(-(x-0.5)^2/0.01) * (1 + sin(7*y)) + max(x, y)^3 / (1 + x*y)", 2);
    ASSERT_TRUE(p);
    const size_t n = 50000;
    std::vector<double> data[2][2]; // [task][coordinate]
    Pcg32 rng(5u, 1u);
    for (auto& task : data)
        for (auto& col : task) {
            col.resize(n);
            for (double& v : col) v = rng.next_double();
        }
    auto run = [&](int task, std::vector<double>* out) {
        out->assign(n, 0.0);
        // Blocks of different sizes, so that both tasks interleave their use of scratch.
        size_t off = 0, step = 1;
        while (off < n) {
            const size_t m = std::min(step, n - off);
            const double* vars[] = {data[task][0].data() + off, data[task][1].data() + off};
            p->evaluate(vars, m, out->data() + off);
            off += m;
            step = step % 300 + 37;
        }
    };
    std::vector<double> serial[2], parallel[2];
    run(0, &serial[0]);
    run(1, &serial[1]);
#ifdef MCP_TEST_THREADS
    std::thread a(run, 0, &parallel[0]);
    std::thread b(run, 1, &parallel[1]);
    a.join();
    b.join();
#else
    // No threads in this build (Emscripten without pthreads): the same runs, one after the
    // other, still compared.
    run(0, &parallel[0]);
    run(1, &parallel[1]);
#endif
    for (int t = 0; t < 2; ++t) {
        ASSERT_EQ(parallel[t].size(), n);
        for (size_t i = 0; i < n; ++i)
            ASSERT_TRUE(same(parallel[t][i], serial[t][i])) << t << " " << i;
    }
    // And each agrees with point evaluation.
    for (size_t i = 0; i < n; i += 997) {
        const double pt[] = {data[1][0][i], data[1][1][i]};
        EXPECT_TRUE(same(serial[1][i], p->evaluate_point(pt)));
    }
}
