/* hsr.c - exact incremental hidden-surface removal (sections 5.4.2 and
 * 5.4.5).  MLR: the input domains, each with its lists of visibles and
 * invisibles.  LLR: the visibility map, disjoint domains in a Grid-List,
 * each with its parents ordered front to back up to the first opaque one
 * (followed by the unordered hidden parents). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

typedef struct ivec { int *v; int n, cap; } ivec;

/* -DHSR_STATS (off by default; docs/hsr.md, "Fig. 5.30"): counts of what the adds
 * do, summed and printed to stderr by hsr_destroy (then reset).  Without it the
 * counters compile to nothing (the object code is the same as without them). */
#ifdef HSR_STATS
#include <stdio.h>
static struct { long long adds, cand, ext_miss, apart, overlay, no_both, hidden_inplace, covered, replaced,
                edges_rem, edges_n, list_steps, repairs, holes, hole_edges, readds, merges; } hst;
#define HST_ADD(f, v) (hst.f += (v))
#else
#define HST_ADD(f, v) ((void)0)
#endif

static int iv_push(ivec *a, int x)
{
    if (a->n == a->cap) {
        int c = a->cap ? a->cap * 2 : 4;
        int *q = realloc(a->v, sizeof(int) * (size_t)c);
        if (!q) return 0;
        a->v = q; a->cap = c;
    }
    a->v[a->n++] = x;
    return 1;
}
static int iv_find(const ivec *a, int x)
{
    for (int i = 0; i < a->n; i++) if (a->v[i] == x) { HST_ADD(list_steps, i + 1); return i; }
    HST_ADD(list_steps, a->n);
    return -1;
}
static int iv_add(ivec *a, int x) { return iv_find(a, x) >= 0 || iv_push(a, x); }
static void iv_del(ivec *a, int x)
{
    int i = iv_find(a, x);
    if (i < 0) return;
    HST_ADD(list_steps, a->n - i - 1);
    memmove(a->v + i, a->v + i + 1, sizeof(int) * (size_t)(a->n - i - 1));
    a->n--;
}

/* mark_par / mark_acc: stamps for O(1) duplicate tests while one parent list or
 * one accumulated list is being built (iv_find there made long lists O(n^2)). */
typedef struct mlr { int present; hsr_domain *dom; hsr_plane plane; double opacity; ivec vis, invis;
                     unsigned mark_par, mark_acc; } mlr;
typedef struct llr { int used; hsr_domain *dom; ivec par; int nvis; } llr;

struct hsr_ctx {
    hsr_config cfg;
    hsr_gridlist *grid;
    mlr *m; int nm, capm;
    llr *l; int nl, capl;
    ivec freel;
    unsigned stamp;
    ivec *track;   /* during a damage repair: the slots given a new domain (for merge_slots) */
};

static unsigned next_stamp(hsr_ctx *h)
{
    if (++h->stamp == 0) {   /* wrapped: forget every old mark */
        for (int i = 0; i < h->nm; i++) h->m[i].mark_par = h->m[i].mark_acc = 0;
        h->stamp = 1;
    }
    return h->stamp;
}

#define OPAQUE(h, id) ((h)->m[id].opacity >= 1.0)

hsr_status hsr_create(const hsr_config *cfg, hsr_ctx **out)
{
    if (!out) return HSR_EINVAL;
    *out = NULL;
    if (!cfg) return HSR_EINVAL;
    hsr_ctx *h = calloc(1, sizeof *h);
    if (!h) return HSR_ENOMEM;
    h->cfg = *cfg;
    hsr_status st = hsr_gridlist_create(cfg->window, cfg->grid_nx, cfg->grid_ny, &h->grid);
    if (st != HSR_OK) { free(h); return st; }
    *out = h;
    return HSR_OK;
}

void hsr_destroy(hsr_ctx *h)
{
    if (!h) return;
#ifdef HSR_STATS
    fprintf(stderr, "hsr_stats adds %lld candidates %lld extent_miss %lld apart %lld overlays %lld "
            "no_overlap %lld hidden_in_place %lld covered %lld replaced %lld edges_rem %lld edges_n %lld "
            "list_steps %lld repairs %lld hole_domains %lld hole_edges %lld readds %lld merges %lld\n",
            hst.adds, hst.cand, hst.ext_miss, hst.apart, hst.overlay, hst.no_both,
            hst.hidden_inplace, hst.covered, hst.replaced, hst.edges_rem, hst.edges_n, hst.list_steps,
            hst.repairs, hst.holes, hst.hole_edges, hst.readds, hst.merges);
    memset(&hst, 0, sizeof hst);
#endif
    for (int i = 0; i < h->nm; i++) {
        hsr_domain_free(h->m[i].dom); free(h->m[i].vis.v); free(h->m[i].invis.v);
    }
    for (int i = 0; i < h->nl; i++) { hsr_domain_free(h->l[i].dom); free(h->l[i].par.v); }
    free(h->m); free(h->l); free(h->freel.v);
    hsr_gridlist_free(h->grid);
    free(h);
}

