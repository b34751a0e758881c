/* yp_scan.c - the y-processor's per-frame work (sections 7.2, 7.3, 5.5):
 * for every visible pattern and every scanline it touches, the terms of
 * eq. 7.2 as x-processor commands; capacity per line with degradation
 * Eval3 -> Eval2 -> Eval1 of the least visible patterns (section 7.5).
 *
 * A pattern is the visible part of one layer stack: all LLR domains with
 * the same ordered parent prefix are scan-converted together, so the
 * commands do not depend on how the HSR fragmented the visibility map
 * (an incremental update then gives the same streams as a full rebuild).
 *
 * Every line starts with Eval1 (0, W, background + 1/2): the background
 * where nothing is visible, and the 1/2 makes the pixel (the integer part
 * of D) the rounded sum.  A pattern adds cov * (colour - background) per
 * pixel, so a pixel shared by domains gets exactly the box-filter average
 * (eq. 5.6) and a fully covered pixel the pattern's colour:
 *   - pixels it covers fully: one Eval over the span from its first to its
 *     last full pixel, Dis over the pixels in between that are not full
 *     (1 slot each, cheaper than splitting the Eval: 3..5 slots);
 *   - pixels it covers partly: Eval1 (x, 1, cov * (colour - background)).
 * Specular terms of Phong patterns come last, after Acc_mode (1): they
 * are >= 0, so a fitted quadratic that dips below 0 contributes 0. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

#define COV_Q 65536.0     /* coverage is rounded to 2^-16 of a pixel: hides the sub-unit slivers in
                           * which an incremental HSR result may differ from a rebuild */
#define TOL_PARTIAL (1.0 / 64)  /* fit tolerance at partly covered pixels, pixel units */
#define YP_COH_HYST 0.5         /* coherent fitting: new pieces at half the tolerance [choice] */

typedef struct entry {
    double area;
    int maxlev, lev;
    int cost[4];               /* slots of levels 1..3 (without partial pixels) */
    int spec_cost;             /* part of cost[3] after Acc_mode */
    int npart;
    yp_cmdlist lv[4], spec;    /* lv[1..3]: Dis + Sets + Eval over the covered pixels */
    yp_cmdlist tex;            /* texture term (yp_tex.c), emitted after lv[lev]; in cost[] */
    /* coherent fitting with a previous frame: the same terms fitted without it (what lv
     * and spec are without one), their costs; the level of every pattern is chosen on
     * these, so that it does not depend on the history (docs/yproc.md section 11.1) */
    yp_cmdlist plv[4], pspec;
    int pcost[4], pspec_cost;
} entry;

/* where a term's commands are in the previous frame's line: [lo, hi) */
typedef struct tspan { uint16_t term; int lo, hi; } tspan;

/* a line's entries (one per pattern, in the order they are emitted); in colour 0's the
 * terms (yp_cmd.term) its patterns took; with a previous frame, where its line's terms are
 * (open addressing, built at the first entry) */
typedef struct line_entries {
    entry **e; int n, cap;
    uint16_t *term; int nterm, tcap;
    tspan *ps; int pscap, pbuilt;
} line_entries;

/* the spans of the previous line's terms: a term's commands are contiguous (its colour
 * function and texture before Acc_mode, a specular term after it), so a search for its
 * commands looks at them only, not at the whole line for every pattern.  0: no memory */
static int prev_spans(line_entries *L, const yp_cmdlist *pl)
{
    L->pbuilt = 1;
    int cap = 16;
    while (cap < 2 * pl->n) cap *= 2;
    if (!(L->ps = calloc((size_t)cap, sizeof *L->ps))) return 0;
    L->pscap = cap;
    const unsigned m = (unsigned)cap - 1;
    for (int i = 0; i < pl->n; i++) {
        unsigned t = pl->c[i].term, k = t & m;
        if (!t) continue;
        while (L->ps[k].term && L->ps[k].term != t) k = (k + 1) & m;
        if (!L->ps[k].term) L->ps[k] = (tspan){(uint16_t)t, i, i + 1};
        else L->ps[k].hi = i + 1;
    }
    return 1;
}

static void prev_span(const line_entries *L, unsigned t, int *lo, int *hi)
{
    *lo = *hi = 0;
    if (!L->ps || !t) return;
    const unsigned m = (unsigned)L->pscap - 1;
    for (unsigned k = t & m; L->ps[k].term; k = (k + 1) & m)
        if (L->ps[k].term == t) { *lo = L->ps[k].lo; *hi = L->ps[k].hi; return; }
}

/* A term of a pattern on a line (yp_cmd.term; salt 0: its colour function and texture,
 * 1 + l: its specular term of light l): a hash of the layer stack and the salt, so that
 * it names the same term in the next frame, made unique within the line (the next free
 * value after a collision).  Coherent fitting takes up only a term's own commands of the
 * previous frame: by column alone it took another pattern's when two start at one pixel
 * (both cover it partly), or another light's specular term, and a line re-fitted against
 * itself was not itself.  A line with more than 32767 terms gets the hash as it is (not
 * unique; such a line is far over any capacity).  0: no memory. */
static unsigned line_term(line_entries *L, const int *par, int nvis, int salt)
{
    uint32_t h = 2166136261u;   /* FNV-1a over the stack and the salt */
    for (int j = 0; j <= nvis; j++) {
        uint32_t w = j < nvis ? (uint32_t)par[j] : (uint32_t)salt;
        for (int b = 0; b < 4; b++) { h ^= (w >> (8 * b)) & 255u; h *= 16777619u; }
    }
    unsigned t = (h ^ (h >> 16)) & 0xffffu;
    if (t == 0) t = 1;
    if (L->nterm >= 32767) return t;
    if (2 * (L->nterm + 1) > L->tcap) {   /* open addressing, at most half full */
        int nc = L->tcap ? 2 * L->tcap : 64;
        uint16_t *p = calloc((size_t)nc, sizeof *p);
        if (!p) return 0;
        for (int i = 0; i < L->tcap; i++)
            if (L->term[i]) { unsigned k = L->term[i] & (unsigned)(nc - 1); while (p[k]) k = (k + 1) & (unsigned)(nc - 1); p[k] = L->term[i]; }
        free(L->term); L->term = p; L->tcap = nc;
    }
    const unsigned m = (unsigned)L->tcap - 1;
    for (;;) {
        if (t == 0) t = 1;
        unsigned k = t & m;
        while (L->term[k] && L->term[k] != t) k = (k + 1) & m;
        if (!L->term[k]) { L->term[k] = (uint16_t)t; L->nterm++; return t; }
        t = (t + 1) & 0xffffu;      /* taken by another pattern of the line */
    }
}

