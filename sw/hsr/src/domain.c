/* domain.c - the domain: polygon -> Sorted-Edge representation (section
 * 5.2.2: horizontal and double edges dropped, aligned edges joined,
 * crossing edges subdivided), extent, area, point-in-domain, booleans. */
#include <stdlib.h>
#include <string.h>
#include "internal.h"

const char *hsr_status_str(hsr_status s)
{
    switch (s) {
    case HSR_OK: return "ok";
    case HSR_EINVAL: return "invalid argument";
    case HSR_ERANGE: return "coordinate out of range";
    case HSR_ENOMEM: return "out of memory";
    case HSR_ELIMIT: return "size limit exceeded";
    case HSR_ENOTFOUND: return "not found";
    case HSR_EPARSE: return "parse error";
    case HSR_EIO: return "i/o error";
    }
    return "unknown status";
}

int hsr_extent_overlap(hsr_extent a, hsr_extent b)
{
    return !(a.right < b.left || a.left > b.right || a.top < b.bot || a.bot > b.top);
}

hsr_domain *dom_new(void) { return calloc(1, sizeof(hsr_domain)); }

/* sign of x dy - y dx - k of line L at the point of edge line e at height y
 * (> 0: right of L).  x = xnum / (e.dy q), so the sign is that of
 * xnum(e, y) L.dy - (p L.dx + k q) e.dy: below 2^123 (docs/hsr.md bounds). */
static int side_of(const line *L, const line *e, ry y)
{
    if (y.q == 1 && y.p >= -((i128)1 << 31) && y.p < ((i128)1 << 31)) {
        int64_t yp = (int64_t)y.p;   /* |k + dx y| < 2^48 + 2^55: int64 */
        i128 v = (i128)(e->k + e->dx * yp) * L->dy - (i128)(L->k + L->dx * yp) * e->dy;
        return sgn128(v);
    }
    return sgn128(xnum(e, y) * L->dy - ((i128)L->dx * y.p + (i128)L->k * y.q) * e->dy);
}

/* 1 if every edge end of d lies on side s of L or on L (s * side_of <= 0 fails) */
static int all_on_side(const hsr_domain *d, const line *L, int s)
{
    for (int i = 0; i < d->n; i++) {
        const edge *e = &d->e[i];
        if (s * side_of(L, &e->ln, e->y0) < 0 || s * side_of(L, &e->ln, e->y1) < 0) return 0;
    }
    return 1;
}

/* 1 if the edge lines of x hold a line with x on one closed side and y on
 * the other */
static int split_by_edge_of(const hsr_domain *x, const hsr_domain *y)
{
    for (int i = 0; i < x->n; i++) {
        const edge *e = &x->e[i];
        /* side +1: x's interior is to the right of e */
        if (all_on_side(y, &e->ln, -e->side) && all_on_side(x, &e->ln, e->side)) return 1;
    }
    return 0;
}

/* Cheap exact test that the interiors of a and b are disjoint (then an
 * overlay of the two has no part covered by both): a horizontal line or
 * an edge line of either with one domain on each closed side.  0 means
 * "not shown", not "they overlap".  Small domains only (the test is
 * quadratic in the edges). */
int dom_interiors_apart(const hsr_domain *a, const hsr_domain *b)
{
    if (!a || !b || !a->n || !b->n) return 1;
    if (a->n + b->n > 24) return 0;
    ry alo = a->e[0].y0, ahi = a->e[0].y1, blo = b->e[0].y0, bhi = b->e[0].y1;
    for (int i = 1; i < a->n; i++) {
        if (ry_cmp(a->e[i].y0, alo) < 0) alo = a->e[i].y0;
        if (ry_cmp(a->e[i].y1, ahi) > 0) ahi = a->e[i].y1;
    }
    for (int i = 1; i < b->n; i++) {
        if (ry_cmp(b->e[i].y0, blo) < 0) blo = b->e[i].y0;
        if (ry_cmp(b->e[i].y1, bhi) > 0) bhi = b->e[i].y1;
    }
    if (ry_cmp(ahi, blo) <= 0 || ry_cmp(bhi, alo) <= 0) return 1;
    return split_by_edge_of(a, b) || split_by_edge_of(b, a);
}

int dom_push(hsr_domain *d, const edge *e)
{
    if (d->n == d->cap) {
        int c = d->cap ? d->cap * 2 : 8;
        edge *q = realloc(d->e, sizeof(edge) * (size_t)c);
        if (!q) return 0;
        d->e = q; d->cap = c;
    }
    d->e[d->n++] = *e;
    return 1;
}

void dom_finish_extent(hsr_domain *d)
{
    hsr_extent x = {1, 1, 0, 0};
    for (int i = 0; i < d->n; i++) {
        const edge *e = &d->e[i];
        int64_t l0, l1, r0, r1;
        x_floor_ceil(&e->ln, e->y0, &l0, &r0);
        x_floor_ceil(&e->ln, e->y1, &l1, &r1);
        int64_t l = l0 < l1 ? l0 : l1, r = r0 > r1 ? r0 : r1;
        int64_t b = ry_floor(e->y0), t = ry_ceil(e->y1);
        if (i == 0) { x.left = l; x.right = r; x.bot = b; x.top = t; continue; }
        if (l < x.left) x.left = l;
        if (r > x.right) x.right = r;
        if (b < x.bot) x.bot = b;
        if (t > x.top) x.top = t;
    }
    d->ext = x;
}