/* ---- LLR slot management ------------------------------------------ */
static hsr_status llr_create(hsr_ctx *h, hsr_domain *dom, const int *pre, int npre,
                             const ivec *tail)
{
    int s;
    if (h->freel.n) s = h->freel.v[--h->freel.n];
    else {
        if (h->nl == h->capl) {
            int c = h->capl ? h->capl * 2 : 64;
            llr *q = realloc(h->l, sizeof(llr) * (size_t)c);
            if (!q) { hsr_domain_free(dom); return HSR_ENOMEM; }
            h->l = q; h->capl = c;
        }
        s = h->nl++;
        memset(&h->l[s], 0, sizeof(llr));
    }
    llr *L = &h->l[s];
    L->used = 1; L->dom = dom; L->par.n = 0; L->nvis = npre;
    int ok = 1;
    unsigned mark = next_stamp(h);
    for (int i = 0; i < npre && ok; i++) {
        h->m[pre[i]].mark_par = mark;
        ok = iv_push(&L->par, pre[i]) && iv_add(&h->m[pre[i]].vis, s);
    }
    for (int i = 0; tail && i < tail->n && ok; i++) {
        int t = tail->v[i];
        if (h->m[t].mark_par == mark || !h->m[t].present) continue;
        h->m[t].mark_par = mark;
        ok = iv_push(&L->par, t) && iv_add(&h->m[t].invis, s);
    }
    if (!ok || (h->track && !iv_push(h->track, s))) return HSR_ENOMEM;
    return hsr_gridlist_insert(h->grid, s, dom->ext);
}

static void llr_destroy(hsr_ctx *h, int s)
{
    llr *L = &h->l[s];
    hsr_gridlist_remove(h->grid, s);
    for (int i = 0; i < L->par.n; i++) {
        iv_del(&h->m[L->par.v[i]].vis, s);
        iv_del(&h->m[L->par.v[i]].invis, s);
    }
    hsr_domain_free(L->dom);
    L->dom = NULL; L->used = 0; L->par.n = 0; L->nvis = 0;
    iv_push(&h->freel, s);   /* on failure the slot is just not reused */
}

static void collect(int id, void *ctx) { iv_push(ctx, id); }

/* ---- adding one MLR domain to the LLR (5.4.2) --------------------- */
typedef struct add_ctx {
    const hsr_ctx *h; int id, k; const int *pre; pair_order ord[HSR_MAX_PREFIX];
    int saw_both, hidden, covered;
} add_ctx;

static int classify_add(uint64_t db, uint64_t cb, void *vctx)
{
    add_ctx *c = vctx;
    int r = (int)(db & 1), n = (int)((db >> 1) & 1);
    if (r && !n) return 0;
    if (!r) return n ? 1 : -1;
    if (!n) return 0;
    c->saw_both = 1;
    int pos = 0;
    while (pos < c->k && !c->ord[pos].p_front_side[(cb >> pos) & 1]) pos++;
    if (pos == c->k && (OPAQUE(c->h, c->pre[c->k - 1]) || c->k >= HSR_MAX_PREFIX)) { c->hidden = 1; return 1; }
    if (pos == 0 && OPAQUE(c->h, c->id)) { c->covered = 1; return 0; }
    return 2 + pos;
}

/* The parents of LLR domain s join the accumulated hidden list acc of the
 * domain being added (deduplicated by mark_acc). */
static hsr_status acc_parents(hsr_ctx *h, int s, ivec *acc, unsigned acc_mark)
{
    const llr *N = &h->l[s];
    hsr_status st = HSR_OK;
    for (int i = 0; i < N->par.n; i++) {
        int p = N->par.v[i];
        if (h->m[p].mark_acc == acc_mark) continue;
        h->m[p].mark_acc = acc_mark;
        if (!iv_push(acc, p)) st = HSR_ENOMEM;
    }
    return st;
}

/* LLR domain s is wholly covered by the domain being added: its parents join
 * acc and s goes. */
static hsr_status absorb(hsr_ctx *h, int s, ivec *acc, unsigned acc_mark)
{
    hsr_status st = acc_parents(h, s, acc, acc_mark);
    llr_destroy(h, s);
    return st;
}

/* Slot s (wholly covered by opaque MLR domain id, in front) becomes id's new
 * LLR domain dom: id is its only visible parent, N's former visible parents
 * become hidden (moved from their visibles to their invisibles), the hidden
 * ones stay where they are (no work per hidden parent), and the parents in
 * acc are appended unless already listed (looked up in the parent's own lists,
 * which are short, not in the slot's long one). */