static void set_term(yp_cmdlist *l, unsigned term)
{
    for (int i = 0; i < l->n; i++) l->c[i].term = (uint16_t)term;
}

typedef struct key { int slot; const int *par; int nvis; } key;

static int key_cmp(const void *pa, const void *pb)
{
    const key *a = pa, *b = pb;
    int n = a->nvis < b->nvis ? a->nvis : b->nvis;
    for (int i = 0; i < n; i++) if (a->par[i] != b->par[i]) return a->par[i] < b->par[i] ? -1 : 1;
    if (a->nvis != b->nvis) return a->nvis < b->nvis ? -1 : 1;
    return a->slot < b->slot ? -1 : a->slot > b->slot;
}

/* Entries and their command lists live in an arena freed at the end of the
 * frame: a 70K-triangle mesh makes ~400K entries, and one malloc per list
 * (with room for 16 commands) cost most of the scan's time and ~600 MB. */
typedef struct arena_blk { struct arena_blk *next; size_t used, cap; max_align_t data[]; } arena_blk;
typedef struct arena { arena_blk *head; } arena;

static void *arena_alloc(arena *a, size_t sz)
{
    sz = (sz + sizeof(max_align_t) - 1) / sizeof(max_align_t) * sizeof(max_align_t);
    arena_blk *b = a->head;
    if (!b || b->cap - b->used < sz) {
        size_t cap = sz > ((size_t)1 << 20) ? sz : ((size_t)1 << 20);
        b = malloc(sizeof(arena_blk) + cap);
        if (!b) return NULL;
        b->next = a->head; b->used = 0; b->cap = cap;
        a->head = b;
    }
    void *p = (char *)b->data + b->used;
    b->used += sz;
    return p;
}

static void arena_free(arena *a)
{
    while (a->head) { arena_blk *n = a->head->next; free(a->head); a->head = n; }
}

/* a copy of scratch list src in the arena (src stays for reuse) */
static hsr_status arena_list(arena *a, const yp_cmdlist *src, yp_cmdlist *dst)
{
    dst->c = NULL; dst->n = dst->cap = src->n; dst->slots = src->slots;
    if (!src->n) return HSR_OK;
    if (!(dst->c = arena_alloc(a, sizeof(yp_cmd) * (size_t)src->n))) return HSR_ENOMEM;
    memcpy(dst->c, src->c, sizeof(yp_cmd) * (size_t)src->n);
    return HSR_OK;
}

typedef struct scan {
    const yp_shader *sh;
    const yp_options *o;
    yp_frame *fr;
    int W, H, y0, y1, nl;
    line_entries *le;          /* [y1 - y0][3] */
    /* scratch */
    double *fb, *fs, *ft, *cov;  /* per column: base, spec (nl), total; coverage */
    double *fx;                /* per column: texture term (3 per column) */
    unsigned char *use, *use2;
    double *tmp, *tolv;
    double *covsum;            /* [y1 - y0][W]: coverage of all patterns */
    arena ar;                  /* entries and their lists */
    yp_cmdlist wl[4], wspec, wtex;   /* scratch lists of one entry */
    yp_cmdlist wpl, wpspec, wfit;    /* and its terms without the previous frame */
} scan;

/* the options of line y: its level of detail (yp_lod.c) or the frame's */
static void line_opts(const scan *s, int y, int *maxlev, int *aa, double *tol, int *tex)
{
    if (s->o->line_lod) { yp_lod_line_options(s->o, s->o->line_lod[y], maxlev, aa, tol, tex); return; }
    *maxlev = s->o->shading == YP_FLAT ? 1 : s->o->shading == YP_GOURAUD ? 2 : 3;
    *aa = s->o->aa; *tol = s->o->tol; *tex = 1;
}

static hsr_status append(yp_cmdlist *dst, const yp_cmdlist *src);

/* Dis over the runs of [a, b) where in[x - off] == 0 */
static hsr_status push_dis(yp_cmdlist *l, const unsigned char *in, int a, int b, int off)
{
    for (int x = a; x < b;) {
        if (in[x - off]) { x++; continue; }
        int g = x;
        while (x < b && !in[x - off]) x++;
        yp_cmd d = {YP_DIS, 0, (uint16_t)g, (uint16_t)(x - g), {0, 0, 0}, 0};
        hsr_status st = yp_cmdlist_push(l, d);
        if (st != HSR_OK) return st;
    }
    return HSR_OK;
}

static int64_t q24(double v) { return llround(v * YP_ONE); }