void hsr_domain_free(hsr_domain *d)
{
    if (!d) return;
    free(d->e);
    free(d);
}

hsr_domain *hsr_domain_clone(const hsr_domain *d)
{
    if (!d) return NULL;
    hsr_domain *c = dom_new();
    if (!c) return NULL;
    *c = *d;
    c->e = NULL; c->cap = 0; c->n = 0;
    for (int i = 0; i < d->n; i++)
        if (!dom_push(c, &d->e[i])) { hsr_domain_free(c); return NULL; }
    return c;
}

int hsr_domain_is_empty(const hsr_domain *d) { return !d || d->n == 0; }
int hsr_domain_edge_count(const hsr_domain *d) { return d ? d->n : 0; }

hsr_extent hsr_domain_extent(const hsr_domain *d)
{
    hsr_extent none = {1, 1, 0, 0};
    return (d && d->n) ? d->ext : none;
}

double hsr_domain_area(const hsr_domain *d)
{
    if (!d || !d->n) return 0.0;
    long double a = 0, xref = (long double)d->ext.left;
    for (int i = 0; i < d->n; i++) {
        const edge *e = &d->e[i];
        long double h = (long double)ry_d(e->y1) - (long double)ry_d(e->y0);
        long double xs = (long double)x_at_d(&e->ln, e->y0) + (long double)x_at_d(&e->ln, e->y1) - 2 * xref;
        a += -e->side * h * xs / 2;
    }
    return (double)a;
}

int hsr_domain_contains(const hsr_domain *d, int64_t x, int64_t y)
{
    if (!d || !d->n || x < d->ext.left || x > d->ext.right || y < d->ext.bot || y > d->ext.top)
        return 0;
    ry yy = ry_int(y);
    int c = 0;
    for (int i = 0; i < d->n; i++) {
        const edge *e = &d->e[i];
        if (ry_cmp(e->y0, yy) <= 0 && ry_cmp(yy, e->y1) < 0 && x_cmp_int(&e->ln, yy, x) <= 0) c ^= 1;
    }
    return c;
}

hsr_status hsr_domain_edge(const hsr_domain *d, int i, double seg[4])
{
    if (!d || !seg || i < 0 || i >= d->n) return HSR_EINVAL;
    const edge *e = &d->e[i];
    seg[0] = x_at_d(&e->ln, e->y0); seg[1] = ry_d(e->y0);
    seg[2] = x_at_d(&e->ln, e->y1); seg[3] = ry_d(e->y1);
    return HSR_OK;
}

static int classify_one(uint64_t db, uint64_t cb, void *ctx)
{
    (void)cb; (void)ctx;
    return (db & 1) ? 0 : -1;
}

hsr_status hsr_domain_from_rings(const int64_t *xy, const int *ring_len,
                                 int nrings, hsr_domain **out)
{
    if (!out) return HSR_EINVAL;
    *out = NULL;
    if (nrings < 0 || (nrings > 0 && (!xy || !ring_len))) return HSR_EINVAL;
    long total = 0;
    for (int r = 0; r < nrings; r++) {
        if (ring_len[r] < 0) return HSR_EINVAL;
        total += ring_len[r];
        if (total > HSR_MAX_RING_POINTS) return HSR_ELIMIT;
    }
    for (long i = 0; i < 2 * total; i++)
        if (xy[i] < -HSR_COORD_MAX || xy[i] > HSR_COORD_MAX) return HSR_ERANGE;
    edge *raw = malloc(sizeof(edge) * (size_t)(total ? total : 1));
    if (!raw) return HSR_ENOMEM;
    int n = 0;
    long base = 0;
    for (int r = 0; r < nrings; r++) {
        int m = ring_len[r];
        for (int i = 0; i < m && m >= 3; i++) {
            const int64_t *a = &xy[2 * (base + i)], *b = &xy[2 * (base + (i + 1) % m)];
            edge e;
            if (!line_make(a[0], a[1], b[0], b[1], &e.ln)) continue;
            int64_t y0 = a[1] < b[1] ? a[1] : b[1], y1 = a[1] < b[1] ? b[1] : a[1];
            e.y0 = ry_int(y0); e.y1 = ry_int(y1); e.side = 0;
            raw[n++] = e;
        }
        base += m;
    }
    sweep_in in = {raw, n, 0};
    hsr_status st = sweep_overlay(&in, 1, NULL, NULL, 0, classify_one, NULL, 1, out);
    free(raw);
    return st;
}

static int classify_bool(uint64_t db, uint64_t cb, void *ctx)
{
    (void)cb;
    int a = (int)(db & 1), b = (int)((db >> 1) & 1), r = 0;
    switch (*(const hsr_boolop *)ctx) {
    case HSR_UNION: r = a | b; break;
    case HSR_INTERSECT: r = a & b; break;
    case HSR_SUBTRACT: r = a & !b; break;
    case HSR_XOR: r = a ^ b; break;
    }
    return r ? 0 : -1;
}

hsr_status hsr_domain_boolean(const hsr_domain *a, const hsr_domain *b,
                              hsr_boolop op, hsr_domain **out)
{
    if (!a || !b || !out || op < HSR_UNION || op > HSR_XOR) return HSR_EINVAL;
    sweep_in in[2] = {{a->e, a->n, 0}, {b->e, b->n, 1}};
    return sweep_overlay(in, 2, NULL, NULL, 0, classify_bool, &op, 1, out);
}
