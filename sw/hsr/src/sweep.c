/* sweep.c - exact slab sweep overlaying several edge sets (section 5.2.2
 * conversion and all binary operations).  Events are edge endpoints and
 * edge crossings; between two events no edges cross, so each slab is a
 * row of trapezoids whose label comes from the sources covering it.
 * Output edges are boundaries between differently labelled trapezoids;
 * collinear pieces are joined and the result is put in Sorted-Edge order.
 *
 * Speed (docs/performance.md, y-processor section): a mesh of 70K
 * triangles makes ~600K overlays of a few edges each, so the per-call
 * overhead matters.  The working arrays are kept between calls (grown,
 * never shrunk; single-threaded use, as the qsort context already was),
 * the sorts are a stable merge sort (the same order glibc's qsort, a
 * stable merge sort, gave, so results are unchanged) and the output
 * domains are assembled apart from the sweep, only those the caller will
 * use (sweep_overlay_pieces, then sweep_assemble). */
#include <stdlib.h>
#include <string.h>
#include "internal.h"

typedef struct sedge { const edge *e; int src; int64_t xmin, xmax; } sedge;
typedef struct piece { line ln; ry y0, y1; int side, label, prev, merged; } piece;

/* scratch: grown on demand, kept between calls */
static struct scratch {
    sedge *E; size_t nE, capE;
    ry *Y; size_t nY, capY;
    piece *P; size_t nP, capP;
    void *tmp; size_t captmp;               /* merge sort buffer (bytes) */
    int *act; size_t capact;
    int *lab; size_t caplab;                /* lastpiece, start, fill: 3 * (nlabels + 1) */
    int *idx; size_t capidx;                /* assemble: idx, indeg, adj_head, adj_next, adj_to, queue */
    edge *ed; size_t caped;
    int64_t *K; size_t capK;                /* integer slab boundaries */
    int nlab;                               /* labels of the pieces in P */
} S;

static int grow(void **p, size_t *cap, size_t need, size_t sz)
{
    if (need <= *cap) return 1;
    size_t c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, c * sz);
    if (!q) return 0;
    *p = q; *cap = c;
    return 1;
}
#define GROW(arr, cap, need) grow((void **)&(arr), &(cap), (need), sizeof *(arr))

/* Stable merge sort of n elements of type T (insertion sort below 16). */
#define DEFINE_STABLE_SORT(name, T, LESS_EQ)                                          \
    static void name##_rec(T *a, T *t, size_t n)                                      \
    {                                                                                 \
        if (n <= 16) {                                                                \
            for (size_t i = 1; i < n; i++) {                                          \
                T v = a[i]; size_t j = i;                                             \
                while (j > 0 && !(LESS_EQ(&a[j - 1], &v))) { a[j] = a[j - 1]; j--; }  \
                a[j] = v;                                                             \
            }                                                                         \
            return;                                                                   \
        }                                                                             \
        size_t h = n / 2;                                                             \
        name##_rec(a, t, h); name##_rec(a + h, t, n - h);                             \
        if (LESS_EQ(&a[h - 1], &a[h])) return;                                        \
        memcpy(t, a, h * sizeof(T));                                                  \
        size_t i = 0, j = h, k = 0;                                                   \
        while (i < h && j < n) a[k++] = LESS_EQ(&t[i], &a[j]) ? t[i++] : a[j++];      \
        while (i < h) a[k++] = t[i++];                                                \
    }                                                                                 \
    static int name(T *a, size_t n)                                                   \
    {                                                                                 \
        if (n < 2) return 1;                                                          \
        if (!grow(&S.tmp, &S.captmp, (n / 2 + 1) * sizeof(T), 1)) return 0;           \
        name##_rec(a, S.tmp, n);                                                      \
        return 1;                                                                     \
    }