static hsr_status adopt(hsr_ctx *h, int s, int id, hsr_domain *dom, const ivec *acc)
{
    llr *L = &h->l[s];
    hsr_status st = HSR_OK;
    hsr_gridlist_remove(h->grid, s);
    hsr_domain_free(L->dom);
    L->dom = dom;
    for (int i = 0; i < L->nvis; i++) {
        ivec *v = &h->m[L->par.v[i]].vis;
        iv_del(v, s);
        if (!iv_push(&h->m[L->par.v[i]].invis, s)) st = HSR_ENOMEM;
    }
    if (iv_find(&h->m[id].invis, s) >= 0) {   /* a re-add that N listed as hidden: rare */
        iv_del(&L->par, id);
        iv_del(&h->m[id].invis, s);
    }
    /* id goes first; the old first parent moves to the (unordered) hidden end */
    if (!iv_push(&L->par, L->par.v[0]) || !iv_push(&h->m[id].vis, s)) st = HSR_ENOMEM;
    else { L->par.v[0] = id; L->nvis = 1; }
    for (int i = 0; i < acc->n && st == HSR_OK; i++) {
        int p = acc->v[i];
        if (p == id || !h->m[p].present || iv_find(&h->m[p].invis, s) >= 0 || iv_find(&h->m[p].vis, s) >= 0) continue;
        if (!iv_push(&L->par, p) || !iv_push(&h->m[p].invis, s)) st = HSR_ENOMEM;
    }
    if (h->track && !iv_push(h->track, s)) st = HSR_ENOMEM;
    hsr_status s2 = hsr_gridlist_insert(h->grid, s, dom->ext);
    return st != HSR_OK ? st : s2;
}

/* Candidates are scattered in memory: slot -> domain -> edges is a chain of
 * cache misses (most of add_domain's own time in the profile).  Start the loads
 * of the next candidates early, each stage one step behind the previous (its
 * pointer has arrived by then): the slot 4 ahead, its domain 2 ahead, the
 * edges and the parent list 1 ahead.  Only hints: nothing is read from a slot
 * that is not in use, and no result depends on them. */
/* always_inline: as a function of its own, GCC finds it free of side effects
 * (a prefetch is not one) and deletes the call, prefetches and all */
static inline __attribute__((always_inline)) void prefetch_cand(const hsr_ctx *h, const ivec *cand, int ci)
{
    if (ci + 4 < cand->n) __builtin_prefetch(&h->l[cand->v[ci + 4]]);
    if (ci + 2 < cand->n) {
        const llr *L = &h->l[cand->v[ci + 2]];
        if (L->used) __builtin_prefetch(L->dom);
    }
    if (ci + 1 < cand->n) {
        const llr *L = &h->l[cand->v[ci + 1]];
        if (L->used) {
            const char *e = (const char *)L->dom->e;
            __builtin_prefetch(e); __builtin_prefetch(e + 64);
            __builtin_prefetch(e + 128); __builtin_prefetch(e + 192);
            __builtin_prefetch(L->par.v);
        }
    }
}

/* Adds the part rem (owned, taken) of MLR domain id to the LLR: all of it for
 * an add, its part in the damaged region for a damage repair.  The depth
 * orders are those of id's whole domain, so a part is added as in a full build. */