/* one pattern on one row: layers par[0..nvis-1], coverage cov[x0..x1) */
static hsr_status row_entry(scan *s, const int *par, int nvis, int y, const double *cov, int x0, int x1)
{
    const yp_shader *sh = s->sh;
    const hsr_scene *sc = sh->sc;
    int nl = s->nl, npart = 0, lmax, laa, ltex, any_tex = 0;
    double ltol;
    line_opts(s, y, &lmax, &laa, &ltol, &ltex);
    double area = 0;
    unsigned char *full = s->use;   /* indexed by absolute column */
    for (int x = x0; x < x1; x++) {
        double c = cov[x - x0];
        full[x] = c >= 1.0;
        if (c <= 0) continue;
        area += c;
        if (!full[x]) npart++;
    }
    if (area <= 0) return HSR_OK;
    /* colour functions at the pixel centres of [x0, x1) */
    double w[HSR_MAX_PREFIX + 1], rem = 1;
    for (int j = 0; j < nvis; j++) {
        double op = sc->mat[sc->f[par[j]].material].opacity;
        if (op > 1) op = 1;
        w[j] = (j == nvis - 1 && op >= 1) ? rem : rem * op;
        rem -= w[j];
    }
    double base[3], spec[3 * HSR_MAX_LIGHTS], tex[3];
    for (int x = x0; x < x1; x++) {
        if (cov[x - x0] <= 0) continue;
        double *fb = &s->fb[3 * x], *fs = &s->fs[3 * nl * x], *fx = &s->fx[3 * x];
        for (int c = 0; c < 3; c++) fb[c] = fx[c] = 0;
        for (int i = 0; i < 3 * nl; i++) fs[i] = 0;
        for (int j = 0; j < nvis; j++) {
            yp_shade_face(sh, par[j], x + 0.5, y + 0.5, base, spec);
            for (int c = 0; c < 3; c++) fb[c] += w[j] * (base[c] - yp_bg(sh, c, x, y));
            for (int i = 0; i < 3 * nl; i++) fs[i] += w[j] * spec[i];
            if (yp_shade_texture(sh, par[j], x + 0.5, y + 0.5, tex)) {
                any_tex = 1;
                for (int c = 0; c < 3; c++) fx[c] += w[j] * tex[c];
            }
        }
        for (int c = 0; c < 3; c++) {
            double t = fb[c] + fx[c];
            for (int l = 0; l < nl; l++) t += fs[3 * l + c];
            s->ft[3 * x + c] = t;
            s->fr->ideal[((size_t)c * s->H + y) * s->W + x] += cov[x - x0] * t;
        }
        s->covsum[(size_t)(y - s->y0) * s->W + x] += cov[x - x0];
    }
    line_entries *le = &s->le[3 * (y - s->y0)];
    const unsigned term = line_term(&le[0], par, nvis, 0);
    unsigned sterm[HSR_MAX_LIGHTS];
    for (int l = 0; l < nl; l++) sterm[l] = line_term(&le[0], par, nvis, 1 + l);
    if (!term) return HSR_ENOMEM;
    for (int l = 0; l < nl; l++) if (!sterm[l]) return HSR_ENOMEM;
    int cf = -1, cl = -1;
    for (int x = x0; x < x1; x++) if (cov[x - x0] > 0) { if (cf < 0) cf = x; cl = x; }
    const int a = cf, n = cl + 1 - cf;
    unsigned char *cv = s->use2 + s->W;         /* covered, relative to a */
    for (int x = a; x <= cl; x++) cv[x - a] = cov[x - x0] > 0;
    for (int c = 0; c < 3; c++) {
        entry *e = arena_alloc(&s->ar, sizeof *e);
        if (!e) return HSR_ENOMEM;
        memset(e, 0, sizeof *e);
        line_entries *L = &le[c];
        if (L->n == L->cap) {
            int nc = L->cap ? 2 * L->cap : 32;
            entry **p = realloc(L->e, sizeof(entry *) * (size_t)nc);
            if (!p) return HSR_ENOMEM;
            L->e = p; L->cap = nc;
        }
        L->e[L->n++] = e;
        for (int i = 0; i < 4; i++) s->wl[i].n = s->wl[i].slots = 0;
        s->wspec.n = s->wspec.slots = s->wtex.n = s->wtex.slots = s->wpspec.n = s->wpspec.slots = 0;
        e->area = area; e->npart = npart;
        e->maxlev = lmax;
        /* separate specular terms (level 3): lights whose highlight on the
         * fully covered pixels exceeds the tolerance */
        int sep[HSR_MAX_LIGHTS], nsep = 0;
        for (int l = 0; l < nl; l++) {
            double mx = 0;
            if (e->maxlev == 3)
                for (int x = a; x <= cl; x++) if (full[x] && s->fs[3 * nl * x + 3 * l + c] > mx) mx = s->fs[3 * nl * x + 3 * l + c];
            sep[l] = mx > ltol;
            nsep += sep[l];
        }
        double *f = s->tmp;
        hsr_status st = HSR_OK;
        /* coherent fitting: the previous frame's line and where this pattern's terms are
         * in it (plo..phi: its colour function, before Acc_mode) */
        const yp_cmdlist *pl = s->o->prev ? &s->o->prev[c * s->H + y] : NULL;
        int plo = 0, phi = 0;
        if (pl && !L->pbuilt && !prev_spans(L, pl)) return HSR_ENOMEM;
        if (pl) prev_span(L, term, &plo, &phi);
        const double hyst = s->o->coherent ? YP_COH_HYST : 1;
        for (int lev = 1; lev <= e->maxlev && st == HSR_OK; lev++) {
            /* target: cov * colour over the covered pixels (Dis elsewhere) */
            for (int x = a; x <= cl; x++) {
                double cvx = cov[x - x0], v = 0;
                if (cvx > 0) {
                    v = s->ft[3 * x + c] - s->fx[3 * x + c];   /* the texture is its own term */
                    if (lev == 3 && full[x]) for (int l = 0; l < nl; l++) if (sep[l]) v -= s->fs[3 * nl * x + 3 * l + c];
                    v *= cvx;
                }
                f[x - a] = v;
            }
            double tol = ltol * (e->maxlev == lev ? 1 : e->maxlev - lev == 1 ? 4 : 16);
            /* partly covered pixels: a tight tolerance, so the pieces of a
             * pixel shared by several patterns add up to its box average */
            double *tv = s->tolv;
            for (int x = a; x <= cl; x++) tv[x - a] = cov[x - x0] < 1 ? fmin(tol, TOL_PARTIAL) : tol;
            /* coherent fitting: a partly covered pixel at either end of the span gets an
             * Eval1 of its own, so that the spline between them can stay when the light
             * moves (the edge pixels' tight tolerance would otherwise change its start and
             * its last knot in every frame) */
            int ea = 0, eb = 0;
            if (s->o->coherent && n > 4) {
                ea = cov[a - x0] < 1 && cv[1];
                eb = cov[cl - x0] < 1 && cv[n - 2];
            }
            /* with the previous frame's line (if any) into wl[lev] and, with one, the same
             * term without it into wpl: Dis, the fit without prev (wfit) and the edges'
             * Eval1s of this frame */
            yp_cmdlist *w = &s->wl[lev], *wp = &s->wpl;
            w->n = w->slots = wp->n = wp->slots = s->wfit.n = s->wfit.slots = 0;
            st = push_dis(w, cv, a + ea, a + n - eb, a);
            if (st == HSR_OK && pl) st = push_dis(wp, cv, a + ea, a + n - eb, a);
            if (st == HSR_OK && yp_fit_coherent(f + ea, cv + ea, tv + ea, n - ea - eb, a + ea, lev - 1, tol, 0, hyst, pl, plo, phi,
                                                term, w, pl ? &s->wfit : NULL, NULL) < 0)
                st = HSR_ELIMIT;
            if (st == HSR_OK && pl) st = append(wp, &s->wfit);
            for (int k = 0; k < 2 && st == HSR_OK; k++) {
                if (!(k ? eb : ea)) continue;
                int x = k ? cl : a;
                yp_cmd e1 = {YP_EVAL, 0, (uint16_t)x, 1, {q24(f[x - a]), 0, 0}, 0};
                if (pl) st = yp_cmdlist_push(wp, e1);
                /* the previous frame's Eval1 of this pixel (this pattern's: the pattern on
                 * the other side of the edge has one at this pixel too) stays while within
                 * cov * tol of the target: the pixel's error, summed over the patterns
                 * sharing it, stays within tol, as on a fully covered pixel */
                for (int i = plo; pl && i < phi; i++) {
                    const yp_cmd *q = &pl->c[i];
                    if (q->op == YP_EVAL && q->order == 0 && q->x == x && q->dx == 1 && q->term == term
                        && fabs((double)q->v[0] / YP_ONE - f[x - a]) <= cov[x - x0] * tol) { e1 = *q; break; }
                }
                if (st == HSR_OK) st = yp_cmdlist_push(w, e1);
            }
            set_term(w, term);
            set_term(wp, term);
            if (st == HSR_OK) st = arena_list(&s->ar, w, &e->lv[lev]);
            if (st == HSR_OK && pl) st = arena_list(&s->ar, wp, &e->plv[lev]);
            if (!pl) e->plv[lev] = e->lv[lev];
            e->cost[lev] = e->lv[lev].slots;
            e->pcost[lev] = e->plv[lev].slots;
        }
        for (int l = 0; l < nl && st == HSR_OK && nsep; l++) {
            if (!sep[l]) continue;
            int sa = -1, sb = -1;
            unsigned char *use = s->use2;
            for (int x = a; x <= cl; x++)
                if (full[x] && s->fs[3 * nl * x + 3 * l + c] > ltol) { if (sa < 0) sa = x; sb = x; }
            /* pass 0 with the previous frame's line (if any) into wspec, pass 1 without it
             * into wpspec: the fit without prev that pass 0 made (wfit) if the span did not
             * change, else a fit of its own */
            const int fa = sa, fb = sb;
            for (int pass = 0; pass < 1 + (pl != NULL) && st == HSR_OK; pass++) {
                const yp_cmdlist *pp = pass ? NULL : pl;
                yp_cmdlist *w = pass ? &s->wpspec : &s->wspec;
                const int n0 = w->n;
                if (pass && sa == fa && sb == fb) {
                    st = push_dis(w, use, sa, sb + 1, sa);
                    if (st == HSR_OK) st = append(w, &s->wfit);
                } else {
                    sa = fa; sb = fb;
                    /* coherent: a specular term of the previous frame that starts at or left
                     * of sa over fully covered pixels keeps its start (its end grows if need
                     * be), so its Sets can stay; not if it is more than twice (and 32 pixels)
                     * longer */
                    int slo = 0, shi = 0;
                    if (pp) prev_span(L, sterm[l], &slo, &shi);
                    for (int i = slo; i < shi; i++) {
                        const yp_cmd *e = &pp->c[i];
                        int ea = e->x, eb = e->x + e->dx - 1 > sb ? e->x + e->dx - 1 : sb, okr = 1;
                        if (e->op != YP_EVAL || e->order != 2 || e->term != sterm[l] || ea > sa || ea < a || eb > cl
                            || eb + 1 - ea > 2 * (sb + 1 - sa) + 32) continue;
                        for (int x = ea; x <= eb && okr; x++) okr = full[x];
                        if (okr) { sa = ea; sb = eb; break; }
                    }
                    for (int x = sa; x <= sb; x++) { f[x - sa] = full[x] ? s->fs[3 * nl * x + 3 * l + c] : 0; use[x - sa] = full[x]; }
                    s->wfit.n = s->wfit.slots = 0;
                    st = push_dis(w, use, sa, sb + 1, sa);
                    if (st == HSR_OK && yp_fit_coherent(f, use, NULL, sb + 1 - sa, sa, 2, ltol, 1, hyst, pp, slo, shi,
                                                        sterm[l], w, pp ? &s->wfit : NULL, NULL) < 0)
                        st = HSR_ELIMIT;
                }
                for (int i = n0; i < w->n; i++) w->c[i].term = (uint16_t)sterm[l];
            }
        }
        if (st == HSR_OK) st = arena_list(&s->ar, &s->wspec, &e->spec);
        if (st == HSR_OK && pl) st = arena_list(&s->ar, &s->wpspec, &e->pspec);
        if (!pl) e->pspec = e->spec;
        /* the texture term: cov * texture over the covered pixels, one Eval3 spline whose
         * knots do not depend on the lights (docs/yproc.md section 11) */
        if (st == HSR_OK && any_tex && ltex) {
            double *tv = s->tolv;
            for (int x = a; x <= cl; x++) {
                f[x - a] = cov[x - x0] > 0 ? cov[x - x0] * s->fx[3 * x + c] : 0;
                tv[x - a] = cov[x - x0] < 1 ? fmin(ltol, TOL_PARTIAL) : ltol;
            }
            st = push_dis(&s->wtex, cv, a, a + n, a);
            if (st == HSR_OK && yp_fit(f, cv, tv, n, a, 2, ltol, 0, &s->wtex) < 0) st = HSR_ELIMIT;
            set_term(&s->wtex, term);
            if (st == HSR_OK) st = arena_list(&s->ar, &s->wtex, &e->tex);
            for (int lev = 1; lev <= e->maxlev; lev++) { e->cost[lev] += e->tex.slots; e->pcost[lev] += e->tex.slots; }
        }
        if (st != HSR_OK) return st;
        e->spec_cost = e->spec.slots;
        e->pspec_cost = e->pspec.slots;
        if (e->maxlev == 3) { e->cost[3] += e->spec.slots; e->pcost[3] += e->pspec.slots; }
        e->lev = e->maxlev;
    }
    return HSR_OK;
}