#define RY_LE(a, b) (ry_cmp(*(a), *(b)) <= 0)
#define SEDGE_LE(a, b) (ry_cmp((a)->e->y0, (b)->e->y0) <= 0)
DEFINE_STABLE_SORT(sort_ry, ry, RY_LE)
DEFINE_STABLE_SORT(sort_sedge, sedge, SEDGE_LE)
#define I64_LE(a, b) (*(a) <= *(b))
DEFINE_STABLE_SORT(sort_i64, int64_t, I64_LE)

/* The slab boundaries: usually all integers (q = 1; then equal values are
 * equal (p, q) too, so sorting the 64-bit numerators gives the very array
 * the general sort gives), else the stable sort on exact comparisons. */
static int sort_ys(ry *a, size_t n)
{
    if (!GROW(S.K, S.capK, n + 1)) return 0;
    for (size_t i = 0; i < n; i++) {
        if (a[i].q != 1 || a[i].p < INT64_MIN || a[i].p > INT64_MAX) return sort_ry(a, n);
        S.K[i] = (int64_t)a[i].p;
    }
    if (!sort_i64(S.K, n)) return 0;
    for (size_t i = 0; i < n; i++) a[i].p = S.K[i];
    return 1;
}

static const piece *g_pieces; /* sort context (single-threaded use) */
static int cmp_piece(const piece *p, const piece *q)
{
    int c = line_cmp(&p->ln, &q->ln);
    if (c) return c;
    if (p->side != q->side) return p->side - q->side;
    return ry_cmp(p->y0, q->y0);
}
#define PIECE_LE(a, b) (cmp_piece(&g_pieces[*(a)], &g_pieces[*(b)]) <= 0)
DEFINE_STABLE_SORT(sort_piece_idx, int, PIECE_LE)

static int slab_cmp(const sedge *a, const sedge *b, ry lo, ry hi)
{
    int c = x_cmp_at(&a->e->ln, &b->e->ln, lo);
    return c ? c : x_cmp_at(&a->e->ln, &b->e->ln, hi);
}

/* Build out[label] from the pieces: join, then topological x-order. */
static hsr_status assemble(piece *pc, int np, int nlabels, const unsigned char *need, hsr_domain **out)
{
    size_t m0 = (size_t)(np ? np : 1);
    if (!GROW(S.lab, S.caplab, 3 * ((size_t)nlabels + 1)) || !GROW(S.idx, S.capidx, 6 * m0)
        || !GROW(S.ed, S.caped, m0))
        return HSR_ENOMEM;
    int *idx = S.idx, *start = S.lab, *fill = S.lab + nlabels + 1;
    int *indeg = S.idx + m0, *adj_head = indeg + m0, *adj_next = adj_head + m0, *adj_to = adj_next + m0,
        *queue = adj_to + m0;
    edge *ed = S.ed;
    memset(start, 0, sizeof(int) * ((size_t)nlabels + 1));
    memset(fill, 0, sizeof(int) * (size_t)nlabels);
    for (int i = 0; i < np; i++) start[pc[i].label + 1]++;
    for (int l = 0; l < nlabels; l++) start[l + 1] += start[l];
    for (int i = 0; i < np; i++) idx[start[pc[i].label] + fill[pc[i].label]++] = i;
    g_pieces = pc;
    for (int l = 0; l < nlabels; l++) {
        int *ix = idx + start[l], m = start[l + 1] - start[l], ne = 0;
        if (m == 0 || (need && !need[l])) continue;
        if (!sort_piece_idx(ix, (size_t)m)) return HSR_ENOMEM;
        for (int i = 0; i < m; i++) {
            piece *p = &pc[ix[i]];
            if (ne > 0 && line_eq(&ed[ne - 1].ln, &p->ln) && ed[ne - 1].side == p->side
                && ry_cmp(ed[ne - 1].y1, p->y0) == 0) {
                ed[ne - 1].y1 = p->y1;
            } else {
                ed[ne].ln = p->ln; ed[ne].y0 = p->y0; ed[ne].y1 = p->y1; ed[ne].side = p->side;
                ne++;
            }
            p->merged = ne - 1;
        }
        for (int i = 0; i < ne; i++) { adj_head[i] = -1; indeg[i] = 0; }
        int na = 0;
        for (int i = 0; i < m; i++) {
            piece *p = &pc[ix[i]];
            if (p->prev < 0) continue;
            int u = pc[p->prev].merged, v = p->merged;
            if (u == v) continue;
            adj_to[na] = v; adj_next[na] = adj_head[u]; adj_head[u] = na++;
            indeg[v]++;
        }
        hsr_domain *d = out[l];
        if (d->cap < ne) {   /* the exact size at once (dom_push would double) */
            edge *q = realloc(d->e, sizeof(edge) * (size_t)ne);
            if (!q) return HSR_ENOMEM;
            d->e = q; d->cap = ne;
        }
        int qh = 0, qt = 0;
        for (int i = 0; i < ne; i++) if (!indeg[i]) queue[qt++] = i;
        while (qh < qt) {
            int u = queue[qh++];
            d->e[d->n++] = ed[u];
            for (int a = adj_head[u]; a >= 0; a = adj_next[a])
                if (--indeg[adj_to[a]] == 0) queue[qt++] = adj_to[a];
        }
        /* a cycle would mean crossing edges (cannot happen); keep all edges */
        for (int i = 0; i < ne; i++) if (indeg[i] > 0) d->e[d->n++] = ed[i];
        dom_finish_extent(d);
    }
    return HSR_OK;
}