static hsr_status add_region(hsr_ctx *h, int id, hsr_domain *rem)
{
    hsr_status st = HSR_OK;
    mlr *M = &h->m[id];
    if (hsr_domain_is_empty(rem)) { hsr_domain_free(rem); return HSR_OK; }
    ivec cand = {0, 0, 0}, acc = {0, 0, 0}, tail = {0, 0, 0};
    unsigned acc_mark = next_stamp(h);
    int keep = -1;   /* a slot wholly covered by I, reused for I's new domain */
    hsr_gridlist_query(h->grid, rem->ext, collect, &cand);
    HST_ADD(adds, 1); HST_ADD(cand, cand.n);
    for (int ci = 0; ci < cand.n && !hsr_domain_is_empty(rem); ci++) {
        int s = cand.v[ci];
        prefetch_cand(h, &cand, ci);
        llr *N = &h->l[s];
        if (!N->used || !hsr_extent_overlap(rem->ext, N->dom->ext)) { HST_ADD(ext_miss, 1); continue; }
        /* interiors shown disjoint: the overlay would meet nothing (saw_both 0).
         * -DHSR_NO_SEPARATION_TEST (an experiment, docs/hsr.md "Fig. 5.30") leaves it
         * out, as the source's loop had no such test; results are the same. */
#ifndef HSR_NO_SEPARATION_TEST
        if (dom_interiors_apart(rem, N->dom)) { HST_ADD(apart, 1); continue; }
#endif
        HST_ADD(overlay, 1); HST_ADD(edges_rem, rem->n); HST_ADD(edges_n, N->dom->n);
        add_ctx c;   /* not cleared whole (60 orders, 4 KB): ord[j < k] is set below */
        c.saw_both = c.hidden = c.covered = 0;
        c.h = h; c.id = id; c.k = N->nvis; c.pre = N->par.v;
        sweep_in in[2 + HSR_MAX_PREFIX];
        edge cuts[HSR_MAX_PREFIX];
        int64_t hy[HSR_MAX_PREFIX];
        int hb[HSR_MAX_PREFIX], nin = 2, nh = 0;
        in[0] = (sweep_in){rem->e, rem->n, 0};
        in[1] = (sweep_in){N->dom->e, N->dom->n, 1};
        for (int j = 0; j < c.k; j++) {
            const mlr *P = &h->m[c.pre[j]];
            pair_order_make(M->dom, M->plane, id, P->dom, P->plane, c.pre[j], &c.ord[j]);
            if (!c.ord[j].has_cut) continue;
            if (c.ord[j].horizontal) { hy[nh] = c.ord[j].hy; hb[nh++] = j; continue; }
            cuts[j].ln = c.ord[j].cut; cuts[j].y0 = ry_int(c.ord[j].ybot);
            cuts[j].y1 = ry_int(c.ord[j].ytop); cuts[j].side = 0;
            in[nin++] = (sweep_in){&cuts[j], 1, 64 + j};
        }
        int nlab = c.k + 3;
        hsr_domain *res[HSR_MAX_PREFIX + 3];
        int cnt[HSR_MAX_PREFIX + 3];
        st = sweep_overlay_pieces(in, nin, hy, hb, nh, classify_add, &c, nlab, cnt);
        if (st != HSR_OK) goto done;
        if (!c.saw_both) { HST_ADD(no_both, 1); continue; }   /* nothing assembled */
        /* which results are used (a label with no pieces is an empty domain) */
        int split = c.covered, front = 0;
        for (int pos = 0; pos <= c.k; pos++) front |= cnt[2 + pos] > 0;
        split |= front;
        unsigned char need[HSR_MAX_PREFIX + 3];
        int all = split && !(c.covered && cnt[1] == 0 && !front);
        for (int i = 0; i < nlab; i++) need[i] = (unsigned char)(i == 0 || all);
        st = sweep_assemble(nlab, need, res);
        if (st != HSR_OK) goto done;
        hsr_domain_free(rem);
        rem = res[0];
        if (!split) {
            /* The new domain is hidden wherever it meets N (no covered part, no new
             * front piece), so N keeps its shape: append id to N's hidden parents in
             * place.  Destroying and recreating N would copy its whole parent list on
             * every add, making n domains hidden behind one front domain cost O(n^2)
             * each (Fig. 5.30 tri-spets must be linear). */
            HST_ADD(hidden_inplace, 1);
            for (int i = 1; i < nlab; i++) hsr_domain_free(res[i]);
            /* A re-add during damage repair may meet an N that already lists id; look
             * in id's own lists (short), not in N's (long). */
            int listed = iv_find(&h->m[id].invis, s) >= 0;
            for (int j = 0; j < N->nvis && !listed; j++) listed = N->par.v[j] == id;
            if (!listed && (!iv_push(&N->par, id) || !iv_push(&h->m[id].invis, s))) { st = HSR_ENOMEM; goto done; }
            continue;
        }
        if (c.covered && cnt[1] == 0 && !front) {
            /* I is opaque and in front of all of N: N disappears into the new
             * domain, which inherits all of N's parents as hidden ones.  Keep the
             * slot with the longest parent list for the new domain instead of
             * copying that list (Fig. 5.30 tri-spets reversed: every new triangle
             * covers the one domain holding all earlier ones, O(n) per add). */
            HST_ADD(covered, 1);
            for (int i = 1; i < nlab; i++) hsr_domain_free(res[i]);
            if (keep >= 0 && h->l[keep].par.n >= N->par.n) { st = absorb(h, s, &acc, acc_mark); }
            else { if (keep >= 0) st = absorb(h, keep, &acc, acc_mark); keep = s; }
            if (st != HSR_OK) goto done;
            continue;
        }
        /* N is replaced by its pieces; copy its parents first */
        HST_ADD(replaced, 1);
        int pre[HSR_MAX_PREFIX + 1], k = c.k;
        memcpy(pre, N->par.v, sizeof(int) * (size_t)k);
        tail.n = 0;
        for (int i = k; i < N->par.n; i++) iv_push(&tail, N->par.v[i]);
        if (c.covered) st = acc_parents(h, s, &acc, acc_mark);
        llr_destroy(h, s);
        if (c.hidden) iv_add(&tail, id);
        if (!hsr_domain_is_empty(res[1])) { st = llr_create(h, res[1], pre, k, &tail); res[1] = NULL; }
        if (c.hidden) iv_del(&tail, id);
        for (int pos = 0; pos <= k; pos++) {
            hsr_domain *d = res[2 + pos];
            res[2 + pos] = NULL;
            if (hsr_domain_is_empty(d)) { hsr_domain_free(d); continue; }
            int np[HSR_MAX_PREFIX + 1], nn = 0, ntail0 = tail.n;
            for (int j = 0; j < pos; j++) np[nn++] = pre[j];
            np[nn++] = id;
            for (int j = pos; j < k; j++) {
                if (OPAQUE(h, np[nn - 1]) || nn >= HSR_MAX_PREFIX) iv_add(&tail, pre[j]);
                else np[nn++] = pre[j];
            }
            hsr_status s2 = llr_create(h, d, np, nn, &tail);
            if (s2 != HSR_OK) st = s2;
            tail.n = ntail0;
        }
        hsr_domain_free(res[1]);
        if (st != HSR_OK) goto done;
    }
    if (keep >= 0 && !hsr_domain_is_empty(rem)) { st = adopt(h, keep, id, rem, &acc); rem = NULL; keep = -1; }
    else if (!hsr_domain_is_empty(rem)) { st = llr_create(h, rem, &id, 1, &acc); rem = NULL; }
done:
    if (keep >= 0) llr_destroy(h, keep);   /* error: no stale domain overlapping the new pieces */
    hsr_domain_free(rem);
    free(cand.v); free(acc.v); free(tail.v);
    return st;
}

