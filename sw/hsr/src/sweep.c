/* sweep.c - exact slab sweep overlaying several edge sets (section 5.2.2
 * conversion and all binary operations).  Events are edge endpoints and
 * edge crossings; between two events no edges cross, so each slab is a
 * row of trapezoids whose label comes from the sources covering it.
 * Output edges are boundaries between differently labelled trapezoids;
 * collinear pieces are joined and the result is put in Sorted-Edge order. */
#include <stdlib.h>
#include <string.h>
#include "internal.h"

typedef struct sedge { const edge *e; int src; int64_t xmin, xmax; } sedge;
typedef struct piece { line ln; ry y0, y1; int side, label, prev, merged; } piece;

typedef struct vec { void *p; size_t n, cap, sz; } vec;
static int vpush(vec *v, const void *x)
{
    if (v->n == v->cap) {
        size_t c = v->cap ? v->cap * 2 : 64;
        void *q = realloc(v->p, c * v->sz);
        if (!q) return 0;
        v->p = q; v->cap = c;
    }
    memcpy((char *)v->p + v->n * v->sz, x, v->sz);
    v->n++;
    return 1;
}

static int cmp_ry(const void *a, const void *b) { return ry_cmp(*(const ry *)a, *(const ry *)b); }
static int cmp_sedge_y0(const void *a, const void *b)
{
    return ry_cmp(((const sedge *)a)->e->y0, ((const sedge *)b)->e->y0);
}

static const piece *g_pieces; /* qsort context (single-threaded use) */
static int cmp_piece_idx(const void *a, const void *b)
{
    const piece *p = &g_pieces[*(const int *)a], *q = &g_pieces[*(const int *)b];
    int c = line_cmp(&p->ln, &q->ln);
    if (c) return c;
    if (p->side != q->side) return p->side - q->side;
    return ry_cmp(p->y0, q->y0);
}

static int slab_cmp(const sedge *a, const sedge *b, ry lo, ry hi)
{
    int c = x_cmp_at(&a->e->ln, &b->e->ln, lo);
    return c ? c : x_cmp_at(&a->e->ln, &b->e->ln, hi);
}

/* Build out[label] from the pieces: join, then topological x-order. */
static hsr_status assemble(piece *pc, int np, int nlabels, hsr_domain **out)
{
    hsr_status st = HSR_ENOMEM;
    int *idx = malloc(sizeof(int) * (size_t)(np ? np : 1));
    int *start = calloc((size_t)nlabels + 1, sizeof(int));
    if (!idx || !start) goto done;
    for (int i = 0; i < np; i++) start[pc[i].label + 1]++;
    for (int l = 0; l < nlabels; l++) start[l + 1] += start[l];
    {
        int *fill = calloc((size_t)nlabels, sizeof(int));
        if (!fill) goto done;
        for (int i = 0; i < np; i++) idx[start[pc[i].label] + fill[pc[i].label]++] = i;
        free(fill);
    }
    g_pieces = pc;
    for (int l = 0; l < nlabels; l++) {
        int *ix = idx + start[l], m = start[l + 1] - start[l];
        if (m == 0) continue;
        if (m > 1) qsort(ix, (size_t)m, sizeof(int), cmp_piece_idx);
        edge *ed = malloc(sizeof(edge) * (size_t)m);
        int *indeg = calloc((size_t)m, sizeof(int)), ne = 0;
        int *adj_head = malloc(sizeof(int) * (size_t)m);
        int *adj_next = malloc(sizeof(int) * (size_t)m), *adj_to = malloc(sizeof(int) * (size_t)m);
        int *queue = malloc(sizeof(int) * (size_t)m);
        if (!ed || !indeg || !adj_head || !adj_next || !adj_to || !queue) {
            free(ed); free(indeg); free(adj_head); free(adj_next); free(adj_to); free(queue);
            goto done;
        }
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
        for (int i = 0; i < ne; i++) adj_head[i] = -1;
        int na = 0;
        for (int i = 0; i < m; i++) {
            piece *p = &pc[ix[i]];
            if (p->prev < 0) continue;
            int u = pc[p->prev].merged, v = p->merged;
            if (u == v) continue;
            adj_to[na] = v; adj_next[na] = adj_head[u]; adj_head[u] = na++;
            indeg[v]++;
        }
        int qh = 0, qt = 0, ok = 1;
        for (int i = 0; i < ne; i++) if (!indeg[i]) queue[qt++] = i;
        hsr_domain *d = out[l];
        while (qh < qt && ok) {
            int u = queue[qh++];
            ok = dom_push(d, &ed[u]);
            for (int a = adj_head[u]; a >= 0; a = adj_next[a])
                if (--indeg[adj_to[a]] == 0) queue[qt++] = adj_to[a];
        }
        /* a cycle would mean crossing edges (cannot happen); keep all edges */
        for (int i = 0; i < ne && ok; i++) if (indeg[i] > 0) ok = dom_push(d, &ed[i]);
        free(ed); free(indeg); free(adj_head); free(adj_next); free(adj_to); free(queue);
        if (!ok) goto done;
        dom_finish_extent(d);
    }
    st = HSR_OK;
done:
    free(idx); free(start);
    return st;
}