#define PUSH(arr, n, cap, val) \
    do { if (!GROW(arr, cap, (n) + 1)) goto fail; (arr)[(n)++] = (val); } while (0)

hsr_status sweep_overlay_pieces(const sweep_in *in, int nin, const int64_t *hcut_y,
                                const int *hcut_bit, int nhcut, sweep_classify fn,
                                void *ctx, int nlabels, int *count)
{
    S.nE = S.nY = S.nP = 0; S.nlab = 0;
    for (int i = 0; i < nin; i++)
        for (int j = 0; j < in[i].n; j++) {
            const edge *e = &in[i].e[j];
            sedge s = {e, in[i].src, 0, 0};
            int64_t a, b, ca, cb;
            x_floor_ceil(&e->ln, e->y0, &a, &ca);
            x_floor_ceil(&e->ln, e->y1, &b, &cb);
            s.xmin = (a < b ? a : b) - 1;
            s.xmax = (ca > cb ? ca : cb) + 1;
            PUSH(S.E, S.nE, S.capE, s);
            PUSH(S.Y, S.nY, S.capY, e->y0);
            PUSH(S.Y, S.nY, S.capY, e->y1);
        }
    for (int i = 0; i < nhcut; i++) PUSH(S.Y, S.nY, S.capY, ry_int(hcut_y[i]));
    sedge *es = S.E;
    int n = (int)S.nE;
    if (!sort_sedge(es, (size_t)n)) goto fail;
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n && ry_cmp(es[j].e->y0, es[i].e->y1) < 0; j++) {
            if (es[j].xmin > es[i].xmax || es[j].xmax < es[i].xmin) continue;
            ry y;
            if (!line_cross_y(&es[i].e->ln, &es[j].e->ln, &y)) continue;
            if (ry_cmp(y, es[j].e->y0) <= 0 || ry_cmp(y, es[i].e->y1) >= 0
                || ry_cmp(y, es[j].e->y1) >= 0) continue;
            PUSH(S.Y, S.nY, S.capY, y);
        }
    if (!sort_ys(S.Y, S.nY)) goto fail;
    ry *ys = S.Y;
    int ny = 0;
    for (size_t i = 0; i < S.nY; i++) if (ny == 0 || ry_cmp(ys[ny - 1], ys[i]) != 0) ys[ny++] = ys[i];
    if (!GROW(S.act, S.capact, (size_t)n + 1) || !GROW(S.lab, S.caplab, 3 * ((size_t)nlabels + 1))) goto fail;
    int *act = S.act, *lastpiece = S.lab;
    int na = 0, next = 0;
    for (int s = 0; s + 1 < ny; s++) {
        ry lo = ys[s], hi = ys[s + 1];
        int w = 0;
        for (int i = 0; i < na; i++) if (ry_cmp(es[act[i]].e->y1, lo) > 0) act[w++] = act[i];
        na = w;
        while (next < n && ry_cmp(es[next].e->y0, lo) <= 0) {
            if (ry_cmp(es[next].e->y1, lo) > 0) act[na++] = next;
            next++;
        }
        for (int i = 1; i < na; i++) {   /* insertion sort: nearly sorted */
            int v = act[i], j = i - 1;
            while (j >= 0 && slab_cmp(&es[act[j]], &es[v], lo, hi) > 0) { act[j + 1] = act[j]; j--; }
            act[j + 1] = v;
        }
        uint64_t db = 0, cb = 0;
        for (int h = 0; h < nhcut; h++)
            if (ry_cmp(lo, ry_int(hcut_y[h])) >= 0) cb |= (uint64_t)1 << hcut_bit[h];
        int cur = fn(db, cb, ctx);
        for (int l = 0; l < nlabels; l++) lastpiece[l] = -1;
        for (int i = 0; i < na;) {
            int j = i;
            while (j < na && (j == i || slab_cmp(&es[act[i]], &es[act[j]], lo, hi) == 0)) {
                int src = es[act[j]].src;
                if (src < 64) db ^= (uint64_t)1 << src; else cb ^= (uint64_t)1 << (src - 64);
                j++;
            }
            int nxt = fn(db, cb, ctx);
            if (nxt != cur) {
                int labs[2] = {cur, nxt}, sides[2] = {-1, +1};
                for (int t = 0; t < 2; t++) {
                    if (labs[t] < 0 || labs[t] >= nlabels) continue;
                    piece p = {es[act[i]].e->ln, lo, hi, sides[t], labs[t], lastpiece[labs[t]], -1};
                    PUSH(S.P, S.nP, S.capP, p);
                    lastpiece[labs[t]] = (int)S.nP - 1;
                }
            }
            cur = nxt;
            i = j;
        }
    }
    for (int l = 0; l < nlabels; l++) count[l] = 0;
    for (size_t i = 0; i < S.nP; i++) count[S.P[i].label]++;
    S.nlab = nlabels;
    return HSR_OK;