static hsr_status add_domain(hsr_ctx *h, int id)
{
    if (hsr_domain_is_empty(h->m[id].dom)) return HSR_OK;
    hsr_domain *rem = hsr_domain_clone(h->m[id].dom);
    return rem ? add_region(h, id, rem) : HSR_ENOMEM;
}

/* ---- removal with damage repair (5.4.5) --------------------------- */
/* Removing MLR domains leaves a hole in the LLR: the LLR domains with one of
 * them in their visible prefix (where they are hidden parents they are just
 * dropped from the list).  Whatever shows in the hole is among the parents of
 * the hole's domains (every MLR domain that covers an LLR domain is one of its
 * parents), so the repair re-adds each of those parents clipped to the hole, in
 * id order, with the depth orders of its whole domain (add_region), and then
 * joins each new domain to the LLR domains with the same visible prefix whose
 * extents it meets (merge_slots), so that repeated moves do not cut the LLR up
 * along every old hole.  The work is in proportion to the hole and its parents,
 * not to the parents' whole domains (docs/hsr.md, "Damage repair"). */
static int cmp_int(const void *a, const void *b) { return *(const int *)a - *(const int *)b; }

static int classify_hole(uint64_t db, uint64_t cb, void *ctx)
{
    (void)cb; (void)ctx;
    return (db & 1) ? 0 : -1;
}

/* Takes xs[0..nx-1] out of the LLR: R receives the parents to re-add (sorted,
 * without xs), *hole the union of the removed LLR domains (NULL if none). */
static hsr_status damage_remove(hsr_ctx *h, const int *xs, int nx, ivec *R, hsr_domain **hole)
{
    ivec L = {0, 0, 0};
    sweep_in *in = NULL;
    hsr_status st = HSR_ENOMEM;
    *hole = NULL;
    unsigned mark = next_stamp(h);
    for (int i = 0; i < nx; i++) h->m[xs[i]].mark_acc = mark;
    for (int i = 0; i < nx; i++) {
        mlr *X = &h->m[xs[i]];
        for (int j = 0; j < X->vis.n; j++) if (!iv_push(&L, X->vis.v[j])) goto done;
        for (int j = X->invis.n - 1; j >= 0; j--) iv_del(&h->l[X->invis.v[j]].par, xs[i]);
        X->invis.n = 0;
    }
    if (L.n > 1) {
        qsort(L.v, (size_t)L.n, sizeof(int), cmp_int);
        int w = 1;
        for (int i = 1; i < L.n; i++) if (L.v[i] != L.v[w - 1]) L.v[w++] = L.v[i];
        L.n = w;
    }
    for (int i = 0; i < L.n; i++) {
        const llr *N = &h->l[L.v[i]];
        for (int j = 0; j < N->par.n; j++) {
            int p = N->par.v[j];
            if (h->m[p].mark_acc == mark) continue;
            h->m[p].mark_acc = mark;
            if (!iv_push(R, p)) goto done;
        }
    }
    if (R->n > 1) qsort(R->v, (size_t)R->n, sizeof(int), cmp_int);
    if (L.n) {
        if (!(in = malloc(sizeof(sweep_in) * (size_t)L.n))) goto done;
        for (int i = 0; i < L.n; i++) in[i] = (sweep_in){h->l[L.v[i]].dom->e, h->l[L.v[i]].dom->n, 0};
        st = sweep_overlay(in, L.n, NULL, NULL, 0, classify_hole, NULL, 1, hole);
        if (st != HSR_OK) goto done;
        HST_ADD(holes, L.n); HST_ADD(hole_edges, (*hole)->n);
    }
    for (int i = 0; i < L.n; i++) llr_destroy(h, L.v[i]);
    st = HSR_OK;
done:
    free(L.v); free(in);
    return st;
}

