/* separate.c - depth order of two surfaces and separate(A,B) (section
 * 5.4.1).  Where two planes cross inside the common extent the crossing
 * line is snapped to two integer points; that snapped line becomes a cut
 * and the depth order is decided once per side of it, so the decision is
 * exact, symmetric and independent of how the surfaces are fragmented. */
#include <math.h>
#include <stdlib.h>
#include "internal.h"

static double fz(hsr_plane p, hsr_plane q, double x, double y)
{
    return (p.a - q.a) * x + (p.b - q.b) * y + (p.c - q.c);
}

static int64_t clampc(double v)
{
    if (!(v > -HSR_COORD_MAX)) return -HSR_COORD_MAX;   /* also NaN */
    if (v > HSR_COORD_MAX) return HSR_COORD_MAX;
    return (int64_t)llround(v);
}

/* 1 if line L splits the corners (cx, cy) of the common extent as the crossing does (f:
 * the depth difference there, g: its gradient's length), corners within a unit of
 * either line aside. Being within a unit of both crossing points is not enough: when the
 * planes cross only in a corner of the extent, the two points are a unit apart, and any
 * line through that corner passes, also one that cuts right across the overlap. */
static int splits_like(const line *L, const double *cx, const double *cy, const double *f, double g)
{
    double len = hypot((double)L->dx, (double)L->dy);
    int sgn = 0;
    for (int i = 0; i < 4; i++) {
        double de = (cx[i] * (double)L->dy - cy[i] * (double)L->dx - (double)L->k) / len;
        if (fabs(de) <= 1 || fabs(f[i]) <= g) continue;
        int s = (de > 0) == (f[i] > 0) ? 1 : -1;
        if (sgn && s != sgn) return 0;
        sgn = s;
    }
    return 1;
}

/* canonical: p has the lower id */
/* an input edge line within 1 unit of the crossing (a shared edge) */
static int edge_near(const hsr_domain *d, const double *px, const double *py, double *best, line *bl,
                     const double *cx, const double *cy, const double *f, double g)
{
    int found = 0;
    for (int i = 0; d && i < d->n; i++) {
        const line *L = &d->e[i].ln;
        double len = hypot((double)L->dx, (double)L->dy);
        double d0 = fabs(px[0] * L->dy - py[0] * L->dx - (double)L->k) / len;
        double d1 = fabs(px[1] * L->dy - py[1] * L->dx - (double)L->k) / len;
        if (fmax(d0, d1) < *best && splits_like(L, cx, cy, f, g)) { *best = fmax(d0, d1); *bl = *L; found = 1; }
    }
    return found;
}

static void order_canon(const hsr_domain *dp, hsr_plane pp, hsr_extent ep, int idp,
                        const hsr_domain *dq, hsr_plane pq, hsr_extent eq, int idq, pair_order *o)
{
    int tie = idp < idq;
    o->has_cut = 0; o->horizontal = 0;
    o->p_front_side[0] = o->p_front_side[1] = tie;
    hsr_extent b = {ep.left > eq.left ? ep.left : eq.left, ep.bot > eq.bot ? ep.bot : eq.bot,
                    ep.right < eq.right ? ep.right : eq.right, ep.top < eq.top ? ep.top : eq.top};
    if (b.left > b.right || b.bot > b.top) return;
    double cx[4] = {(double)b.left, (double)b.right, (double)b.right, (double)b.left};
    double cy[4] = {(double)b.bot, (double)b.bot, (double)b.top, (double)b.top};
    double f[4], lo = INFINITY, hi = -INFINITY, zmag = 0;
    for (int i = 0; i < 4; i++) {
        f[i] = fz(pp, pq, cx[i], cy[i]);
        double z1 = fabs(pp.a * cx[i] + pp.b * cy[i] + pp.c), z2 = fabs(pq.a * cx[i] + pq.b * cy[i] + pq.c);
        zmag = fmax(zmag, fmax(z1, z2));
        lo = fmin(lo, f[i]); hi = fmax(hi, f[i]);
    }
    if (hi - lo <= 1e-12 * zmag && fabs(hi) <= 1e-12 * zmag) return; /* coincident */
    double fc = fz(pp, pq, (cx[0] + cx[1]) / 2, (cy[0] + cy[2]) / 2);
    if (lo >= 0 || hi <= 0) {
        int front = hi <= 0 ? (lo < 0 ? 1 : tie) : 0;
        o->p_front_side[0] = o->p_front_side[1] = front;
        return;
    }
    /* crossing line meets the box boundary in (at least) two points */
    double px[4], py[4];
    int np = 0;
    for (int i = 0; i < 4 && np < 4; i++) {
        int j = (i + 1) & 3;
        if ((f[i] <= 0) == (f[j] <= 0)) continue;
        double t = f[i] / (f[i] - f[j]);
        px[np] = cx[i] + t * (cx[j] - cx[i]); py[np] = cy[i] + t * (cy[j] - cy[i]); np++;
    }
    int front_c = fc < 0 ? 1 : (fc > 0 ? 0 : tie);
    o->p_front_side[0] = o->p_front_side[1] = front_c;
    if (np < 2) return;
    if (b.bot == b.top) return;
    int64_t x0 = clampc(px[0]), y0 = clampc(py[0]), x1 = clampc(px[1]), y1 = clampc(py[1]);
    double D = (double)(b.right - b.left) + (double)(b.top - b.bot) + 16;
    double mx = (px[0] + px[1]) / 2.0, my = (py[0] + py[1]) / 2.0, nx, ny, best = 1.0;
    double g = hypot(pp.a - pq.a, pp.b - pq.b);    /* |f| / g: distance to the crossing */
    int shared = edge_near(dp, px, py, &best, &o->cut, cx, cy, f, g);
    shared |= edge_near(dq, px, py, &best, &o->cut, cx, cy, f, g);
    if (!shared && x0 == x1 && y0 == y1) return;
    if (!shared && y0 == y1) {
        line h = {1, 0, -y0};                       /* y = y0 */
        if (!splits_like(&h, cx, cy, f, g)) return;
        o->horizontal = 1; o->hy = y0; nx = 0; ny = 1;
    }
    else {
        if (!shared && !line_make(x0, y0, x1, y1, &o->cut)) return;
        /* the snapped points of a crossing through a corner may be a unit apart: a cut
         * in any direction; then the corner (under a unit square) takes the centre's order */
        if (!shared && !splits_like(&o->cut, cx, cy, f, g)) return;
        double len = hypot((double)o->cut.dx, (double)o->cut.dy);
        nx = o->cut.dy / len; ny = -o->cut.dx / len;   /* points to the right */
    }
    double fr = fz(pp, pq, mx + D * nx, my + D * ny), fl = fz(pp, pq, mx - D * nx, my - D * ny);
    o->p_front_side[1] = fr < 0 ? 1 : (fr > 0 ? 0 : tie);
    o->p_front_side[0] = fl < 0 ? 1 : (fl > 0 ? 0 : tie);
    o->ybot = b.bot; o->ytop = b.top;
    o->has_cut = 1;
}

