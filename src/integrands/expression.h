// User-typed expressions ("exp(-(x-0.5)^2/0.01)", "x1*x2 + sin(pi*y)", "step(x-0.3)"):
// parsed by recursive descent, constant-folded, and compiled to a linear instruction list
// over registers that is run one instruction at a time over a whole block of points, so the
// interpretation cost is paid once per instruction per block, not once per point.
//
// Language (see compile_expression):
//   numbers     12  0.5  .5  1.  1e-3  2.5E+8   (finite; "1e999" is an error)
//   constants   pi  e
//   variables   x y z (= x1 x2 x3), x1 .. x<dim>; or, compiled with ExprVariables::Unit (the
//               coordinates of a point of the unit cube, as warps read them), u (= u1), u1 ..
//               u<dim>
//   operators   precedence from loosest to tightest:
//                 + -  binary, left-associative
//                 * /  binary, left-associative
//                 + -  unary (may repeat: --2 = 2; -x^2 = -(x^2); 2*-3 = -6)
//                 ^    binary, right-associative (2^3^2 = 512); its exponent may carry a
//                      unary sign (2^-1 = 0.5, 2^-x^2 = 2^(-(x^2)))
//   functions   sin cos tan asin acos atan sinh cosh tanh exp log (natural) log10 sqrt
//               abs floor ceil erf step sign (one argument); pow min max (two arguments)
//               step(t) = 1 for t >= 0 (so step(0) = 1), 0 for t < 0, NaN for NaN;
//               sign(t) = -1, 0 or 1 (0 keeps the sign of a zero t), NaN for NaN;
//               min and max return NaN when either argument is NaN (unlike std::fmin).
//   No implicit multiplication ("2x" is an error). Identifiers are case-sensitive.
// Arithmetic is plain IEEE double: log(x) at x = -1 is NaN, 1/x at x = 0 is inf; evaluation
// never traps. Constants are folded at compile time, and a constant (sub-)expression that is
// not finite is an error like "1e400": "10^400", "1/0", "log(-1)", "exp(1000)" are refused
// ("the constant '10^400' is +infinite (it overflows); constants must be finite").
// a^k for an integer constant |k| <= 8 is computed by repeated multiplication (a^-k as
// 1/(a^k)), a^0.5 as sqrt(a) (so (-inf)^0.5 is NaN, not inf), a^0 is 1 (NaN^0 too, as
// std::pow); any other power calls std::pow. pow(a, b) is the same as a^b.
// Limits: at most 10000 bytes of text and 200 levels of nesting (parentheses, calls and
// exponents); beyond them compile_expression returns an error, never crashes. The length is
// checked before anything is read, and every recursive step of the parser counts a level, so
// the call stack is bounded whatever the input (runs of signs and flat chains are loops).
// Errors read "at position P: MESSAGE", P the 1-based column (in characters, UTF-8 aware)
// of the offending token; the first problem in reading order is reported.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/made.h"

namespace mcp {

/// A compiled expression: an immutable instruction list, safe to share between threads.
class ExprProgram {
  public:
    /// out[i] = value of the expression at point i, for i < n (n <= kBlockSize is typical
    /// but any n must work). vars[j] points to n values of variable j (x1 = vars[0], ...).
    /// No allocation per call after the first on a thread (use a thread_local scratch
    /// buffer grown on demand). out may be one of the variables' arrays (in place) but must
    /// not partially overlap one.
    void evaluate(const double* const* vars, size_t n, double* out) const;
    /// Scalar convenience for tests and tabulation (not for hot loops).
    double evaluate_point(const double* x) const;
    int dimension() const; ///< the dimension it was compiled for
    const std::string& source() const;
    size_t instruction_count() const; ///< after constant folding

  private:
    friend class ExprCompiler;

    /// Where an instruction reads an argument: a constant, a caller's variable array or a
    /// scratch register.
    struct Operand {
        enum Kind : uint8_t { None, Const, Var, Reg };
        Kind kind = None;
        int index = 0;      ///< variable (0-based) or register
        double value = 0.0; ///< the constant
    };
    /// dest = op(a) or op(a, b); a fused pair of arithmetic operations computes
    /// dest = outer(inner(a, b), c) (inner_left) or outer(c, inner(a, b)) in one loop.
    struct Instr {
        uint8_t op = 0;    ///< an ExprOp (expression.cpp)
        uint8_t inner = 0; ///< fused: the first operation
        uint8_t outer = 0; ///< fused: the second operation
        bool inner_left = false;
        int8_t k = 0; ///< the exponent of an integer power
        int dest = 0; ///< register written
        Operand a, b; ///< b only for binary operations
        Operand c;    ///< fused only; constants of fused operations are read from splats_
    };

    void run_chunk(const double* const* vars, size_t off, size_t m, double* regs,
                   double* out) const;

    std::string source_;
    int dim_ = 1;
    std::vector<Instr> code_;
    int num_regs_ = 0;
    Operand result_; ///< the value of the expression: a constant, a variable or register 0
    std::vector<double> splats_; ///< kBlockSize copies of each constant of a fused operation
};

/// Which names the variables of an expression have.
enum class ExprVariables {
    Point, ///< a domain point: x, y, z (= x1, x2, x3) and x1 .. x<dim>
    Unit,  ///< a point of the unit cube (a warp's input): u (= u1) and u1 .. u<dim>
};

/// Parses and compiles `text` for points of `dim` dimensions (1..64). Variables (Point):
/// x, y, z name x1, x2, x3 (x alone is x1); x1..x<dim> by index; (Unit): u names u1, u1..u<dim>
/// by index, and x, y, z are unknown. Using a variable beyond dim is an error. On error,
/// Made::error is "at position P: MESSAGE" (P = 1-based character column).
Made<std::shared_ptr<const ExprProgram>>
compile_expression(const std::string& text, int dim,
                   ExprVariables variables = ExprVariables::Point);

} // namespace mcp
