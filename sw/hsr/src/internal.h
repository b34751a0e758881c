/* internal.h - private types shared by the sw/hsr sources. */
#ifndef HSR_INTERNAL_H
#define HSR_INTERNAL_H

#include "hsr.h"

typedef __int128 i128;

/* Line x*dy - y*dx = k, dy > 0, gcd(dx,dy) == 1 (canonical, so equal
 * lines compare equal).  |dx|,|dy| <= 2^24, |k| <= 2^48. */
typedef struct line { int64_t dx, dy, k; } line;

/* Rational y = p/q, q > 0; |p| <= 2^73, q <= 2^49 (see docs/hsr.md). */
typedef struct ry { i128 p; int64_t q; } ry;

/* Edge of a domain: the part of `ln` with y0 <= y <= y1 (y0 < y1).
 * side = +1: interior to the right (a left boundary), -1: to the left. */
typedef struct edge { line ln; ry y0, y1; int side; } edge;

struct hsr_domain {
    int n, cap;
    edge *e;       /* Sorted-Edge order */
    hsr_extent ext;
};

/* exact.c */
int line_make(int64_t x0, int64_t y0, int64_t x1, int64_t y1, line *out);
int line_cross_y(const line *a, const line *b, ry *y); /* 0 if parallel */
int x_cmp_int(const line *a, ry y, int64_t x);      /* sign(xa(y)-x) */
double ry_d(ry y);
double x_at_d(const line *a, ry y);

/* The hot predicates are inline (they are most of the overlay's time).
 * Each fast path is exact: it is taken only where it gives the same
 * integer result as the general 128-bit expression. */
static inline int sgn128(i128 v) { return (v > 0) - (v < 0); }

static inline int line_eq(const line *a, const line *b)
{
    return a->dx == b->dx && a->dy == b->dy && a->k == b->k;
}

static inline int line_cmp(const line *a, const line *b)   /* total order */
{
    if (a->dx != b->dx) return a->dx < b->dx ? -1 : 1;
    if (a->dy != b->dy) return a->dy < b->dy ? -1 : 1;
    if (a->k != b->k) return a->k < b->k ? -1 : 1;
    return 0;
}

static inline ry ry_int(int64_t v) { ry r; r.p = v; r.q = 1; return r; }

/* sign(a - b); equal denominators (q > 0): compare the numerators */
static inline int ry_cmp(ry a, ry b)
{
    if (a.q == b.q) return (a.p > b.p) - (a.p < b.p);
    return sgn128(a.p * b.q - b.p * a.q);
}

/* numerator of x(y) = (k q + dx p) / (dy q) */
static inline i128 xnum(const line *a, ry y) { return (i128)a->k * y.q + (i128)a->dx * y.p; }

/* sign(xa(y) - xb(y)); equal dy (> 0): compare the numerators */
static inline int x_cmp_at(const line *a, const line *b, ry y)
{
    if (a->dy == b->dy) return sgn128(xnum(a, y) - xnum(b, y));
    return sgn128(xnum(a, y) * b->dy - xnum(b, y) * a->dy);
}

/* floor(n / d), d > 0; 64-bit division where both fit (same result) */
static inline i128 floordiv128(i128 n, i128 d)
{
    if (n >= INT64_MIN && n <= INT64_MAX && d <= INT64_MAX) {
        int64_t n6 = (int64_t)n, d6 = (int64_t)d, q = n6 / d6;
        if (n6 % d6 != 0 && n6 < 0) q -= 1;
        return q;
    }
    i128 q = n / d;
    if ((n % d) != 0 && n < 0) q -= 1;
    return q;
}

static inline int64_t ry_floor(ry y) { return (int64_t)floordiv128(y.p, y.q); }
static inline int64_t ry_ceil(ry y) { return (int64_t)-floordiv128(-y.p, y.q); }
static inline int64_t x_floor(const line *a, ry y) { return (int64_t)floordiv128(xnum(a, y), (i128)a->dy * y.q); }
static inline int64_t x_ceil(const line *a, ry y) { return (int64_t)-floordiv128(-xnum(a, y), (i128)a->dy * y.q); }
/* x_floor and x_ceil of the same point from one division: with the quotient
 * q0 truncated toward zero and remainder r, floor = q0 - (r != 0 && n < 0) and
 * ceil = q0 + (r != 0 && n > 0), the values the two calls give. */