static int ent_area_cmp(const void *pa, const void *pb)
{
    const entry *a = *(entry *const *)pa, *b = *(entry *const *)pb;
    return a->area < b->area ? -1 : a->area > b->area;
}

/* slots of the line at the entries' levels: their terms (plain 0) or those fitted
 * without the previous frame (plain 1) */
static int line_cost(entry **e, int n, int *spec, int base, int plain)
{
    int t = base, sp = 0;
    for (int i = 0; i < n; i++) {
        t += plain ? e[i]->pcost[e[i]->lev] : e[i]->cost[e[i]->lev];
        if (e[i]->lev == 3 && (plain ? e[i]->pspec_cost : e[i]->spec_cost)) sp = 1;
    }
    if (spec) *spec = sp;
    return t + sp;
}

/* src's commands after dst's: one copy (n and slots of a list are kept by
 * yp_cmdlist_push, so the sum of the two is dst's new slot count) */
static hsr_status append(yp_cmdlist *dst, const yp_cmdlist *src)
{
    if (!src->n) return HSR_OK;
    if (dst->n + src->n > dst->cap) {
        int nc = dst->cap ? dst->cap : 16;
        while (nc < dst->n + src->n) nc *= 2;
        yp_cmd *p = realloc(dst->c, sizeof(yp_cmd) * (size_t)nc);
        if (!p) return HSR_ENOMEM;
        dst->c = p; dst->cap = nc;
    }
    memcpy(dst->c + dst->n, src->c, sizeof(yp_cmd) * (size_t)src->n);
    dst->n += src->n;
    dst->slots += src->slots;
    return HSR_OK;
}