static int same_prefix(const llr *a, const llr *b)
{
    return a->nvis == b->nvis && !memcmp(a->par.v, b->par.v, sizeof(int) * (size_t)a->nvis);
}

/* Slot k takes the union u of its domain and slot d's (same prefix): d's hidden
 * parents that k lacks are appended (looked up in the parent's own list), d goes. */
static hsr_status join(hsr_ctx *h, int k, int d, hsr_domain *u)
{
    hsr_status st = HSR_OK;
    const llr *D = &h->l[d];
    for (int i = D->nvis; i < D->par.n && st == HSR_OK; i++) {
        int p = D->par.v[i];
        if (iv_find(&h->m[p].invis, k) >= 0) continue;
        if (!iv_push(&h->l[k].par, p) || !iv_push(&h->m[p].invis, k)) st = HSR_ENOMEM;
    }
    llr_destroy(h, d);
    llr *K = &h->l[k];
    hsr_gridlist_remove(h->grid, k);
    hsr_domain_free(K->dom);
    K->dom = u;
    hsr_status s2 = hsr_gridlist_insert(h->grid, k, u->ext);
    HST_ADD(merges, 1);
    return st != HSR_OK ? st : s2;
}

/* Each slot in track still in use is joined with every LLR domain of the same
 * visible prefix whose extent meets its own (the slot keeping the longer parent
 * list keeps the union). */
static hsr_status merge_slots(hsr_ctx *h, const ivec *track)
{
    hsr_status st = HSR_OK;
    ivec cand = {0, 0, 0};
    for (int ti = 0; ti < track->n && st == HSR_OK; ti++) {
        int s = track->v[ti];
        if (!h->l[s].used) continue;
        int again = 1;
        while (again && st == HSR_OK) {
            again = 0;
            cand.n = 0;
            hsr_gridlist_query(h->grid, h->l[s].dom->ext, collect, &cand);
            for (int ci = 0; ci < cand.n; ci++) {
                int t = cand.v[ci];
                const llr *S = &h->l[s], *T = &h->l[t];
                if (t == s || !T->used || !same_prefix(S, T) || !hsr_extent_overlap(S->dom->ext, T->dom->ext)) continue;
                hsr_domain *u = NULL;
                st = hsr_domain_boolean(S->dom, T->dom, HSR_UNION, &u);
                if (st != HSR_OK) break;
                int k = T->par.n > S->par.n ? t : s;
                st = join(h, k, k == s ? t : s, u);
                s = k; again = 1;
                break;
            }
        }
    }
    free(cand.v);
    return st;
}

/* Removes xs[0..nx-1] (marked not present by the caller) from the LLR and
 * repairs the damage; the slots given new domains are appended to track (for
 * merge_slots, after the caller's own adds). */
static hsr_status repair(hsr_ctx *h, const int *xs, int nx, ivec *track)
{
    ivec R = {0, 0, 0};
    hsr_domain *hole = NULL;
    HST_ADD(repairs, 1);
    hsr_status st = damage_remove(h, xs, nx, &R, &hole);
    h->track = track;
    for (int i = 0; i < R.n && st == HSR_OK && hole; i++) {
        const mlr *P = &h->m[R.v[i]];
        if (!hsr_extent_overlap(P->dom->ext, hole->ext)) continue;
        hsr_domain *rem = NULL;
        st = hsr_domain_boolean(P->dom, hole, HSR_INTERSECT, &rem);
        HST_ADD(readds, 1);
        if (st == HSR_OK) st = add_region(h, R.v[i], rem);
    }
    h->track = NULL;
    hsr_domain_free(hole);
    free(R.v);
    return st;
}

/* ---- public operations --------------------------------------------- */
static int plane_ok(hsr_plane p) { return isfinite(p.a) && isfinite(p.b) && isfinite(p.c); }
static int id_ok(const hsr_ctx *h, int id) { return h && id >= 0 && id < h->nm && h->m[id].present; }

hsr_status hsr_add(hsr_ctx *h, const int64_t *xy, const int *ring_len, int nrings,
                   hsr_plane plane, double opacity, int *id_out)
{
    if (!h || !plane_ok(plane) || !(opacity >= 0.0 && opacity <= 1.0)) return HSR_EINVAL;
    hsr_domain *d;
    hsr_status st = hsr_domain_from_rings(xy, ring_len, nrings, &d);
    if (st != HSR_OK) return st;
    if (h->nm == h->capm) {
        int c = h->capm ? h->capm * 2 : 64;
        mlr *q = realloc(h->m, sizeof(mlr) * (size_t)c);
        if (!q) { hsr_domain_free(d); return HSR_ENOMEM; }
        h->m = q; h->capm = c;
    }
    int id = h->nm++;
    memset(&h->m[id], 0, sizeof(mlr));
    h->m[id].present = 1; h->m[id].dom = d; h->m[id].plane = plane; h->m[id].opacity = opacity;
    if (id_out) *id_out = id;
    return add_domain(h, id);
}