void pair_order_make(const hsr_domain *dp, hsr_plane pp, int idp,
                     const hsr_domain *dq, hsr_plane pq, int idq, pair_order *o)
{
    hsr_extent ep = hsr_domain_extent(dp), eq = hsr_domain_extent(dq);
    if (idp <= idq) { order_canon(dp, pp, ep, idp, dq, pq, eq, idq, o); return; }
    order_canon(dq, pq, eq, idq, dp, pp, ep, idp, o);
    o->p_front_side[0] = !o->p_front_side[0];
    o->p_front_side[1] = !o->p_front_side[1];
}

typedef struct sep_ctx { const pair_order *o; int map[4]; int saw_both; } sep_ctx;

static int classify_sep(uint64_t db, uint64_t cb, void *vctx)
{
    sep_ctx *c = vctx;
    int a = (int)(db & 1), b = (int)((db >> 1) & 1);
    if (a && !b) return c->map[0];
    if (!a && b) return c->map[1];
    if (!a) return -1;
    c->saw_both = 1;
    return c->o->p_front_side[cb & 1] ? c->map[2] : c->map[3];
}

void hsr_separation_free(hsr_separation *s)
{
    if (!s) return;
    hsr_domain_free(s->a); hsr_domain_free(s->b);
    hsr_domain_free(s->a_over_b); hsr_domain_free(s->b_over_a);
    s->a = s->b = s->a_over_b = s->b_over_a = NULL;
}

static int plane_ok(hsr_plane p) { return isfinite(p.a) && isfinite(p.b) && isfinite(p.c); }

hsr_status hsr_separate(const hsr_surface *A, const hsr_surface *B, hsr_separation *out)
{
    if (!out) return HSR_EINVAL;
    out->a = out->b = out->a_over_b = out->b_over_a = NULL;
    out->kind = HSR_SEP_DISJOINT;
    if (!A || !B || !A->dom || !B->dom || !plane_ok(A->plane) || !plane_ok(B->plane)) return HSR_EINVAL;
    pair_order o;
    pair_order_make(A->dom, A->plane, A->id, B->dom, B->plane, B->id, &o);
    /* labels: 0 = A side, 1 = B side, 2 = A n_B B, 3 = B n_A A */
    sep_ctx c = {&o, {0, 1, 0, 1}, 0};
    hsr_sep_case kind = HSR_SEP_OPAQUE;
    if (!A->opaque && B->opaque) { c.map[2] = 2; kind = HSR_SEP_A_TRANSPARENT; }
    if (A->opaque && !B->opaque) { c.map[3] = 3; kind = HSR_SEP_B_TRANSPARENT; }
    if (!A->opaque && !B->opaque) { c.map[2] = 2; c.map[3] = 3; kind = HSR_SEP_BOTH; }
    sweep_in in[3] = {{A->dom->e, A->dom->n, 0}, {B->dom->e, B->dom->n, 1}, {NULL, 0, 64}};
    edge cut;
    int nin = 2, nh = 0, hbit = 0;
    if (o.has_cut && !o.horizontal) {
        cut.ln = o.cut; cut.y0 = ry_int(o.ybot); cut.y1 = ry_int(o.ytop); cut.side = 0;
        in[2].e = &cut; in[2].n = 1; nin = 3;
    } else if (o.has_cut) nh = 1;
    hsr_domain *res[4];
    hsr_status st = sweep_overlay(in, nin, &o.hy, &hbit, nh, classify_sep, &c, 4, res);
    if (st != HSR_OK) return st;
    out->a = res[0]; out->b = res[1];
    if (!c.saw_both) kind = HSR_SEP_DISJOINT;
    if (kind == HSR_SEP_A_TRANSPARENT || kind == HSR_SEP_BOTH) out->a_over_b = res[2]; else hsr_domain_free(res[2]);
    if (kind == HSR_SEP_B_TRANSPARENT || kind == HSR_SEP_BOTH) out->b_over_a = res[3]; else hsr_domain_free(res[3]);
    out->kind = kind;
    return HSR_OK;
}