/* Background image (section 7.4.5: Eval0 carries raster images): pixels
 * no pattern covers get Eval0 runs of equal 12-bit values (D := I and
 * locked, 1 slot per run); under the covered pixels the image + 1/2 is
 * accumulated as a spline (the patterns add cov * (colour - image)). */
static hsr_status background_image(scan *s, int y, int c, yp_cmdlist *out)
{
    const double *cs = &s->covsum[(size_t)(y - s->y0) * s->W];
    hsr_status st = HSR_OK;
    int first = -1, last = -1;
    for (int x = 0; x < s->W && st == HSR_OK;) {
        if (cs[x] > 0) { if (first < 0) first = x; last = x; x++; continue; }
        int v = (int)lround(yp_bg(s->sh, c, x, y)), a = x;
        while (x < s->W && cs[x] <= 0 && (int)lround(yp_bg(s->sh, c, x, y)) == v) x++;
        yp_cmd e0 = {YP_EVAL0, 0, (uint16_t)a, (uint16_t)(x - a), {v, 0, 0}, 0};
        st = yp_cmdlist_push(out, e0);
    }
    if (first < 0 || st != HSR_OK) return st;
    int n = last + 1 - first;
    double *f = s->tmp;
    unsigned char *use = s->use2;
    for (int x = first; x <= last; x++) { use[x - first] = cs[x] > 0; f[x - first] = yp_bg(s->sh, c, x, y) + 0.5; }
    st = push_dis(out, use, first, last + 1, first);
    if (st == HSR_OK && yp_fit(f, use, NULL, n, first, 2, 0.25, 0, out) < 0) st = HSR_ELIMIT;
    return st;
}

/* 1 if a pixel of the line would differ from its exact value by more
 * than half the range (the 12-bit pixel wrapped) */
static int wraps(scan *s, const yp_cmdlist *l, int y, int c)
{
    uint16_t *pix = malloc(sizeof(uint16_t) * (size_t)s->W);
    if (!pix) return 0;
    if (yp_simulate_line(l, s->W, pix) != HSR_OK) { free(pix); return 0; }   /* as without pix */
    const double *id = &s->fr->ideal[((size_t)c * s->H + y) * s->W];
    int bad = 0;
    for (int x = 0; x < s->W && !bad; x++) bad = fabs(pix[x] - id[x]) > 2048;
    free(pix);
    return bad;
}