hsr_status hsr_remove(hsr_ctx *h, int id)
{
    if (!id_ok(h, id)) return HSR_ENOTFOUND;
    h->m[id].present = 0;
    ivec track = {0, 0, 0};
    hsr_status st = repair(h, &id, 1, &track);
    if (st == HSR_OK) st = merge_slots(h, &track);
    free(track.v);
    hsr_domain_free(h->m[id].dom);
    h->m[id].dom = NULL;
    return st;
}

hsr_status hsr_change_many(hsr_ctx *h, const hsr_change *c, int n)
{
    if (!h || n < 0 || (n > 0 && !c)) return HSR_EINVAL;
    unsigned mark = next_stamp(h);
    for (int i = 0; i < n; i++) {
        if (!id_ok(h, c[i].id)) return HSR_ENOTFOUND;
        if (h->m[c[i].id].mark_par == mark) return HSR_EINVAL;   /* listed twice */
        h->m[c[i].id].mark_par = mark;
        if (c[i].xy && !plane_ok(c[i].plane)) return HSR_EINVAL;
        if (!(c[i].opacity < 0 || c[i].opacity <= 1.0)) return HSR_EINVAL;   /* NaN too */
    }
    hsr_domain **nd = calloc((size_t)n + 1, sizeof *nd);
    int *xs = malloc(sizeof(int) * ((size_t)n + 1)), nx = 0;
    hsr_status st = nd && xs ? HSR_OK : HSR_ENOMEM;
    for (int i = 0; i < n && st == HSR_OK; i++)
        if (c[i].xy) st = hsr_domain_from_rings(c[i].xy, c[i].ring_len, c[i].nrings, &nd[i]);
    /* Only whether a domain is opaque shapes the LLR: a transparent domain that
     * stays transparent keeps its place in every prefix (the composited colour is
     * the caller's), so it needs no repair. */
    for (int i = 0; i < n && st == HSR_OK; i++) {
        const mlr *M = &h->m[c[i].id];
        int keep = !nd[i] && (c[i].opacity < 0 || (M->opacity < 1.0 && c[i].opacity < 1.0));
        if (!keep) xs[nx++] = c[i].id;
    }
    if (st == HSR_OK) {
        if (nx > 1) qsort(xs, (size_t)nx, sizeof(int), cmp_int);
        ivec track = {0, 0, 0};
        for (int i = 0; i < nx; i++) h->m[xs[i]].present = 0;
        st = repair(h, xs, nx, &track);
        for (int i = 0; i < nx; i++) h->m[xs[i]].present = 1;
        for (int i = 0; i < n; i++) {
            mlr *M = &h->m[c[i].id];
            if (nd[i]) { hsr_domain_free(M->dom); M->dom = nd[i]; nd[i] = NULL; M->plane = c[i].plane; }
            if (c[i].opacity >= 0) M->opacity = c[i].opacity;
        }
        /* the new domains' pieces are joined too: an add into a repaired LLR would
         * otherwise leave pieces of one prefix apart that a build makes one */
        h->track = &track;
        for (int i = 0; i < nx && st == HSR_OK; i++) st = add_domain(h, xs[i]);
        h->track = NULL;
        if (st == HSR_OK) st = merge_slots(h, &track);
        free(track.v);
    }
    for (int i = 0; i < n && nd; i++) hsr_domain_free(nd[i]);
    free(nd); free(xs);
    return st;
}

hsr_status hsr_move(hsr_ctx *h, int id, const int64_t *xy, const int *ring_len,
                    int nrings, hsr_plane plane)
{
    if (!id_ok(h, id)) return HSR_ENOTFOUND;
    if (!plane_ok(plane) || !xy) return HSR_EINVAL;
    hsr_change c = {id, xy, ring_len, nrings, plane, -1};
    return hsr_change_many(h, &c, 1);
}

hsr_status hsr_set_opacity(hsr_ctx *h, int id, double opacity)
{
    if (!id_ok(h, id)) return HSR_ENOTFOUND;
    if (!(opacity >= 0.0 && opacity <= 1.0)) return HSR_EINVAL;
    hsr_change c = {id, NULL, NULL, 0, {0, 0, 0}, opacity};
    return hsr_change_many(h, &c, 1);
}

