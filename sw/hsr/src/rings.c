/* rings.c - domain (Sorted-Edge) -> closed boundary rings for output.
 * Edges are directed with the interior on their left; the horizontal
 * parts of the boundary (dropped in the Sorted-Edge form) are recovered
 * per vertex level from the coverage just below and just above it. */
#include <stdlib.h>
#include "internal.h"

typedef struct pt { ry y; const line *ln; } pt;
typedef struct seg { pt a, b; int used; } seg;

static int pt_cmp(const pt *p, const pt *q)
{
    int c = ry_cmp(p->y, q->y);
    return c ? c : x_cmp_at(p->ln, q->ln, p->y);
}
static int cmp_seg_start(const void *a, const void *b) { return pt_cmp(&((const seg *)a)->a, &((const seg *)b)->a); }
static int cmp_ry(const void *a, const void *b) { return ry_cmp(*(const ry *)a, *(const ry *)b); }

static ry g_y;  /* qsort context */
static int cmp_line_at(const void *a, const void *b)
{
    return x_cmp_at(*(const line *const *)a, *(const line *const *)b, g_y);
}

hsr_status hsr_domain_rings(const hsr_domain *d, double **xy_out, int **len_out, int *nrings)
{
    if (!d || !xy_out || !len_out || !nrings) return HSR_EINVAL;
    *xy_out = NULL; *len_out = NULL; *nrings = 0;
    int n = d->n, cap = 5 * n + 8, ns = 0, nlev = 0;
    seg *s = malloc(sizeof(seg) * (size_t)cap);
    ry *lev = malloc(sizeof(ry) * (size_t)(2 * n + 1));
    const line **pos = malloc(sizeof(line *) * (size_t)(n + 1));
    double *xy = malloc(sizeof(double) * 2 * (size_t)cap);
    int *len = malloc(sizeof(int) * (size_t)cap);
    hsr_status st = HSR_ENOMEM;
    if (!s || !lev || !pos || !xy || !len) goto fail;
    for (int i = 0; i < n; i++) {
        const edge *e = &d->e[i];
        pt lo = {e->y0, &e->ln}, hi = {e->y1, &e->ln};
        s[ns].a = e->side > 0 ? hi : lo; s[ns].b = e->side > 0 ? lo : hi; s[ns].used = 0; ns++;
        lev[nlev++] = e->y0; lev[nlev++] = e->y1;
    }
    if (nlev > 1) qsort(lev, (size_t)nlev, sizeof(ry), cmp_ry);
    for (int li = 0; li < nlev; li++) {
        if (li > 0 && ry_cmp(lev[li], lev[li - 1]) == 0) continue;
        ry y = lev[li];
        int np = 0;
        for (int i = 0; i < n; i++)
            if (ry_cmp(d->e[i].y0, y) <= 0 && ry_cmp(y, d->e[i].y1) <= 0) pos[np++] = &d->e[i].ln;
        g_y = y;
        if (np > 1) qsort(pos, (size_t)np, sizeof(line *), cmp_line_at);
        int below = 0, above = 0;
        for (int i = 0; i < np;) {
            int j = i;
            while (j < np && x_cmp_at(pos[i], pos[j], y) == 0) {
                const edge *e = (const edge *)((const char *)pos[j] - offsetof(edge, ln));
                if (ry_cmp(e->y0, y) < 0) below ^= 1;
                if (ry_cmp(y, e->y1) < 0) above ^= 1;
                j++;
            }
            if (j < np && below != above) {
                if (ns >= cap) goto fail;
                pt p = {y, pos[i]}, q = {y, pos[j]};
                s[ns].a = above ? p : q; s[ns].b = above ? q : p; s[ns].used = 0; ns++;
            }
            i = j;
        }
    }
    if (ns > 1) qsort(s, (size_t)ns, sizeof(seg), cmp_seg_start);
    int nxy = 0, nr = 0;
    for (int i = 0; i < ns; i++) {
        if (s[i].used) continue;
        int start = nxy, cur = i;
        pt first = s[i].a;
        for (;;) {
            s[cur].used = 1;
            xy[2 * nxy] = x_at_d(s[cur].a.ln, s[cur].a.y); xy[2 * nxy + 1] = ry_d(s[cur].a.y); nxy++;
            if (pt_cmp(&s[cur].b, &first) == 0) break;
            int lo = 0, hi = ns;      /* first start >= end point */
            while (lo < hi) { int m = (lo + hi) / 2; if (pt_cmp(&s[m].a, &s[cur].b) < 0) lo = m + 1; else hi = m; }
            int nx = -1;
            for (int k = lo; k < ns && pt_cmp(&s[k].a, &s[cur].b) == 0; k++) if (!s[k].used) { nx = k; break; }
            if (nx < 0) { st = HSR_EINVAL; goto fail; }   /* open chain: cannot happen */
            cur = nx;
            if (nxy >= cap) goto fail;
        }
        len[nr++] = nxy - start;
    }
    free(s); free(lev); free(pos);
    *xy_out = xy; *len_out = len; *nrings = nr;
    return HSR_OK;
fail:
    free(s); free(lev); free(pos); free(xy); free(len);
    return st;
}