/* degrade and emit line y, colour c */
static hsr_status finish_line(scan *s, int y, int c)
{
    line_entries *L = &s->le[3 * (y - s->y0) + c];
    yp_line_stats *ls = &s->fr->st[y];
    int n = L->n, sp;
    /* the background term first: its slots count against the line */
    yp_cmdlist bgl = {0};
    hsr_status st0;
    if (!s->sh->img) {
        yp_cmd bg = {YP_EVAL, 0, 0, (uint16_t)s->W, {q24(s->sh->bg[c] + 0.5), 0, 0}, 0};
        st0 = yp_cmdlist_push(&bgl, bg);
    } else st0 = background_image(s, y, c, &bgl);
    entry **ord = malloc(sizeof(entry *) * (size_t)(n + 1));
    if (!ord || st0 != HSR_OK) { free(ord); yp_cmdlist_free(&bgl); return st0 != HSR_OK ? st0 : HSR_ENOMEM; }
    if (n) memcpy(ord, L->e, sizeof(entry *) * (size_t)n);
    qsort(ord, (size_t)n, sizeof(entry *), ent_area_cmp);
    /* section 7.5: lower the colour function of the least visible
     * patterns first, Eval3 -> Eval2 for all, then Eval2 -> Eval1 */
    /* the line's cost (line_cost) is kept up to date as patterns are lowered,
     * not recounted per pattern: O(n) instead of O(n^2) on a busy line.  With a previous
     * frame (coherent fitting) the levels are chosen on the costs of the terms fitted
     * without it: they depend on this frame only, so a line fitted again against its own
     * commands gets the same levels (docs/yproc.md section 11.1) */
    int sum = bgl.slots, nsp = 0;
    for (int i = 0; i < n; i++) {
        sum += L->e[i]->pcost[L->e[i]->lev];
        nsp += L->e[i]->lev == 3 && L->e[i]->pspec_cost;
    }
    for (int lev = 3; lev >= 2 && !s->o->no_degrade && sum + (nsp > 0) > s->o->capacity; lev--)
        for (int i = 0; i < n && sum + (nsp > 0) > s->o->capacity; i++)
            if (ord[i]->lev == lev && ord[i]->pcost[lev - 1] < ord[i]->pcost[lev]) {
                sum -= ord[i]->pcost[lev] - ord[i]->pcost[lev - 1];
                if (lev == 3 && ord[i]->pspec_cost) nsp--;
                ord[i]->lev = lev - 1;
            }
    free(ord);
    ls->degraded[c] = 0;
    for (int i = 0; i < n; i++) if (L->e[i]->lev < L->e[i]->maxlev) ls->degraded[c]++;
    yp_cmdlist *out = &s->fr->line[c * s->H + y];
    yp_cmdlist_free(out);
    hsr_status st = HSR_OK;
    ls->merged[c] = ls->overflow[c] = 0;
    /* the line of the terms (coherent: kept from the previous frame where they still fit)
     * and, if it does not fit or wraps, with a previous frame, the line of the terms fitted
     * without it, which the levels were chosen for */
    int done = 0;
    for (int plain = 0; plain <= (s->o->prev != NULL) && !done && st == HSR_OK; plain++) {
        int cost = line_cost(L->e, n, &sp, bgl.slots, plain);
        if (cost > s->o->capacity && !s->o->no_degrade) continue;
        yp_cmdlist_free(out);
        st = append(out, &bgl);
        for (int i = 0; i < n && st == HSR_OK; i++) {
            st = append(out, plain ? &L->e[i]->plv[L->e[i]->lev] : &L->e[i]->lv[L->e[i]->lev]);
            if (st == HSR_OK) st = append(out, &L->e[i]->tex);
        }
        if (sp && st == HSR_OK) {
            yp_cmd am = {YP_ACCMODE, 0, 0, 0, {1, 0, 0}, 0};
            st = yp_cmdlist_push(out, am);
            for (int i = 0; i < n && st == HSR_OK; i++)
                if (L->e[i]->lev == 3) st = append(out, plain ? &L->e[i]->pspec : &L->e[i]->spec);
        }
        /* The array wraps (docs/isa.md section 1): a pixel whose exact value
         * is within the fit tolerance of 0 or 4096 could come out as its
         * opposite.  Check the line with the array model; if it happens, the
         * line takes the merged form below, whose targets keep clear of both. */
        if (st == HSR_OK && wraps(s, out, y, c)) continue;
        if (cost > s->o->capacity) ls->overflow[c] = 1;   /* no_degrade: as is, the controller drops it */
        done = 1;
    }
    if (st == HSR_OK && !done) {
        /* Even Eval1 for every pattern does not fit: the last resort
         * before dropping anything is one spline for the whole line
         * through the exact target values, with a tolerance raised until
         * it fits (every pattern still contributes; the line is reported). */
        double *f = s->tmp;
        unsigned char *use = s->use2;
        const double *id = &s->fr->ideal[((size_t)c * s->H + y) * s->W];
        for (double tol = 4 * s->o->tol; tol < 8192; tol *= 2) {
            for (int x = 0; x < s->W; x++) { f[x] = fmin(fmax(id[x] + 0.5, 0.5 + tol), 4095.5 - tol); use[x] = 1; }
            yp_cmdlist_free(out);
            if (yp_fit(f, use, NULL, s->W, 0, 2, tol, 0, out) < 0) { st = HSR_ELIMIT; break; }
            if (out->slots <= s->o->capacity) break;
        }
        ls->merged[c] = 1;
        ls->degraded[c] = n;
        ls->overflow[c] = out->slots > s->o->capacity;
    }
    yp_cmdlist_free(&bgl);
    ls->cmds[c] = out->n; ls->slots[c] = out->slots;
    if (c == 0) {
        ls->patterns = n; ls->partial = 0;
        for (int i = 0; i < n; i++) ls->partial += L->e[i]->npart;
    }
    return st;
}

/* the frame's command counts of lines y0..y1-1 added (sign 1) or taken away (-1):
 * a scan of some lines takes their old counts away first and adds the new ones, so
 * the totals stay those of the whole frame without a pass over every line */
static void count_lines(yp_frame *fr, int y0, int y1, int sign)
{
    for (int c = 0; c < 3; c++)
        for (int y = y0; y < y1; y++) {
            const yp_cmdlist *l = &fr->line[c * fr->height + y];
            int after = 0;
            for (int k = 0; k < l->n; k++) {
                const yp_cmd *m = &l->c[k];
                if (m->op == YP_EVAL) { fr->n_eval[m->order + 1] += sign; if (after) fr->n_spec += sign; }
                else if (m->op == YP_EVAL0) fr->n_eval[0] += sign;
                else if (m->op == YP_SETDDI) fr->n_knots += sign;
                else if (m->op == YP_DIS) fr->n_dis += sign;
                else if (m->op == YP_ACCMODE) after = 1;
            }
        }
    for (int y = y0; y < y1; y++) fr->n_partial += sign * 3 * fr->st[y].partial;
}

