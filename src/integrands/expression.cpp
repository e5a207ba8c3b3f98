// Expression compiler: a lazy lexer, a recursive-descent parser that emits instructions
// as it goes (single pass, no AST), constant folding on the fly, and a block interpreter.
//
// Each parse function yields an Operand: a constant (folded), a variable (the caller's
// array, never copied) or a register holding an emitted instruction's result. Registers
// follow a stack discipline: the registers in use are exactly those held by operands still
// pending in the parser, numbered 0, 1, 2, ... in the order they were created, so an
// operation releases its operands' registers (always the top ones) and takes the lowest
// free one for its result. The final value of a non-constant expression is register 0,
// written by the last instruction; the interpreter points that instruction at `out`.
#include "integrands/expression.h"

#include <cassert>
#include <clocale>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "core/exp_block.h"
#include "core/points.h"

namespace mcp {

namespace {

constexpr size_t kMaxTextLength = 10000;
constexpr int kMaxDepth = 200;
constexpr int kMaxDim = 64;
constexpr int kMaxIntPower = 8; ///< a^k by repeated multiplication for |k| <= this
constexpr double kPiValue = 3.14159265358979323846;
constexpr double kEValue = 2.71828182845904523536;

enum ExprOp : uint8_t {
    // unary (operand a is never a constant: constants are folded)
    OpNeg,
    OpSin,
    OpCos,
    OpTan,
    OpAsin,
    OpAcos,
    OpAtan,
    OpSinh,
    OpCosh,
    OpTanh,
    OpExp,
    OpLog,
    OpLog10,
    OpSqrt,
    OpAbs,
    OpFloor,
    OpCeil,
    OpErf,
    OpStep,
    OpSign,
    OpIntPow, ///< a^k, k = Instr::k in [-8, 8] \ {0, 1}
    // binary (at most one operand is a constant)
    OpAdd,
    OpSub,
    OpMul,
    OpDiv,
    OpPow,
    OpMin,
    OpMax,
    // two arithmetic operations (OpAdd..OpDiv) fused into one loop
    OpFused,
};

bool is_binary(uint8_t op) {
    return op >= OpAdd && op <= OpMax;
}
bool is_arithmetic(uint8_t op) {
    return op >= OpAdd && op <= OpDiv;
}

// ---------------------------------------------------------------------------
// Scalar kernels, shared by constant folding and the block loops so that a folded
// constant equals what the interpreter would have computed.

inline double k_step(double t) {
    return t >= 0.0 ? 1.0 : (t < 0.0 ? 0.0 : t);
}
inline double k_sign(double t) {
    return t > 0.0 ? 1.0 : (t < 0.0 ? -1.0 : t);
}
inline double k_min(double a, double b) {
    return (a < b || std::isnan(a)) ? a : b;
}
inline double k_max(double a, double b) {
    return (a > b || std::isnan(a)) ? a : b;
}

template <int K> inline double ipow_pos(double a) {
    static_assert(K >= 2 && K <= 8, "integer powers 2..8");
    if constexpr (K == 2) {
        return a * a;
    } else if constexpr (K == 3) {
        return a * a * a;
    } else {
        const double t = a * a;
        if constexpr (K == 4) return t * t;
        if constexpr (K == 5) return t * t * a;
        if constexpr (K == 6) return t * t * t;
        if constexpr (K == 7) return t * t * t * a;
        if constexpr (K == 8) {
            const double q = t * t;
            return q * q;
        }
    }
}

template <int K> inline double ipow(double a) {
    if constexpr (K == -1) {
        return 1.0 / a;
    } else if constexpr (K < 0) {
        return 1.0 / ipow_pos<-K>(a);
    } else {
        return ipow_pos<K>(a);
    }
}

// X(k) for every integer power k handled by multiplication: [-8, 8] without 0 and 1.
#define MCP_FOR_INT_POWERS(X)                                                                      \
    X(-8) X(-7) X(-6) X(-5) X(-4) X(-3) X(-2) X(-1) X(2) X(3) X(4) X(5) X(6) X(7) X(8)

double int_pow_scalar(double a, int k) {
    switch (k) {
#define MCP_CASE(K)                                                                                \
    case K: return ipow<K>(a);
        MCP_FOR_INT_POWERS(MCP_CASE)
#undef MCP_CASE
    }
    return std::pow(a, static_cast<double>(k));
}

bool is_small_int_power(double c) {
    return c == std::floor(c) && std::fabs(c) <= kMaxIntPower;
}

/// a^c for a constant exponent c, as the compiled program computes it.
double pow_const_exponent(double a, double c) {
    if (c == 0.0) return 1.0;
    if (c == 1.0) return a;
    if (is_small_int_power(c)) return int_pow_scalar(a, static_cast<int>(c));
    if (c == 0.5) return std::sqrt(a);
    return std::pow(a, c);
}

double apply_unary(uint8_t op, int k, double a) {
    switch (op) {
    case OpNeg: return -a;
    case OpSin: return std::sin(a);
    case OpCos: return std::cos(a);
    case OpTan: return std::tan(a);
    case OpAsin: return std::asin(a);
    case OpAcos: return std::acos(a);
    case OpAtan: return std::atan(a);
    case OpSinh: return std::sinh(a);
    case OpCosh: return std::cosh(a);
    case OpTanh: return std::tanh(a);
    case OpExp: return exp_tang(a);
    case OpLog: return std::log(a);
    case OpLog10: return std::log10(a);
    case OpSqrt: return std::sqrt(a);
    case OpAbs: return std::fabs(a);
    case OpFloor: return std::floor(a);
    case OpCeil: return std::ceil(a);
    case OpErf: return std::erf(a);
    case OpStep: return k_step(a);
    case OpSign: return k_sign(a);
    case OpIntPow: return int_pow_scalar(a, k);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

double apply_binary(uint8_t op, double a, double b) {
    switch (op) {
    case OpAdd: return a + b;
    case OpSub: return a - b;
    case OpMul: return a * b;
    case OpDiv: return a / b;
    case OpPow: return pow_const_exponent(a, b); // both constant: the exponent is a constant
    case OpMin: return k_min(a, b);
    case OpMax: return k_max(a, b);
    }
    return std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------
// Block loops: one tight loop per (operation, operand kinds); no dispatch per point.

// Four vectors an iteration under clang (the wasm build): V8 pays a stack check and the address
// arithmetic of every iteration; `(x-0.5)^2/0.01` took 0.94 ns a point instead of 1.00.
#if defined(__clang__)
#define MCP_INTERLEAVE _Pragma("clang loop interleave_count(4)")
#else
#define MCP_INTERLEAVE
#endif

template <class F> inline void loop1(const double* a, double* r, size_t n, F f) {
    MCP_INTERLEAVE for (size_t i = 0; i < n; ++i) r[i] = f(a[i]);
}

/// A resolved operand: an array (p != nullptr) or a constant c.
struct Arg {
    const double* p;
    double c;
};

template <class F> inline void loop2(Arg a, Arg b, double* r, size_t n, F f) {
    if (a.p && b.p) {
        const double* pa = a.p;
        const double* pb = b.p;
        MCP_INTERLEAVE for (size_t i = 0; i < n; ++i) r[i] = f(pa[i], pb[i]);
    } else if (a.p) {
        const double* pa = a.p;
        const double cb = b.c;
        MCP_INTERLEAVE for (size_t i = 0; i < n; ++i) r[i] = f(pa[i], cb);
    } else {
        const double ca = a.c;
        const double* pb = b.p;
        MCP_INTERLEAVE for (size_t i = 0; i < n; ++i) r[i] = f(ca, pb[i]);
    }
}

void run_unary(uint8_t op, int k, const double* a, double* r, size_t n) {
    switch (op) {
    case OpNeg: loop1(a, r, n, [](double v) { return -v; }); return;
    case OpSin: loop1(a, r, n, [](double v) { return std::sin(v); }); return;
    case OpCos: loop1(a, r, n, [](double v) { return std::cos(v); }); return;
    case OpTan: loop1(a, r, n, [](double v) { return std::tan(v); }); return;
    case OpAsin: loop1(a, r, n, [](double v) { return std::asin(v); }); return;
    case OpAcos: loop1(a, r, n, [](double v) { return std::acos(v); }); return;
    case OpAtan: loop1(a, r, n, [](double v) { return std::atan(v); }); return;
    case OpSinh: loop1(a, r, n, [](double v) { return std::sinh(v); }); return;
    case OpCosh: loop1(a, r, n, [](double v) { return std::cosh(v); }); return;
    case OpTanh: loop1(a, r, n, [](double v) { return std::tanh(v); }); return;
    case OpExp: exp_block(a, r, n); return; // two lanes a step, as fast in wasm as natively
    case OpLog: loop1(a, r, n, [](double v) { return std::log(v); }); return;
    case OpLog10: loop1(a, r, n, [](double v) { return std::log10(v); }); return;
    case OpSqrt: loop1(a, r, n, [](double v) { return std::sqrt(v); }); return;
    case OpAbs: loop1(a, r, n, [](double v) { return std::fabs(v); }); return;
    case OpFloor: loop1(a, r, n, [](double v) { return std::floor(v); }); return;
    case OpCeil: loop1(a, r, n, [](double v) { return std::ceil(v); }); return;
    case OpErf: loop1(a, r, n, [](double v) { return std::erf(v); }); return;
    case OpStep: loop1(a, r, n, k_step); return;
    case OpSign: loop1(a, r, n, k_sign); return;
    case OpIntPow:
        switch (k) {
#define MCP_CASE(K)                                                                                \
    case K: loop1(a, r, n, ipow<K>); return;
            MCP_FOR_INT_POWERS(MCP_CASE)
#undef MCP_CASE
        }
        return;
    }
}

void run_binary(uint8_t op, Arg a, Arg b, double* r, size_t n) {
    switch (op) {
    case OpAdd: loop2(a, b, r, n, [](double u, double v) { return u + v; }); return;
    case OpSub: loop2(a, b, r, n, [](double u, double v) { return u - v; }); return;
    case OpMul: loop2(a, b, r, n, [](double u, double v) { return u * v; }); return;
    case OpDiv: loop2(a, b, r, n, [](double u, double v) { return u / v; }); return;
    case OpPow: loop2(a, b, r, n, [](double u, double v) { return std::pow(u, v); }); return;
    case OpMin: loop2(a, b, r, n, k_min); return;
    case OpMax: loop2(a, b, r, n, k_max); return;
    }
}

#undef MCP_FOR_INT_POWERS

/// Calls body(f) with f the arithmetic operation op (OpAdd..OpDiv).
template <class Body> inline void with_arithmetic(uint8_t op, Body body) {
    switch (op) {
    case OpAdd: body([](double u, double v) { return u + v; }); return;
    case OpSub: body([](double u, double v) { return u - v; }); return;
    case OpMul: body([](double u, double v) { return u * v; }); return;
    case OpDiv: body([](double u, double v) { return u / v; }); return;
    }
}

template <bool InnerLeft, class F1, class F2>
inline void loop_fused(const double* a, const double* b, const double* c, double* r, size_t n,
                       F1 inner, F2 outer) {
    MCP_INTERLEAVE for (size_t i = 0; i < n; ++i) {
        const double t = inner(a[i], b[i]); // rounded to double, as in two separate loops
        r[i] = InnerLeft ? outer(t, c[i]) : outer(c[i], t);
    }
}

/// r = outer(inner(a, b), c) or outer(c, inner(a, b)): two arithmetic operations in one
/// pass over memory (constants come as splat arrays), bit-identical to two passes.
void run_fused(uint8_t inner_op, uint8_t outer_op, bool inner_left, const double* a,
               const double* b, const double* c, double* r, size_t n) {
    with_arithmetic(inner_op, [&](auto inner) {
        with_arithmetic(outer_op, [&](auto outer) {
            if (inner_left)
                loop_fused<true>(a, b, c, r, n, inner, outer);
            else
                loop_fused<false>(a, b, c, r, n, inner, outer);
        });
    });
}

// ---------------------------------------------------------------------------
// Names.

struct FunctionInfo {
    const char* name;
    uint8_t op;
    int arity;
};

constexpr FunctionInfo kFunctions[] = {
    {"sin", OpSin, 1},   {"cos", OpCos, 1},   {"tan", OpTan, 1},     {"asin", OpAsin, 1},
    {"acos", OpAcos, 1}, {"atan", OpAtan, 1}, {"sinh", OpSinh, 1},   {"cosh", OpCosh, 1},
    {"tanh", OpTanh, 1}, {"exp", OpExp, 1},   {"log", OpLog, 1},     {"log10", OpLog10, 1},
    {"sqrt", OpSqrt, 1}, {"abs", OpAbs, 1},   {"floor", OpFloor, 1}, {"ceil", OpCeil, 1},
    {"erf", OpErf, 1},   {"step", OpStep, 1}, {"sign", OpSign, 1},   {"pow", OpPow, 2},
    {"min", OpMin, 2},   {"max", OpMax, 2},
};

const FunctionInfo* find_function(const std::string& name) {
    for (const FunctionInfo& f : kFunctions)
        if (name == f.name) return &f;
    return nullptr;
}

std::string to_lower(std::string s) {
    for (char& c : s)
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    return s;
}

bool is_digit(char c) {
    return c >= '0' && c <= '9';
}
bool is_alpha(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || c == '_';
}
bool is_alnum(char c) {
    return is_alpha(c) || is_digit(c);
}
bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v';
}

/// "x, y, z, x1..x5" for the variables of a dim-dimensional domain, or "u, u1, u2" for those
/// of a unit cube.
std::string variables_text(int dim, ExprVariables kind) {
    if (kind == ExprVariables::Unit) {
        std::string s = "u";
        if (dim <= 3) {
            for (int j = 1; j <= dim; ++j) s += ", u" + std::to_string(j);
        } else {
            s += ", u1..u" + std::to_string(dim);
        }
        return s + " for a " + std::to_string(dim) + "-dimensional unit cube";
    }
    std::string s = "x";
    if (dim >= 2) s += ", y";
    if (dim >= 3) s += ", z";
    if (dim <= 3) {
        for (int j = 1; j <= dim; ++j) s += ", x" + std::to_string(j);
    } else {
        s += ", x1..x" + std::to_string(dim);
    }
    return s + " for a " + std::to_string(dim) + "-dimensional domain";
}

/// 0-based index of the variable x, y, z or x<k> (k >= 1, no leading zero), or of u, u<k> for
/// a unit cube; -1 for other names. The index may be beyond the domain.
long variable_index(const std::string& name, ExprVariables kind) {
    const char letter = kind == ExprVariables::Unit ? 'u' : 'x';
    if (name.size() == 1 && name[0] == letter) return 0;
    if (kind == ExprVariables::Point) {
        if (name == "y") return 1;
        if (name == "z") return 2;
    }
    if (name.size() < 2 || name[0] != letter || name[1] == '0') return -1;
    for (size_t i = 1; i < name.size(); ++i)
        if (!is_digit(name[i])) return -1;
    if (name.size() > 7) return 1000000; // beyond any domain
    return std::strtol(name.c_str() + 1, nullptr, 10) - 1;
}

/// Reads a number already checked to match [0-9]*(.[0-9]*)?([eE][+-]?[0-9]+)?, independently
/// of the C locale's decimal point.
double read_number(const std::string& token) {
    std::string s = token;
    const char* point = std::localeconv()->decimal_point;
    if (point && std::strcmp(point, ".") != 0) {
        const size_t dot = s.find('.');
        if (dot != std::string::npos) s.replace(dot, 1, point);
    }
    return std::strtod(s.c_str(), nullptr);
}

} // namespace

// ---------------------------------------------------------------------------
// The compiler (a friend of ExprProgram).

class ExprCompiler {
  public:
    using Operand = ExprProgram::Operand;
    using Instr = ExprProgram::Instr;

    ExprCompiler(const std::string& text, int dim, ExprVariables variables)
        : text_(text), dim_(dim), variables_(variables) {}

    bool compile(ExprProgram& program);
    const std::string& error() const { return error_; }

  private:
    enum TokKind {
        TEnd,
        TNumber,
        TIdent,
        TPlus,
        TMinus,
        TStar,
        TSlash,
        TCaret,
        TLParen,
        TRParen,
        TComma
    };
    struct Token {
        TokKind kind = TEnd;
        size_t pos = 0; ///< byte offset
        size_t len = 0;
        double number = 0.0;
    };

    // Lexer.
    bool advance();
    bool lex_number();
    std::string token_text(const Token& t) const {
        return t.kind == TEnd ? "end of input" : "'" + text_.substr(t.pos, t.len) + "'";
    }

    // Errors: the first one wins.
    size_t column(size_t offset) const;
    bool fail(size_t offset, const std::string& message);
    std::string juxtaposition_hint() const;
    bool enter(size_t offset) {
        if (++depth_ > kMaxDepth)
            return fail(offset, "expression nested too deeply (more than " +
                                    std::to_string(kMaxDepth) + " levels)");
        return true;
    }
    void leave() { --depth_; }
    /// A folded constant must be finite: "10^400", "1/0", "log(-1)" are refused like "1e400",
    /// naming the sub-expression text_[start, end of the last token read).
    bool finite_constant(const Operand& v, size_t start);

    // Parser.
    bool parse_sum(Operand& v);
    bool parse_product(Operand& v);
    bool parse_factor(Operand& v);
    bool parse_primary(Operand& v);
    bool parse_call(const std::string& name, size_t name_pos, Operand& v);
    bool parse_name(const std::string& name, size_t pos, Operand& v);

    // Code generation.
    static Operand constant(double c) {
        Operand o;
        o.kind = Operand::Const;
        o.value = c;
        return o;
    }
    static Operand reg(int r) {
        Operand o;
        o.kind = Operand::Reg;
        o.index = r;
        return o;
    }
    int alloc() {
        const int r = next_reg_++;
        if (next_reg_ > max_regs_) max_regs_ = next_reg_;
        return r;
    }
    void release(const Operand& o) {
        if (o.kind != Operand::Reg) return;
        assert(o.index == next_reg_ - 1); // always the top register
        --next_reg_;
    }
    Operand unary(uint8_t op, Operand a, int k = 0);
    Operand binary(uint8_t op, Operand a, Operand b);
    Operand power(Operand base, Operand exponent, size_t base_mark);
    bool try_fuse(uint8_t op, const Operand& a, const Operand& b, Operand* result);
    bool splat(Operand* o);

    const std::string& text_;
    int dim_;
    ExprVariables variables_;
    size_t pos_ = 0;
    Token tok_;
    TokKind prev_kind_ = TEnd;
    size_t prev_pos_ = 0;
    size_t prev_end_ = 0;
    std::string error_;
    int depth_ = 0;
    std::vector<Instr> code_;
    int next_reg_ = 0;
    int max_regs_ = 0;
    std::vector<double> splat_values_; ///< constants of fused instructions, one slot each
};

size_t ExprCompiler::column(size_t offset) const {
    // Characters, not bytes: UTF-8 continuation bytes do not start a column.
    size_t col = 1;
    for (size_t i = 0; i < offset && i < text_.size(); ++i)
        if ((static_cast<unsigned char>(text_[i]) & 0xC0u) != 0x80u) ++col;
    return col;
}

bool ExprCompiler::fail(size_t offset, const std::string& message) {
    if (error_.empty()) error_ = "at position " + std::to_string(column(offset)) + ": " + message;
    return false;
}

bool ExprCompiler::finite_constant(const Operand& v, size_t start) {
    if (v.kind != Operand::Const || std::isfinite(v.value)) return true;
    std::string sub = prev_end_ > start ? text_.substr(start, prev_end_ - start) : std::string();
    if (sub.size() > 40) sub = sub.substr(0, 37) + "...";
    return fail(start, "the constant '" + sub + "' is " +
                           (std::isnan(v.value) ? std::string("NaN (not a number)")
                                                : std::string(v.value > 0 ? "+" : "-") +
                                                      "infinite (it overflows)") +
                           "; constants must be finite");
}

/// " (implicit multiplication ...)" when the current token directly follows a number, as in
/// "2x", "2pi" or "3(x+1)".
std::string ExprCompiler::juxtaposition_hint() const {
    if (prev_kind_ != TNumber || tok_.pos != prev_end_) return "";
    if (tok_.kind != TIdent && tok_.kind != TLParen) return "";
    return " (implicit multiplication is not supported: write '" +
           text_.substr(prev_pos_, prev_end_ - prev_pos_) + "*" + text_.substr(tok_.pos, tok_.len) +
           "')";
}

bool ExprCompiler::lex_number() {
    const size_t start = pos_;
    size_t p = pos_;
    while (p < text_.size() && is_digit(text_[p])) ++p;
    if (p < text_.size() && text_[p] == '.') {
        ++p;
        while (p < text_.size() && is_digit(text_[p])) ++p;
    }
    if (p < text_.size() && (text_[p] == 'e' || text_[p] == 'E')) {
        size_t q = p + 1;
        if (q < text_.size() && (text_[q] == '+' || text_[q] == '-')) ++q;
        if (q < text_.size() && is_digit(text_[q])) {
            while (q < text_.size() && is_digit(text_[q])) ++q;
            p = q;
        } else if (q > p + 1 || q >= text_.size() || !is_alpha(text_[q])) {
            // "1e", "1e+", "1e)": an exponent without digits. (A letter after e, as in
            // "2exp(x)", ends the number before the e.)
            return fail(start, "malformed number '" + text_.substr(start, q - start) +
                                   "': the exponent has no digits");
        }
    }
    if (p < text_.size() && text_[p] == '.') {
        size_t q = p;
        while (q < text_.size() && (is_alnum(text_[q]) || text_[q] == '.')) ++q;
        return fail(start, "malformed number '" + text_.substr(start, q - start) + "'");
    }
    const std::string token = text_.substr(start, p - start);
    const double value = read_number(token);
    if (!std::isfinite(value))
        return fail(start, "number '" + token + "' is too large (it overflows to infinity)");
    tok_.kind = TNumber;
    tok_.len = p - start;
    tok_.number = value;
    pos_ = p;
    return true;
}

bool ExprCompiler::advance() {
    if (!error_.empty()) return false;
    prev_kind_ = tok_.kind;
    prev_pos_ = tok_.pos;
    prev_end_ = tok_.pos + tok_.len;
    while (pos_ < text_.size() && is_space(text_[pos_])) ++pos_;
    tok_ = Token{};
    tok_.pos = pos_;
    if (pos_ >= text_.size()) {
        tok_.kind = TEnd;
        return true;
    }
    const char c = text_[pos_];
    if (is_digit(c) || (c == '.' && pos_ + 1 < text_.size() && is_digit(text_[pos_ + 1])))
        return lex_number();
    if (is_alpha(c)) {
        size_t p = pos_;
        while (p < text_.size() && is_alnum(text_[p])) ++p;
        tok_.kind = TIdent;
        tok_.len = p - pos_;
        pos_ = p;
        return true;
    }
    TokKind kind = TEnd;
    switch (c) {
    case '+': kind = TPlus; break;
    case '-': kind = TMinus; break;
    case '*': kind = TStar; break;
    case '/': kind = TSlash; break;
    case '^': kind = TCaret; break;
    case '(': kind = TLParen; break;
    case ')': kind = TRParen; break;
    case ',': kind = TComma; break;
    default: {
        const unsigned char u = static_cast<unsigned char>(c);
        if (u >= 0x21 && u <= 0x7E)
            return fail(pos_, std::string("unexpected character '") + c + "'");
        if (u >= 0xC0) { // a UTF-8 sequence: show the whole character
            size_t q = pos_ + 1;
            while (q < text_.size() && (static_cast<unsigned char>(text_[q]) & 0xC0u) == 0x80u) ++q;
            return fail(pos_, "unexpected character '" + text_.substr(pos_, q - pos_) + "'");
        }
        char buf[8];
        std::snprintf(buf, sizeof buf, "0x%02X", static_cast<unsigned>(u));
        return fail(pos_, std::string("unexpected character (byte ") + buf + ")");
    }
    }
    tok_.kind = kind;
    tok_.len = 1;
    ++pos_;
    return true;
}

// sum     := product (('+' | '-') product)*
// product := factor (('*' | '/') factor)*
// factor  := ('+' | '-')* primary ('^' factor)?
// primary := number | constant | variable | function '(' sum (',' sum)* ')' | '(' sum ')'

bool ExprCompiler::parse_sum(Operand& v) {
    const size_t start = tok_.pos;
    if (!parse_product(v)) return false;
    while (tok_.kind == TPlus || tok_.kind == TMinus) {
        const uint8_t op = tok_.kind == TPlus ? OpAdd : OpSub;
        if (!advance()) return false;
        Operand rhs;
        if (!parse_product(rhs)) return false;
        v = binary(op, v, rhs);
        if (!finite_constant(v, start)) return false;
    }
    return true;
}

bool ExprCompiler::parse_product(Operand& v) {
    const size_t start = tok_.pos;
    if (!parse_factor(v)) return false;
    while (tok_.kind == TStar || tok_.kind == TSlash) {
        const uint8_t op = tok_.kind == TStar ? OpMul : OpDiv;
        if (!advance()) return false;
        Operand rhs;
        if (!parse_factor(rhs)) return false;
        v = binary(op, v, rhs);
        if (!finite_constant(v, start)) return false;
    }
    return true;
}

bool ExprCompiler::parse_factor(Operand& v) {
    bool negate = false; // a run of signs is applied after the power: -x^2 = -(x^2)
    while (tok_.kind == TPlus || tok_.kind == TMinus) {
        if (tok_.kind == TMinus) negate = !negate;
        if (!advance()) return false;
    }
    const size_t mark = code_.size();
    const size_t start = tok_.pos;
    if (!parse_primary(v)) return false;
    if (tok_.kind == TCaret) {
        const size_t caret = tok_.pos;
        if (!advance() || !enter(caret)) return false;
        Operand exponent;
        if (!parse_factor(exponent)) return false; // right-associative, may carry a sign
        leave();
        v = power(v, exponent, mark);
        if (!finite_constant(v, start)) return false;
    }
    if (negate) v = unary(OpNeg, v);
    return true;
}

bool ExprCompiler::parse_primary(Operand& v) {
    switch (tok_.kind) {
    case TNumber: v = constant(tok_.number); return advance();
    case TIdent: {
        const std::string name = text_.substr(tok_.pos, tok_.len);
        const size_t name_pos = tok_.pos;
        if (!advance()) return false;
        if (tok_.kind == TLParen) return parse_call(name, name_pos, v);
        return parse_name(name, name_pos, v);
    }
    case TLParen: {
        const size_t open = tok_.pos;
        if (!advance() || !enter(open)) return false;
        if (!parse_sum(v)) return false;
        if (tok_.kind != TRParen)
            return fail(tok_.pos, "expected ')' to close the '(' at position " +
                                      std::to_string(column(open)) + juxtaposition_hint());
        leave();
        return advance();
    }
    default: return fail(tok_.pos, "expected an expression, got " + token_text(tok_));
    }
}

bool ExprCompiler::parse_name(const std::string& name, size_t pos, Operand& v) {
    if (name == "pi") {
        v = constant(kPiValue);
        return true;
    }
    if (name == "e") {
        v = constant(kEValue);
        return true;
    }
    if (find_function(name))
        return fail(pos, "function '" + name + "' needs its arguments in parentheses, as in " +
                             name + (find_function(name)->arity == 2 ? "(a, b)" : "(x)"));
    const long index = variable_index(name, variables_);
    if (index < 0)
        return fail(pos, "unknown variable '" + name +
                             "' (variables: " + variables_text(dim_, variables_) + ")");
    if (index >= dim_)
        return fail(pos, "variable '" + name + "' is beyond the " +
                             (variables_ == ExprVariables::Unit ? "unit cube's" : "domain's") +
                             " dimension (variables: " + variables_text(dim_, variables_) + ")");
    v = Operand{};
    v.kind = Operand::Var;
    v.index = static_cast<int>(index);
    return true;
}

bool ExprCompiler::parse_call(const std::string& name, size_t name_pos, Operand& v) {
    const FunctionInfo* f = find_function(name);
    if (!f) {
        if (name == "pi" || name == "e")
            return fail(name_pos, "'" + name + "' is a constant, not a function (write " + name +
                                      "*(...) to multiply)");
        if (variable_index(name, variables_) >= 0)
            return fail(name_pos, "'" + name + "' is a variable, not a function (write " + name +
                                      "*(...) to multiply)");
        const FunctionInfo* similar = find_function(to_lower(name));
        return fail(name_pos, "unknown function '" + name + "'" +
                                  (similar ? std::string(" (names are case-sensitive: did you "
                                                         "mean '") +
                                                 similar->name + "'?)"
                                           : std::string()));
    }
    const size_t open = tok_.pos;
    if (!advance() || !enter(open)) return false;
    Operand args[2];
    int count = 0;
    size_t first_arg_mark = code_.size();
    size_t excess_pos = 0;
    if (tok_.kind != TRParen) {
        for (;;) {
            const size_t arg_pos = tok_.pos;
            const size_t mark = code_.size();
            const int reg_mark = next_reg_;
            Operand a;
            if (!parse_sum(a)) return false;
            if (count < f->arity) {
                args[count] = a;
            } else { // parsed for its errors, then dropped
                code_.resize(mark);
                next_reg_ = reg_mark;
                if (count == f->arity) excess_pos = arg_pos;
            }
            ++count;
            if (tok_.kind == TComma) {
                if (!advance()) return false;
                continue;
            }
            if (tok_.kind == TRParen) break;
            return fail(tok_.pos,
                        std::string(f->arity == 2 ? "expected ',' or ')'" : "expected ')'") +
                            " to close the '(' at position " + std::to_string(column(open)) +
                            juxtaposition_hint());
        }
    }
    if (count != f->arity)
        return fail(count > f->arity ? excess_pos : tok_.pos,
                    name + " takes " + std::to_string(f->arity) +
                        (f->arity == 1 ? " argument" : " arguments") + ", got " +
                        std::to_string(count));
    leave();
    if (!advance()) return false;
    if (f->op == OpPow)
        v = power(args[0], args[1], first_arg_mark);
    else if (f->arity == 2)
        v = binary(f->op, args[0], args[1]);
    else
        v = unary(f->op, args[0]);
    return finite_constant(v, name_pos);
}

ExprCompiler::Operand ExprCompiler::unary(uint8_t op, Operand a, int k) {
    if (a.kind == Operand::Const) return constant(apply_unary(op, k, a.value));
    if (op == OpNeg && a.kind == Operand::Reg && !code_.empty() && code_.back().op == OpNeg &&
        code_.back().dest == a.index) {
        // -(-t) = t exactly: drop the first negation.
        const Operand src = code_.back().a;
        code_.pop_back();
        if (src.kind == Operand::Reg) return a; // negated in place: the register holds t
        release(a);
        return src;
    }
    release(a);
    Instr in;
    in.op = op;
    in.k = static_cast<int8_t>(k);
    in.a = a;
    in.dest = alloc();
    code_.push_back(in);
    return reg(in.dest);
}

ExprCompiler::Operand ExprCompiler::binary(uint8_t op, Operand a, Operand b) {
    if (a.kind == Operand::Const && b.kind == Operand::Const)
        return constant(apply_binary(op, a.value, b.value));
    if ((op == OpMul || op == OpDiv) && (a.kind == Operand::Const) != (b.kind == Operand::Const)) {
        // (-t) * c = t * (-c) and (-t) / c = t / (-c), c / (-t) = (-c) / t exactly (IEEE
        // rounding is symmetric in sign): fold the negation into the constant.
        Operand& t = a.kind == Operand::Const ? b : a;
        Operand& c = a.kind == Operand::Const ? a : b;
        if (t.kind == Operand::Reg && !code_.empty() && code_.back().op == OpNeg &&
            code_.back().dest == t.index) {
            const Operand src = code_.back().a;
            code_.pop_back();
            if (src.kind != Operand::Reg) {
                release(t);
                t = src;
            }
            c.value = -c.value;
        }
    }
    Operand fused;
    if (try_fuse(op, a, b, &fused)) return fused;
    release(b);
    release(a);
    Instr in;
    in.op = op;
    in.a = a;
    in.b = b;
    in.dest = alloc();
    code_.push_back(in);
    return reg(in.dest);
}

/// Gives a constant operand a splat slot (shared by equal constants); false when there are
/// already too many (each costs kBlockSize doubles).
bool ExprCompiler::splat(Operand* o) {
    if (o->kind != Operand::Const) return true;
    constexpr size_t kMaxSplats = 64;
    for (size_t i = 0; i < splat_values_.size(); ++i)
        if (std::memcmp(&splat_values_[i], &o->value, sizeof(double)) == 0) {
            o->index = static_cast<int>(i);
            return true;
        }
    if (splat_values_.size() >= kMaxSplats) return false;
    o->index = static_cast<int>(splat_values_.size());
    splat_values_.push_back(o->value);
    return true;
}

/// When a or b is the result of the previous instruction, itself a single arithmetic
/// operation, and op is arithmetic too, replaces that instruction by a fused pair: one pass
/// over memory instead of two, same rounding (the intermediate is still a double).
bool ExprCompiler::try_fuse(uint8_t op, const Operand& a, const Operand& b, Operand* result) {
    if (!is_arithmetic(op) || code_.empty() || !is_arithmetic(code_.back().op)) return false;
    const Instr& last = code_.back();
    const bool a_last = a.kind == Operand::Reg && a.index == last.dest;
    const bool b_last = b.kind == Operand::Reg && b.index == last.dest;
    if (!a_last && !b_last) return false;
    Instr in;
    in.op = OpFused;
    in.inner = last.op;
    in.outer = op;
    in.inner_left = a_last;
    in.a = last.a;
    in.b = last.b;
    in.c = a_last ? b : a;
    const size_t splats_before = splat_values_.size();
    if (!splat(&in.a) || !splat(&in.b) || !splat(&in.c)) {
        splat_values_.resize(splats_before);
        return false;
    }
    // The previous instruction's operands are intact: nothing has been written since.
    release(b);
    release(a);
    in.dest = alloc();
    code_.back() = in;
    *result = reg(in.dest);
    return true;
}

ExprCompiler::Operand ExprCompiler::power(Operand base, Operand exponent, size_t base_mark) {
    if (exponent.kind == Operand::Const) {
        const double c = exponent.value;
        if (base.kind == Operand::Const) return constant(pow_const_exponent(base.value, c));
        if (c == 0.0) { // a^0 = 1 for every a, NaN included: drop the base's code
            code_.resize(base_mark);
            release(base);
            return constant(1.0);
        }
        if (c == 1.0) return base;
        if (is_small_int_power(c)) return unary(OpIntPow, base, static_cast<int>(c));
        if (c == 0.5) return unary(OpSqrt, base);
    }
    return binary(OpPow, base, exponent);
}

bool ExprCompiler::compile(ExprProgram& program) {
    if (text_.size() > kMaxTextLength)
        return fail(kMaxTextLength,
                    "expression is longer than " + std::to_string(kMaxTextLength) + " characters");
    if (!advance()) return false;
    if (tok_.kind == TEnd) return fail(0, "empty expression");
    Operand v;
    if (!parse_sum(v)) return false;
    if (tok_.kind == TRParen) return fail(tok_.pos, "unexpected ')'");
    if (tok_.kind != TEnd)
        return fail(tok_.pos, "expected an operator or end of input, got " + token_text(tok_) +
                                  juxtaposition_hint());
    if (v.kind != Operand::Reg) { // a constant or a variable: no code needed
        code_.clear();
        max_regs_ = 0;
        splat_values_.clear();
    }
    // By the stack discipline, a register result is register 0, written last.
    assert(v.kind != Operand::Reg || (v.index == 0 && code_.back().dest == 0));
    program.source_ = text_;
    program.dim_ = dim_;
    program.code_ = std::move(code_);
    program.num_regs_ = max_regs_;
    program.result_ = v;
    program.splats_.resize(splat_values_.size() * kBlockSize);
    for (size_t i = 0; i < splat_values_.size(); ++i)
        for (size_t j = 0; j < kBlockSize; ++j)
            program.splats_[i * kBlockSize + j] = splat_values_[i];
    return true;
}

// ---------------------------------------------------------------------------
// ExprProgram.

int ExprProgram::dimension() const {
    return dim_;
}
const std::string& ExprProgram::source() const {
    return source_;
}
size_t ExprProgram::instruction_count() const {
    return code_.size();
}

void ExprProgram::run_chunk(const double* const* vars, size_t off, size_t m, double* regs,
                            double* out) const {
    auto resolve = [&](const Operand& o) -> Arg {
        switch (o.kind) {
        case Operand::Var: return Arg{vars[o.index] + off, 0.0};
        case Operand::Reg: return Arg{regs + static_cast<size_t>(o.index) * kBlockSize, 0.0};
        default: return Arg{nullptr, o.value};
        }
    };
    const size_t last = code_.size() - 1;
    for (size_t i = 0; i <= last; ++i) {
        const Instr& in = code_[i];
        double* r = i == last ? out : regs + static_cast<size_t>(in.dest) * kBlockSize;
        if (in.op == OpFused) {
            auto array = [&](const Operand& o) {
                return o.kind == Operand::Const
                           ? splats_.data() + static_cast<size_t>(o.index) * kBlockSize
                           : resolve(o).p;
            };
            run_fused(in.inner, in.outer, in.inner_left, array(in.a), array(in.b), array(in.c), r,
                      m);
        } else if (is_binary(in.op)) {
            run_binary(in.op, resolve(in.a), resolve(in.b), r, m);
        } else {
            run_unary(in.op, in.k, resolve(in.a).p, r, m);
        }
    }
}

void ExprProgram::evaluate(const double* const* vars, size_t n, double* out) const {
    if (code_.empty()) {
        if (result_.kind == Operand::Var) {
            const double* x = vars[result_.index];
            if (x != out)
                for (size_t i = 0; i < n; ++i) out[i] = x[i];
        } else {
            for (size_t i = 0; i < n; ++i) out[i] = result_.value;
        }
        return;
    }
    thread_local std::vector<double> scratch;
    const size_t need = static_cast<size_t>(num_regs_) * kBlockSize;
    if (scratch.size() < need) scratch.resize(need);
    for (size_t off = 0; off < n; off += kBlockSize) {
        const size_t m = n - off < kBlockSize ? n - off : kBlockSize;
        run_chunk(vars, off, m, scratch.data(), out + off);
    }
}

double ExprProgram::evaluate_point(const double* x) const {
    const double* vars[kMaxDim];
    for (int j = 0; j < dim_; ++j) vars[j] = x + j;
    double out = 0.0;
    evaluate(vars, 1, &out);
    return out;
}

Made<std::shared_ptr<const ExprProgram>> compile_expression(const std::string& text, int dim,
                                                            ExprVariables variables) {
    using Result = std::shared_ptr<const ExprProgram>;
    if (dim < 1 || dim > kMaxDim)
        return made_error<Result>("expression: dimension must be in 1.." + std::to_string(kMaxDim) +
                                  ", got " + std::to_string(dim));
    ExprCompiler compiler(text, dim, variables);
    auto program = std::make_shared<ExprProgram>();
    if (!compiler.compile(*program)) return made_error<Result>(compiler.error());
    return Made<Result>{std::move(program), std::string()};
}

} // namespace mcp
