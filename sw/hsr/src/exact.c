/* exact.c - exact predicates on integer lines and rational y values.
 * Magnitude bounds (docs/hsr.md) keep every product below 2^125. */
#include "internal.h"

static int64_t gcd64(int64_t a, int64_t b)
{
    if (a < 0) a = -a;
    if (b < 0) b = -b;
    while (b) { int64_t t = a % b; a = b; b = t; }
    return a;
}

int line_make(int64_t x0, int64_t y0, int64_t x1, int64_t y1, line *out)
{
    if (y0 == y1) return 0;
    if (y1 < y0) { int64_t t = x0; x0 = x1; x1 = t; t = y0; y0 = y1; y1 = t; }
    int64_t dx = x1 - x0, dy = y1 - y0, g = gcd64(dx, dy);
    dx /= g; dy /= g;
    out->dx = dx; out->dy = dy; out->k = x0 * dy - y0 * dx;
    return 1;
}

int line_cross_y(const line *a, const line *b, ry *y)
{
    i128 den = (i128)b->dx * a->dy - (i128)a->dx * b->dy;
    if (den == 0) return 0;
    i128 num = (i128)a->k * b->dy - (i128)b->k * a->dy;
    if (den < 0) { den = -den; num = -num; }
    y->p = num; y->q = (int64_t)den;
    return 1;
}

int x_cmp_int(const line *a, ry y, int64_t x)
{
    return sgn128(xnum(a, y) - (i128)x * a->dy * y.q);
}

double ry_d(ry y)
{
    i128 ip = y.p / y.q, fp = y.p % y.q;
    return (double)ip + (double)fp / (double)y.q;
}

double x_at_d(const line *a, ry y)
{
    i128 n = xnum(a, y), d = (i128)a->dy * y.q;
    i128 ip = n / d, fp = n % d;
    return (double)ip + (double)((long double)fp / (long double)d);
}