hsr_status yp_scan(const yp_shader *sh, const hsr_ctx *h, const yp_options *o, int y0, int y1, yp_frame *fr)
{
    if (!sh || !h || !o || !fr || fr->width != sh->sc->width || fr->height != sh->sc->height) return HSR_EINVAL;
    if (y0 < 0) y0 = 0;
    if (y1 > fr->height) y1 = fr->height;
    if (y0 >= y1) return HSR_OK;
    scan s;
    memset(&s, 0, sizeof s);
    s.sh = sh; s.o = o; s.fr = fr; s.W = fr->width; s.H = fr->height; s.y0 = y0; s.y1 = y1; s.nl = sh->nl;
    const int W = s.W;
    const double U = HSR_SUBPIXEL;
    hsr_status st = HSR_OK;
    int nslots = hsr_llr_slots(h), nk = 0;
    key *keys = malloc(sizeof(key) * (size_t)(nslots + 1));
    s.le = calloc(3 * (size_t)(y1 - y0), sizeof(line_entries));
    s.fb = malloc(sizeof(double) * 3 * (size_t)W);
    s.fs = malloc(sizeof(double) * 3 * (size_t)(s.nl + 1) * (size_t)W);
    s.ft = malloc(sizeof(double) * 3 * (size_t)W);
    s.fx = calloc(3 * (size_t)W, sizeof(double));
    s.tmp = malloc(sizeof(double) * (size_t)W);
    s.tolv = malloc(sizeof(double) * (size_t)W);
    s.covsum = calloc((size_t)(y1 - y0) * (size_t)W, sizeof(double));
    s.use = malloc((size_t)W + 1); s.use2 = malloc(2 * (size_t)W + 2);
    double *acc = NULL;
    size_t acccap = 0;
    unsigned char *mark = malloc((size_t)W + 2);   /* point samples: centres to test exactly */
    if (!keys || !s.le || !s.fb || !s.fs || !s.ft || !s.fx || !s.tmp || !s.tolv || !s.covsum || !s.use || !s.use2 || !mark) { st = HSR_ENOMEM; goto done; }
    for (int y = y0; y < y1; y++)
        for (int c = 0; c < 3; c++)
            for (int x = 0; x < W; x++) fr->ideal[((size_t)c * s.H + y) * W + x] = yp_bg(sh, c, x, y);
    for (int sl = 0; sl < nslots; sl++) {
        const int *par; int nvis;
        if (hsr_llr_get(h, sl, NULL, &par, &nvis, NULL)) { keys[nk].slot = sl; keys[nk].par = par; keys[nk].nvis = nvis; nk++; }
    }
    qsort(keys, (size_t)nk, sizeof(key), key_cmp);
    for (int g = 0; g < nk && st == HSR_OK;) {
        int ge = g + 1;
        while (ge < nk && keys[ge].nvis == keys[g].nvis && !memcmp(keys[ge].par, keys[g].par, sizeof(int) * (size_t)keys[g].nvis)) ge++;
        /* pixel box of the group, clipped to the lines asked for */
        int64_t l = INT64_MAX, b = INT64_MAX, r = INT64_MIN, t = INT64_MIN;
        for (int i = g; i < ge; i++) {
            const hsr_domain *d; hsr_llr_get(h, keys[i].slot, &d, NULL, NULL, NULL);
            hsr_extent e = hsr_domain_extent(d);
            if (e.left < l) l = e.left;
            if (e.bot < b) b = e.bot;
            if (e.right > r) r = e.right;
            if (e.top > t) t = e.top;
        }
        int gx0 = (int)floor(l / U), gx1 = (int)ceil(r / U), gy0 = (int)floor(b / U), gy1 = (int)ceil(t / U);
        if (gx0 < 0) gx0 = 0;
        if (gx1 > W) gx1 = W;
        int ry0 = gy0 > y0 ? gy0 : y0, ry1 = gy1 < y1 ? gy1 : y1;
        if (gy0 < 0) gy0 = 0;
        if (gx0 >= gx1 || ry0 >= ry1) { g = ge; continue; }
        int nx = gx1 - gx0, ny = gy1 - gy0;
        size_t need = (size_t)ny * (size_t)(nx + 2);
        if (need > acccap) {
            double *p = realloc(acc, sizeof(double) * need);
            if (!p) { st = HSR_ENOMEM; break; }
            acc = p; acccap = need;
        }
        memset(acc, 0, sizeof(double) * need);
        /* anti-aliasing per line (its level of detail): area coverage if any line of the
         * group has it, then point samples on the lines that do not */
        int need_aa = 0, need_pt = 0;
        for (int y = ry0; y < ry1; y++) {
            int ml, laa, ltx; double lt;
            line_opts(&s, y, &ml, &laa, &lt, &ltx);
            if (laa) need_aa = 1; else need_pt = 1;
        }
        if (need_aa) {
            for (int i = g; i < ge && st == HSR_OK; i++) {
                const hsr_domain *d; hsr_llr_get(h, keys[i].slot, &d, NULL, NULL, NULL);
                double *xy = NULL; int *len = NULL, nr = 0;
                st = hsr_domain_rings(d, &xy, &len, &nr);
                if (st != HSR_OK) break;
                for (int rr = 0, off = 0; rr < nr; off += len[rr], rr++) {
                    for (int k = 0; k < len[rr]; k++) {
                        xy[2 * (off + k)] = xy[2 * (off + k)] / U - gx0;
                        xy[2 * (off + k) + 1] = xy[2 * (off + k) + 1] / U - gy0;
                    }
                    yp_cover_ring(xy + 2 * off, len[rr], acc, nx, ny);
                }
                free(xy); free(len);
            }
            /* orientation: outer rings have positive area; fix the sign */
            double sg = 0;
            for (int yy = 0; yy < ny; yy++) { double run = 0; for (int x = 0; x < nx; x++) { run += acc[(size_t)yy * (nx + 2) + x]; sg += run; } }
            sg = sg < 0 ? -1 : 1;
            for (int yy = 0; yy < ny; yy++) {
                double run = 0, *row = &acc[(size_t)yy * (nx + 2)];
                for (int x = 0; x < nx; x++) {
                    run += row[x];
                    double cv = round(sg * run * COV_Q) / COV_Q;
                    row[x] = cv < 0 ? 0 : cv > 1 ? 1 : cv;
                }
            }
        }
        /* point samples: a pixel is in if a domain of the group contains its centre; only
         * the centres inside a domain's extent (a closed box around it) are tested */
        for (int yy = ry0 - gy0; need_pt && yy < ry1 - gy0; yy++) {
            int ml, laa, ltx; double lt;
            line_opts(&s, gy0 + yy, &ml, &laa, &lt, &ltx);
            if (laa) continue;
            double *row = &acc[(size_t)yy * (nx + 2)];
            memset(row, 0, sizeof(double) * (size_t)(nx + 2));
            int64_t py = (int64_t)(gy0 + yy) * HSR_SUBPIXEL + HSR_SUBPIXEL / 2;
            for (int i = g; i < ge; i++) {
                const hsr_domain *d; hsr_llr_get(h, keys[i].slot, &d, NULL, NULL, NULL);
                hsr_extent e = hsr_domain_extent(d);
                if (py < e.bot || py > e.top) continue;
                /* pixel x's centre is (gx0 + x) * S + S / 2: the x with centres in [left, right] */
                int64_t xa = e.left - (int64_t)gx0 * HSR_SUBPIXEL - HSR_SUBPIXEL / 2;
                int64_t xb = e.right - (int64_t)gx0 * HSR_SUBPIXEL - HSR_SUBPIXEL / 2;
                int x0 = xa <= 0 ? 0 : (int)((xa + HSR_SUBPIXEL - 1) / HSR_SUBPIXEL);
                int x1 = xb < 0 ? -1 : (int)(xb / HSR_SUBPIXEL);
                if (x1 > nx - 1) x1 = nx - 1;
                if (x0 > x1) continue;
                /* the centres near an edge crossing the row (its x at py in doubles, +-2 px,
                 * or the whole x range of an edge within a unit of horizontal) are tested
                 * exactly; between them no edge crosses, so a run takes its first centre's
                 * answer */
                memset(mark + x0, 0, (size_t)(x1 - x0 + 1));
                for (int k = 0, ne = hsr_domain_edge_count(d); k < ne; k++) {
                    double sg4[4];
                    if (hsr_domain_edge(d, k, sg4) != HSR_OK) { memset(mark + x0, 1, (size_t)(x1 - x0 + 1)); break; }
                    double ya = fmin(sg4[1], sg4[3]), yb = fmax(sg4[1], sg4[3]), za, zb;
                    if ((double)py < ya - 1 || (double)py > yb + 1) continue;
                    if (yb - ya < 1) { za = fmin(sg4[0], sg4[2]); zb = fmax(sg4[0], sg4[2]); }
                    else {
                        double xc = sg4[0] + ((double)py - sg4[1]) * (sg4[2] - sg4[0]) / (sg4[3] - sg4[1]);
                        za = zb = fmin(fmax(xc, fmin(sg4[0], sg4[2])), fmax(sg4[0], sg4[2]));
                    }
                    double ia = floor((za - 2 * U) / U) - gx0 - 1, ib = ceil((zb + 2 * U) / U) - gx0 + 1;
                    int a0 = ia < x0 ? x0 : (int)ia, b0 = ib > x1 ? x1 : (int)ib;
                    if (a0 <= b0) memset(mark + a0, 1, (size_t)(b0 - a0 + 1));
                }
                for (int x = x0; x <= x1;) {
                    int64_t px = (int64_t)(gx0 + x) * HSR_SUBPIXEL + HSR_SUBPIXEL / 2;
                    if (mark[x]) {
                        if (row[x] == 0 && hsr_domain_contains(d, px, py)) row[x] = 1;
                        x++;
                        continue;
                    }
                    int in = hsr_domain_contains(d, px, py);
                    for (; x <= x1 && !mark[x]; x++) if (in) row[x] = 1;
                }
            }
        }
        for (int y = ry0; y < ry1 && st == HSR_OK; y++)
            st = row_entry(&s, keys[g].par, keys[g].nvis, y, &acc[(size_t)(y - gy0) * (nx + 2)], gx0, gx1);
        g = ge;
    }
    count_lines(fr, y0, y1, -1);
    for (int y = y0; y < y1 && st == HSR_OK; y++)
        for (int c = 0; c < 3 && st == HSR_OK; c++) st = finish_line(&s, y, c);
    count_lines(fr, y0, y1, 1);
done:
    if (s.le) {
        for (int i = 0; i < 3 * (y1 - y0); i++) {
            free(s.le[i].e); free(s.le[i].term); free(s.le[i].ps);
        }
    }
    arena_free(&s.ar);
    for (int i = 0; i < 4; i++) yp_cmdlist_free(&s.wl[i]);
    yp_cmdlist_free(&s.wpl); yp_cmdlist_free(&s.wpspec); yp_cmdlist_free(&s.wfit);
    yp_cmdlist_free(&s.wspec); yp_cmdlist_free(&s.wtex); free(s.fx);
    free(s.le); free(keys); free(acc); free(mark); free(s.fb); free(s.fs); free(s.ft); free(s.tmp); free(s.tolv); free(s.covsum); free(s.use); free(s.use2);
    return st;
}