static inline void x_floor_ceil(const line *a, ry y, int64_t *fl, int64_t *ce)
{
    i128 n = xnum(a, y), d = (i128)a->dy * y.q;
    if (n >= INT64_MIN && n <= INT64_MAX && d <= INT64_MAX) {
        int64_t n6 = (int64_t)n, d6 = (int64_t)d, q0 = n6 / d6, r = n6 % d6;
        *fl = q0 - (r != 0 && n6 < 0);
        *ce = q0 + (r != 0 && n6 > 0);
        return;
    }
    i128 q0 = n / d, r = n % d;
    *fl = (int64_t)(q0 - (r != 0 && n < 0));
    *ce = (int64_t)(q0 + (r != 0 && n > 0));
}

/* domain.c */
hsr_domain *dom_new(void);
int dom_push(hsr_domain *d, const edge *e);
void dom_finish_extent(hsr_domain *d);
int dom_interiors_apart(const hsr_domain *a, const hsr_domain *b);   /* 1: shown disjoint */

/* sweep.c - overlay of up to 64 sources (even-odd each) and 64 cut lines.
 * classify(dom_bits, cut_bits, ctx) -> label in [0,nlabels) or -1.
 * Cut lines split areas but do not change coverage; a horizontal cut
 * (src >= 64 + 64) is given by hcut_y.  Output domains out[0..nlabels-1]
 * are created (possibly empty). */
typedef struct sweep_in {
    const edge *e; int n; int src;   /* src < 64: domain bit, else cut bit */
} sweep_in;
typedef int (*sweep_classify)(uint64_t dom_bits, uint64_t cut_bits, void *ctx);
hsr_status sweep_overlay(const sweep_in *in, int nin, const int64_t *hcut_y,
                         const int *hcut_bit, int nhcut, sweep_classify fn,
                         void *ctx, int nlabels, hsr_domain **out);
/* The same in two steps.  sweep_overlay_pieces runs the sweep and leaves
 * its output pieces in the sweep's scratch (until the next call); count[l]
 * receives label l's number of pieces (0 exactly when out[l] would be
 * empty).  sweep_assemble then builds out[l] for the labels with need[l]
 * (all if need is NULL), the same domains sweep_overlay gives; the others
 * are NULL.  Assembling only what the caller uses saves most of the work. */
hsr_status sweep_overlay_pieces(const sweep_in *in, int nin, const int64_t *hcut_y,
                                const int *hcut_bit, int nhcut, sweep_classify fn,
                                void *ctx, int nlabels, int *count);
hsr_status sweep_assemble(int nlabels, const unsigned char *need, hsr_domain **out);

/* separate.c: depth order of surface p vs q, with the optional cut line */
typedef struct pair_order {
    int has_cut, horizontal;  /* horizontal: cut is y = hy */
    line cut; int64_t hy, ybot, ytop;
    int p_front_side[2];      /* [side] -> 1 if p is in front; side 1 = right/above */
} pair_order;
void pair_order_make(const hsr_domain *dp, hsr_plane pp, int idp,
                     const hsr_domain *dq, hsr_plane pq, int idq, pair_order *o);

/* obj.c helpers shared with scene.c and mtl.c */
int scene_grow(void **p, int *cap, int need, size_t sz);
int scene_tokens(char *line, char **tok, int max);
/* The readers' error message: err = "name:lineno: " and the formatted text (when err is
 * not NULL); returns st. */
hsr_status hsr_text_error(char *err, size_t errlen, const char *name, int lineno,
                          hsr_status st, const char *fmt, ...)
    __attribute__((format(printf, 6, 7)));
/* The readers' line loop: the next line of *p with tokens (blank and comment lines are
 * skipped; *lineno counts every line) into buf/tok, at most max tokens. Returns the number
 * of tokens, 0 at the end of the text, or -1 for a line too long or with too many items
 * (the message in err, as hsr_text_error). */
int hsr_text_next(const char **p, int *lineno, char *buf, size_t cap, char **tok, int max,
                  const char *name, char *err, size_t errlen);

/* mtl.c: read the .mtl file at path and append its materials (newmtl, Kd,
 * Ks, Ns, d, Tr) to sc->mat with file = its index in sc->files + 1.
 * Errors: "path:line: message"; a file that cannot be read is reported as
 * "where: cannot read MTL file 'path' (...)" (where: the OBJ's file:line). */
hsr_status scene_mtl_load(hsr_scene *sc, const char *path, const char *where,
                          char *err, size_t errlen);

/* poly.c: triangulation of an OBJ polygon p (3 doubles per point, n >= 3):
 * fan (0, i, i+1) if it is convex in the plane of its Newell normal, else
 * ear clipping (docs/hsr.md gives the exact rule, shared with the reference
 * renderer).  tri receives 3 * (n - 2) indices into p; returns the number
 * of triangles (n - 2).  *whole = 1 if the polygon is convex and planar to
 * 1e-6 of its size, so that one face with that fan is the same surface. */
int poly_triangulate(const double *p, int n, int *tri, int *whole);

#endif