hsr_status hsr_rebuild(hsr_ctx *h)
{
    if (!h) return HSR_EINVAL;
    for (int s = 0; s < h->nl; s++) if (h->l[s].used) llr_destroy(h, s);
    for (int i = 0; i < h->nm; i++) {
        if (!h->m[i].present) continue;
        hsr_status st = add_domain(h, i);
        if (st != HSR_OK) return st;
    }
    return HSR_OK;
}

hsr_status hsr_pick(const hsr_ctx *h, int64_t x, int64_t y, hsr_pick_mode mode, int *id_out)
{
    if (!h || !id_out) return HSR_EINVAL;
    ivec cand = {0, 0, 0};
    hsr_extent q = {x, y, x, y};
    hsr_gridlist_query(h->grid, q, collect, &cand);
    int found = -1;
    for (int i = 0; i < cand.n && found < 0; i++)
        if (hsr_domain_contains(h->l[cand.v[i]].dom, x, y)) found = cand.v[i];
    free(cand.v);
    if (found < 0) return HSR_ENOTFOUND;
    const llr *L = &h->l[found];
    if (mode == HSR_PICK_VISIBLE) { *id_out = L->par.v[0]; return HSR_OK; }
    if (mode == HSR_PICK_FIRST_OPAQUE) {
        for (int i = 0; i < L->nvis; i++) if (OPAQUE(h, L->par.v[i])) { *id_out = L->par.v[i]; return HSR_OK; }
        return HSR_ENOTFOUND;
    }
    if (mode != HSR_PICK_NEXT_BEHIND) return HSR_EINVAL;
    if (L->nvis > 1) { *id_out = L->par.v[1]; return HSR_OK; }
    int best = -1;
    double bz = 0;
    for (int i = L->nvis; i < L->par.n; i++) {   /* nearest hidden parent at (x,y) */
        const mlr *P = &h->m[L->par.v[i]];
        if (!hsr_domain_contains(P->dom, x, y)) continue;
        double z = P->plane.a * (double)x + P->plane.b * (double)y + P->plane.c;
        if (best < 0 || z < bz) { best = L->par.v[i]; bz = z; }
    }
    if (best < 0) return HSR_ENOTFOUND;
    *id_out = best;
    return HSR_OK;
}

int hsr_llr_slots(const hsr_ctx *h) { return h ? h->nl : 0; }
int hsr_mlr_slots(const hsr_ctx *h) { return h ? h->nm : 0; }

int hsr_llr_get(const hsr_ctx *h, int slot, const hsr_domain **dom, const int **parents,
                int *nvis, int *npar)
{
    if (!h || slot < 0 || slot >= h->nl || !h->l[slot].used) return 0;
    const llr *L = &h->l[slot];
    if (dom) *dom = L->dom;
    if (parents) *parents = L->par.v;
    if (nvis) *nvis = L->nvis;
    if (npar) *npar = L->par.n;
    return 1;
}

int hsr_mlr_get(const hsr_ctx *h, int id, const hsr_domain **dom, hsr_plane *plane,
                double *opacity, int *nvisibles, int *ninvisibles)
{
    if (!id_ok(h, id)) return 0;
    const mlr *M = &h->m[id];
    if (dom) *dom = M->dom;
    if (plane) *plane = M->plane;
    if (opacity) *opacity = M->opacity;
    if (nvisibles) *nvisibles = M->vis.n;
    if (ninvisibles) *ninvisibles = M->invis.n;
    return 1;
}

hsr_status hsr_check(const hsr_ctx *h)
{
    if (!h) return HSR_EINVAL;
    for (int s = 0; s < h->nl; s++) {
        const llr *L = &h->l[s];
        if (!L->used) continue;
        if (L->nvis < 1 || L->nvis > L->par.n || hsr_domain_is_empty(L->dom)) return HSR_EINVAL;
        for (int i = 0; i < L->par.n; i++) {
            int p = L->par.v[i];
            if (!id_ok(h, p)) return HSR_EINVAL;
            if (i < L->nvis - 1 && OPAQUE(h, p)) return HSR_EINVAL;
            const ivec *lst = i < L->nvis ? &h->m[p].vis : &h->m[p].invis;
            if (iv_find(lst, s) < 0) return HSR_EINVAL;
        }
    }
    for (int id = 0; id < h->nm; id++) {
        const mlr *M = &h->m[id];
        if (!M->present) { if (M->vis.n || M->invis.n) return HSR_EINVAL; continue; }
        for (int i = 0; i < M->vis.n; i++) {
            const llr *L = &h->l[M->vis.v[i]];
            int j = iv_find(&L->par, id);
            if (!L->used || j < 0 || j >= L->nvis) return HSR_EINVAL;
        }
        for (int i = 0; i < M->invis.n; i++) {
            const llr *L = &h->l[M->invis.v[i]];
            int j = iv_find(&L->par, id);
            if (!L->used || j < L->nvis) return HSR_EINVAL;
        }
    }
    return HSR_OK;
}
