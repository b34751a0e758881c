/* gridlist.c - Grid-List structure (section 5.3.2).  Every extent is
 * stored once, in the cell holding (left, bot); each cell list is sorted
 * on decreasing right+top.  Queries use w_max / h_max (the largest width
 * and height ever stored; never lowered on removal, which stays correct)
 * to skip cells that cannot hold an overlapping extent.  nx == 1 gives the
 * Slice-List of section 5.3.1. */
#include <stdlib.h>
#include "internal.h"

struct hsr_gridlist {
    hsr_extent win;
    int nx, ny;
    int64_t cw, ch;
    int *head;          /* nx*ny list heads, -1 = empty */
    int cap;            /* id capacity */
    int *next, *cell;   /* per id; cell -1 = not stored */
    hsr_extent *ext;
    int64_t wmax, hmax;
};

hsr_status hsr_gridlist_create(hsr_extent w, int nx, int ny, hsr_gridlist **out)
{
    if (!out) return HSR_EINVAL;
    *out = NULL;
    if (nx < 1 || ny < 1 || nx > 4096 || ny > 4096 || w.right <= w.left || w.top <= w.bot)
        return HSR_EINVAL;
    hsr_gridlist *g = calloc(1, sizeof *g);
    if (!g) return HSR_ENOMEM;
    g->win = w; g->nx = nx; g->ny = ny;
    g->cw = (w.right - w.left + nx - 1) / nx; if (g->cw < 1) g->cw = 1;
    g->ch = (w.top - w.bot + ny - 1) / ny; if (g->ch < 1) g->ch = 1;
    g->head = malloc(sizeof(int) * (size_t)nx * (size_t)ny);
    if (!g->head) { free(g); return HSR_ENOMEM; }
    for (int i = 0; i < nx * ny; i++) g->head[i] = -1;
    *out = g;
    return HSR_OK;
}

void hsr_gridlist_free(hsr_gridlist *g)
{
    if (!g) return;
    free(g->head); free(g->next); free(g->cell); free(g->ext); free(g);
}

static int col_of(const hsr_gridlist *g, int64_t x)
{
    if (x < g->win.left) return 0;
    int64_t c = (x - g->win.left) / g->cw;
    return c >= g->nx ? g->nx - 1 : (int)c;
}

static int row_of(const hsr_gridlist *g, int64_t y)
{
    if (y < g->win.bot) return 0;
    int64_t r = (y - g->win.bot) / g->ch;
    return r >= g->ny ? g->ny - 1 : (int)r;
}

static int grow(hsr_gridlist *g, int id)
{
    if (id < g->cap) return 1;
    int c = g->cap ? g->cap : 64;
    while (c <= id) c *= 2;
    int *nn = realloc(g->next, sizeof(int) * (size_t)c);
    if (!nn) return 0;
    g->next = nn;
    int *nc = realloc(g->cell, sizeof(int) * (size_t)c);
    if (!nc) return 0;
    g->cell = nc;
    hsr_extent *ne = realloc(g->ext, sizeof(hsr_extent) * (size_t)c);
    if (!ne) return 0;
    g->ext = ne;
    for (int i = g->cap; i < c; i++) g->cell[i] = -1;
    g->cap = c;
    return 1;
}

hsr_status hsr_gridlist_insert(hsr_gridlist *g, int id, hsr_extent e)
{
    if (!g || id < 0 || e.right < e.left || e.top < e.bot) return HSR_EINVAL;
    if (!grow(g, id)) return HSR_ENOMEM;
    if (g->cell[id] >= 0) return HSR_EINVAL;
    int c = row_of(g, e.bot) * g->nx + col_of(g, e.left);
    int64_t key = e.right + e.top;
    int *pp = &g->head[c];
    while (*pp >= 0 && g->ext[*pp].right + g->ext[*pp].top > key) pp = &g->next[*pp];
    g->next[id] = *pp; *pp = id;
    g->cell[id] = c; g->ext[id] = e;
    if (e.right - e.left > g->wmax) g->wmax = e.right - e.left;
    if (e.top - e.bot > g->hmax) g->hmax = e.top - e.bot;
    return HSR_OK;
}

hsr_status hsr_gridlist_remove(hsr_gridlist *g, int id)
{
    if (!g || id < 0 || id >= g->cap || g->cell[id] < 0) return HSR_ENOTFOUND;
    int *pp = &g->head[g->cell[id]];
    while (*pp >= 0 && *pp != id) pp = &g->next[*pp];
    if (*pp != id) return HSR_ENOTFOUND;
    *pp = g->next[id];
    g->cell[id] = -1;
    return HSR_OK;
}

long hsr_gridlist_query(const hsr_gridlist *g, hsr_extent q,
                        void (*fn)(int id, void *ctx), void *ctx)
{
    if (!g || !fn) return -1;
    long visited = 0;
    int c0 = col_of(g, q.left - g->wmax), c1 = col_of(g, q.right);
    int r0 = row_of(g, q.bot - g->hmax), r1 = row_of(g, q.top);
    int64_t key = q.left + q.bot;
    for (int r = r0; r <= r1; r++)
        for (int c = c0; c <= c1; c++)
            for (int id = g->head[r * g->nx + c]; id >= 0; id = g->next[id]) {
                const hsr_extent *e = &g->ext[id];
                visited++;
                if (e->right + e->top < key) break;
                if (hsr_extent_overlap(*e, q)) fn(id, ctx);
            }
    return visited;
}