hsr_status sweep_overlay(const sweep_in *in, int nin, const int64_t *hcut_y,
                         const int *hcut_bit, int nhcut, sweep_classify fn,
                         void *ctx, int nlabels, hsr_domain **out)
{
    hsr_status st = HSR_ENOMEM;
    vec E = {0, 0, 0, sizeof(sedge)}, Y = {0, 0, 0, sizeof(ry)}, P = {0, 0, 0, sizeof(piece)};
    int *act = NULL, *lastpiece = NULL;
    for (int l = 0; l < nlabels; l++) out[l] = NULL;
    for (int l = 0; l < nlabels; l++) if (!(out[l] = dom_new())) goto fail;
    for (int i = 0; i < nin; i++)
        for (int j = 0; j < in[i].n; j++) {
            const edge *e = &in[i].e[j];
            sedge s = {e, in[i].src, 0, 0};
            int64_t a = x_floor(&e->ln, e->y0), b = x_floor(&e->ln, e->y1);
            s.xmin = (a < b ? a : b) - 1;
            a = x_ceil(&e->ln, e->y0); b = x_ceil(&e->ln, e->y1);
            s.xmax = (a > b ? a : b) + 1;
            if (!vpush(&E, &s) || !vpush(&Y, &e->y0) || !vpush(&Y, &e->y1)) goto fail;
        }
    for (int i = 0; i < nhcut; i++) { ry y = ry_int(hcut_y[i]); if (!vpush(&Y, &y)) goto fail; }
    sedge *es = E.p;
    int n = (int)E.n;
    if (n > 1) qsort(es, (size_t)n, sizeof(sedge), cmp_sedge_y0);
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n && ry_cmp(es[j].e->y0, es[i].e->y1) < 0; j++) {
            if (es[j].xmin > es[i].xmax || es[j].xmax < es[i].xmin) continue;
            ry y;
            if (!line_cross_y(&es[i].e->ln, &es[j].e->ln, &y)) continue;
            if (ry_cmp(y, es[j].e->y0) <= 0 || ry_cmp(y, es[i].e->y1) >= 0
                || ry_cmp(y, es[j].e->y1) >= 0) continue;
            if (!vpush(&Y, &y)) goto fail;
        }
    ry *ys = Y.p;
    if (Y.n > 1) qsort(ys, Y.n, sizeof(ry), cmp_ry);
    int ny = 0;
    for (size_t i = 0; i < Y.n; i++) if (ny == 0 || ry_cmp(ys[ny - 1], ys[i]) != 0) ys[ny++] = ys[i];
    act = malloc(sizeof(int) * (size_t)(n + 1));
    lastpiece = malloc(sizeof(int) * (size_t)(nlabels + 1));
    if (!act || !lastpiece) goto fail;
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
                    if (!vpush(&P, &p)) goto fail;
                    lastpiece[labs[t]] = (int)P.n - 1;
                }
            }
            cur = nxt;
            i = j;
        }
    }
    st = assemble(P.p, (int)P.n, nlabels, out);
    if (st != HSR_OK) goto fail;
    free(E.p); free(Y.p); free(P.p); free(act); free(lastpiece);
    return HSR_OK;
fail:
    for (int l = 0; l < nlabels; l++) { hsr_domain_free(out[l]); out[l] = NULL; }
    free(E.p); free(Y.p); free(P.p); free(act); free(lastpiece);
    return st == HSR_OK ? HSR_ENOMEM : st;
}