fail:
    return HSR_ENOMEM;
}

hsr_status sweep_assemble(int nlabels, const unsigned char *need, hsr_domain **out)
{
    hsr_status st = HSR_ENOMEM;
    for (int l = 0; l < nlabels; l++) out[l] = NULL;
    if (nlabels != S.nlab) return HSR_EINVAL;
    for (int l = 0; l < nlabels; l++) if ((!need || need[l]) && !(out[l] = dom_new())) goto fail;
    st = assemble(S.P, (int)S.nP, nlabels, need, out);
    if (st != HSR_OK) goto fail;
    return HSR_OK;
fail:
    for (int l = 0; l < nlabels; l++) { hsr_domain_free(out[l]); out[l] = NULL; }
    return st == HSR_OK ? HSR_ENOMEM : st;
}

hsr_status sweep_overlay(const sweep_in *in, int nin, const int64_t *hcut_y,
                         const int *hcut_bit, int nhcut, sweep_classify fn,
                         void *ctx, int nlabels, hsr_domain **out)
{
    int count[64 + 3];
    for (int l = 0; l < nlabels; l++) out[l] = NULL;
    if (nlabels < 1 || nlabels > (int)(sizeof count / sizeof *count)) return HSR_EINVAL;
    hsr_status st = sweep_overlay_pieces(in, nin, hcut_y, hcut_bit, nhcut, fn, ctx, nlabels, count);
    return st != HSR_OK ? st : sweep_assemble(nlabels, NULL, out);
}
