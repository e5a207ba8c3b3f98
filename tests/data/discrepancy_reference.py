#!/usr/bin/env python3
"""Exact squared L2 discrepancies of small point sets, for tests/test_point_analysis.cpp.

Rational arithmetic (fractions.Fraction) on the exact values of the double coordinates, by the
closed forms: L2-star by Warnock's formula [Warnock72], centred and wrap-around
[Hickernell98] (keys in docs/references.md). Independent of mcplay's code: no symmetry, no
transformed coordinates, no floating point.

    python3 tests/data/discrepancy_reference.py

prints, per set, D^2 for star, centred and wrap-around to 30 significant digits.
"""
from decimal import Decimal, getcontext
from fractions import Fraction as F

getcontext().prec = 50


def prod(values):
    r = F(1)
    for v in values:
        r *= v
    return r


def star2(points):
    n, d = len(points), len(points[0])
    t1 = F(1, 3 ** d)
    t2 = F(2, 2 ** d) / n * sum(prod(1 - x * x for x in p) for p in points)
    t3 = F(1, n * n) * sum(prod(1 - max(a, b) for a, b in zip(p, q))
                           for p in points for q in points)
    return t1 - t2 + t3


def centered2(points):
    n, d = len(points), len(points[0])
    h = F(1, 2)
    t1 = F(13, 12) ** d
    t2 = F(2, n) * sum(prod(1 + abs(x - h) / 2 - abs(x - h) ** 2 / 2 for x in p) for p in points)
    t3 = F(1, n * n) * sum(prod(1 + abs(a - h) / 2 + abs(b - h) / 2 - abs(a - b) / 2
                                for a, b in zip(p, q)) for p in points for q in points)
    return t1 - t2 + t3


def wrap2(points):
    n, d = len(points), len(points[0])
    t1 = F(4, 3) ** d
    t3 = F(1, n * n) * sum(prod(F(3, 2) - abs(a - b) * (1 - abs(a - b))
                                for a, b in zip(p, q)) for p in points for q in points)
    return -t1 + t3


def van_der_corput(i):
    r, f = F(0), F(1, 2)
    while i:
        if i & 1:
            r += f
        i >>= 1
        f /= 2
    return r


SETS = {
    "vdc8": [[van_der_corput(i)] for i in range(8)],
    "vdc16": [[van_der_corput(i)] for i in range(16)],
    "hammersley16": [[F(i, 16), van_der_corput(i)] for i in range(16)],
    "hammersley32": [[F(i, 32), van_der_corput(i)] for i in range(32)],
    # Non-dyadic doubles: F(0.1) is the exact value of the double nearest 0.1.
    "hand3d": [[F(0.1), F(0.7), F(0.35)], [F(0.9), F(0.2), F(0.55)], [F(0.5), F(0.5), F(0.95)],
               [F(0.25), F(0.999), F(0.0)]],
    "single2d": [[F(0.3), F(0.6)]],
}

if __name__ == "__main__":
    for name, pts in SETS.items():
        vals = [star2(pts), centered2(pts), wrap2(pts)]
        text = ", ".join("{:.29e}".format(Decimal(v.numerator) / Decimal(v.denominator))
                         for v in vals)
        print("{}: {}".format(name, text))
