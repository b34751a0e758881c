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

static int sgn128(i128 v) { return (v > 0) - (v < 0); }

int line_make(int64_t x0, int64_t y0, int64_t x1, int64_t y1, line *out)
{
    if (y0 == y1) return 0;
    if (y1 < y0) { int64_t t = x0; x0 = x1; x1 = t; t = y0; y0 = y1; y1 = t; }
    int64_t dx = x1 - x0, dy = y1 - y0, g = gcd64(dx, dy);
    dx /= g; dy /= g;
    out->dx = dx; out->dy = dy; out->k = x0 * dy - y0 * dx;
    return 1;
}

int line_eq(const line *a, const line *b)
{
    return a->dx == b->dx && a->dy == b->dy && a->k == b->k;
}

int line_cmp(const line *a, const line *b)
{
    if (a->dx != b->dx) return a->dx < b->dx ? -1 : 1;
    if (a->dy != b->dy) return a->dy < b->dy ? -1 : 1;
    if (a->k != b->k) return a->k < b->k ? -1 : 1;
    return 0;
}

ry ry_int(int64_t v) { ry r; r.p = v; r.q = 1; return r; }

int ry_cmp(ry a, ry b) { return sgn128(a.p * b.q - b.p * a.q); }

int line_cross_y(const line *a, const line *b, ry *y)
{
    i128 den = (i128)b->dx * a->dy - (i128)a->dx * b->dy;
    if (den == 0) return 0;
    i128 num = (i128)a->k * b->dy - (i128)b->k * a->dy;
    if (den < 0) { den = -den; num = -num; }
    y->p = num; y->q = (int64_t)den;
    return 1;
}

/* numerator of x(y) = (k q + dx p) / (dy q) */
static i128 xnum(const line *a, ry y) { return (i128)a->k * y.q + (i128)a->dx * y.p; }

int x_cmp_at(const line *a, const line *b, ry y)
{
    return sgn128(xnum(a, y) * b->dy - xnum(b, y) * a->dy);
}

int x_cmp_int(const line *a, ry y, int64_t x)
{
    return sgn128(xnum(a, y) - (i128)x * a->dy * y.q);
}

static i128 floordiv(i128 n, i128 d)   /* d > 0 */
{
    i128 q = n / d;
    if ((n % d) != 0 && n < 0) q -= 1;
    return q;
}

int64_t ry_floor(ry y) { return (int64_t)floordiv(y.p, y.q); }
int64_t ry_ceil(ry y) { return (int64_t)-floordiv(-y.p, y.q); }
int64_t x_floor(const line *a, ry y) { return (int64_t)floordiv(xnum(a, y), (i128)a->dy * y.q); }
int64_t x_ceil(const line *a, ry y) { return (int64_t)-floordiv(-xnum(a, y), (i128)a->dy * y.q); }

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
