/* yp_tess.c - tessellation as a level of detail (docs/yproc.md section 10): coarser
 * versions of an object made at load time by vertex clustering on a grid (Rossignac and
 * Borrel 1993: every vertex moves to the mean of the vertices in its grid cell, faces
 * that lose a corner vanish), appended to the scene as obj statements of their own.  One
 * version of each object is shown; the others follow its moves but are parked behind the
 * eye (clipped away: empty domains), so a switch is an ordinary move for the incremental
 * HSR and a full rebuild of the scene gives the same picture.  The .anim statement:
 *   tessellation OBJ CELL [VERSIONS]     # versions 1.. by clustering with cells CELL, 2 CELL, ...
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

#define PARK 1e6          /* world units behind the eye where a hidden version waits */

typedef struct tfam {
    int obj[YP_TESS_MAX]; int n, cur, since;
    int block[YP_TESS_MAX], backoff[YP_TESS_MAX];
} tfam;
struct yp_tess { tfam *f; int n; };

void yp_tess_free(yp_tess *t) { if (t) { free(t->f); free(t); } }
int yp_tess_count(const yp_tess *t) { return t ? t->n : 0; }
int yp_tess_versions(const yp_tess *t, int k) { return t && k >= 0 && k < t->n ? t->f[k].n : 0; }
int yp_tess_get(const yp_tess *t, int k) { return t && k >= 0 && k < t->n ? t->f[k].cur : 0; }
int yp_tess_obj(const yp_tess *t, int k, int v)
{
    return t && k >= 0 && k < t->n && v >= 0 && v < t->f[k].n ? t->f[k].obj[v] : -1;
}

hsr_status yp_tess_set(yp_tess *t, int k, int v)
{
    if (!t || k < 0 || k >= t->n || v < 0 || v >= t->f[k].n) return HSR_EINVAL;
    if (t->f[k].cur != v) t->f[k].since = 0;
    t->f[k].cur = v;
    return HSR_OK;
}

typedef struct cell { long long key; int id; } cell;
static int cell_cmp(const void *a, const void *b)
{
    long long x = ((const cell *)a)->key, y = ((const cell *)b)->key;
    return x < y ? -1 : x > y;
}

/* append to sc a version of obj statement `obj` clustered with cell size c (world
 * units) as a new obj statement (its index sc->nobj - 1); faces: its face count */
static hsr_status cluster(hsr_scene *sc, int obj, double c, int *faces, char *err, size_t errlen)
{
    int nv = sc->nv;
    int *map = malloc(sizeof(int) * (size_t)(nv + 1));
    cell *cl = malloc(sizeof(cell) * (size_t)(nv + 1));
    if (!map || !cl) { free(map); free(cl); return HSR_ENOMEM; }
    double lo[3] = {INFINITY, INFINITY, INFINITY};
    for (int fi = 0; fi < sc->nf; fi++) {
        if (sc->f[fi].obj != obj) continue;
        for (int i = 0; i < sc->f[fi].count; i++)
            for (int k = 0; k < 3; k++) lo[k] = fmin(lo[k], sc->v[3 * sc->fv[sc->f[fi].first + i] + k]);
    }
    for (int v = 0; v < nv; v++) map[v] = -1;
    int m = 0;
    for (int fi = 0; fi < sc->nf; fi++) {
        if (sc->f[fi].obj != obj) continue;
        for (int i = 0; i < sc->f[fi].count; i++) {
            int v = sc->fv[sc->f[fi].first + i];
            if (map[v] != -1) continue;
            map[v] = -2;
            long long ix = (long long)floor((sc->v[3 * v] - lo[0]) / c), iy = (long long)floor((sc->v[3 * v + 1] - lo[1]) / c),
                      iz = (long long)floor((sc->v[3 * v + 2] - lo[2]) / c);
            cl[m].key = (ix << 42) | (iy << 21) | iz;
            cl[m].id = v;
            m++;
        }
    }
    qsort(cl, (size_t)m, sizeof(cell), cell_cmp);
    /* cluster ids in key order; representative = mean of the cluster's vertices */
    int nc = 0;
    double *rep = calloc(3 * (size_t)(m + 1), sizeof(double));
    int *cnt = calloc((size_t)(m + 1), sizeof(int));
    if (!rep || !cnt) { free(map); free(cl); free(rep); free(cnt); return HSR_ENOMEM; }
    for (int i = 0; i < m; i++) {
        if (i && cl[i].key != cl[i - 1].key) nc++;
        int v = cl[i].id;
        map[v] = nc;
        for (int k = 0; k < 3; k++) rep[3 * nc + k] += sc->v[3 * v + k];
        cnt[nc]++;
    }
    if (m) nc++;
    /* the OBJ text of the clustered faces, parsed like an obj statement's file */
    size_t cap = 64 + (size_t)nc * 64 + (size_t)sc->nf * 48, len = 0;
    char *txt = malloc(cap);
    hsr_status st = txt ? HSR_OK : HSR_ENOMEM;
#define PUT(...) do { if (st == HSR_OK) { if (cap - len < 256) { cap *= 2; char *p_ = realloc(txt, cap); if (!p_) { st = HSR_ENOMEM; break; } txt = p_; } \
    len += (size_t)snprintf(txt + len, cap - len, __VA_ARGS__); } } while (0)
    for (int i = 0; i < nc; i++) PUT("v %.9g %.9g %.9g\n", rep[3 * i] / cnt[i], rep[3 * i + 1] / cnt[i], rep[3 * i + 2] / cnt[i]);
    int mat = -1, smooth = -2, nfo = 0;
    for (int fi = 0; fi < sc->nf && st == HSR_OK; fi++) {
        const hsr_face *f = &sc->f[fi];
        if (f->obj != obj) continue;
        int q[64], n = 0;
        for (int i = 0; i < f->count && n < 64; i++) {
            int id = map[sc->fv[f->first + i]];
            if (n && q[n - 1] == id) continue;
            q[n++] = id;
        }
        while (n > 1 && q[n - 1] == q[0]) n--;
        if (n < 3) continue;
        int distinct = 1;
        for (int i = 0; i < n && distinct; i++) for (int j = i + 1; j < n; j++) if (q[i] == q[j]) { distinct = 0; break; }
        if (!distinct) continue;
        if (f->material != mat) { mat = f->material; PUT("usemtl %s\n", sc->mat[mat].name); }
        int sm = f->smooth == 0 ? 0 : 1;
        if (sm != smooth) { smooth = sm; PUT(sm ? "s 1\n" : "s off\n"); }
        /* a fan of triangles: a clustered polygon need not be planar any more */
        for (int i = 1; i + 1 < n; i++) { PUT("f %d %d %d\n", q[0] + 1, q[i] + 1, q[i + 1] + 1); nfo++; }
    }
#undef PUT
    free(map); free(cl); free(rep); free(cnt);
    if (st == HSR_OK) {
        int nf0 = sc->nf, mat0 = 0;
        for (int fi = 0; fi < sc->nf; fi++) if (sc->f[fi].obj == obj) { mat0 = sc->f[fi].material; break; }
        char name[64];
        snprintf(name, sizeof name, "<tessellation of obj %d, cell %g>", obj, c);
        st = hsr_obj_parse(sc, txt, name, mat0, err, errlen);
        for (int i = nf0; st == HSR_OK && i < sc->nf; i++) sc->f[i].obj = sc->nobj;
        if (st == HSR_OK) sc->nobj++;
        *faces = sc->nf - nf0;
    }
    free(txt);
    return st;
}

int yp_tess_parse(yp_tess **tp, hsr_scene *sc, char **tok, int nt, char *msg, size_t msglen)
{
    if (strcmp(tok[0], "tessellation")) return 0;
    double o, c, nv = 3;
    if ((nt != 3 && nt != 4) || !hsr_text_num(tok[1], &o) || !hsr_text_num(tok[2], &c) || (nt == 4 && !hsr_text_num(tok[3], &nv))) {
        snprintf(msg, msglen, "expected 'tessellation OBJ CELL [VERSIONS]'");
        return -1;
    }
    if (o != (int)o || o < 0 || o >= sc->nobj) { snprintf(msg, msglen, "object %s does not exist (%d obj lines)", tok[1], sc->nobj); return -1; }
    if (!(c > 0)) { snprintf(msg, msglen, "CELL must be > 0"); return -1; }
    if (nv != (int)nv || nv < 2 || nv > YP_TESS_MAX) { snprintf(msg, msglen, "VERSIONS must be 2..%d (the object's own mesh included)", YP_TESS_MAX); return -1; }
    yp_tess *t = *tp;
    if (!t && !(t = *tp = calloc(1, sizeof *t))) { snprintf(msg, msglen, "out of memory"); return -1; }
    for (int k = 0; k < t->n; k++)
        for (int v = 0; v < t->f[k].n; v++)
            if (t->f[k].obj[v] == (int)o) { snprintf(msg, msglen, "object %d has a tessellation statement already", (int)o); return -1; }
    tfam *p = realloc(t->f, sizeof(tfam) * (size_t)(t->n + 1));
    if (!p) { snprintf(msg, msglen, "out of memory"); return -1; }
    t->f = p;
    tfam *f = &t->f[t->n];
    memset(f, 0, sizeof *f);
    f->obj[0] = (int)o;
    f->n = 1;

    for (int v = 1; v < (int)nv; v++) {
        int faces = 0;
        char e[256] = "";
        if (cluster(sc, (int)o, c * (1 << (v - 1)), &faces, e, sizeof e) != HSR_OK) { snprintf(msg, msglen, "clustering failed: %s", e); return -1; }
        f->obj[f->n++] = sc->nobj - 1;
    }
    t->n++;
    return 1;
}

void yp_tess_offsets(const yp_tess *t, const hsr_scene *sc, double *off)
{
    if (!t) return;
    double w[3], n = 0;
    for (int k = 0; k < 3; k++) { w[k] = sc->eye[k] - sc->at[k]; n += w[k] * w[k]; }
    n = sqrt(n);
    for (int k = 0; k < 3; k++) w[k] = n > 0 ? w[k] / n : (k == 2);
    for (int i = 0; i < t->n; i++) {
        const tfam *f = &t->f[i];
        double m[3] = {off[3 * f->obj[0]], off[3 * f->obj[0] + 1], off[3 * f->obj[0] + 2]};   /* the object's move */
        for (int v = 0; v < f->n; v++) {
            double *o = &off[3 * f->obj[v]];
            for (int k = 0; k < 3; k++) o[k] = m[k] + (v != f->cur ? PARK * w[k] : 0);
        }
    }
}

/* the rows the version shown of object k covers in h (y0 == y1: none) */
static void fam_rows(const yp_tess *t, int k, const hsr_scene *sc, const hsr_ctx *h, int *y0, int *y1)
{
    int ob = t->f[k].obj[t->f[k].cur], H = sc->height;
    *y0 = H; *y1 = 0;
    for (int fi = 0; fi < sc->nf; fi++) {
        const hsr_domain *d;
        if (sc->f[fi].obj != ob || !hsr_mlr_get(h, fi, &d, NULL, NULL, NULL, NULL) || hsr_domain_is_empty(d)) continue;
        hsr_extent e = hsr_domain_extent(d);
        int a = (int)floor((double)e.bot / HSR_SUBPIXEL), b = (int)ceil((double)e.top / HSR_SUBPIXEL) + 1;
        if (a < *y0) *y0 = a;
        if (b > *y1) *y1 = b;
    }
    if (*y0 < 0) *y0 = 0;
    if (*y1 > H) *y1 = H;
    if (*y0 >= *y1) *y0 = *y1 = 0;
}

#define TPROBE 6     /* frames at a version before the finer one is tried */
#define TBACK0 4     /* frames a finer version waits after it did not fit (doubling) */

int yp_tess_coarsen(yp_tess *t, const hsr_scene *sc, const hsr_ctx *h, const unsigned char *stuck, int frame)
{
    int n = 0;
    for (int k = 0; t && k < t->n; k++) {
        tfam *f = &t->f[k];
        if (f->cur + 1 >= f->n) continue;
        int y0, y1, hit = 0;
        fam_rows(t, k, sc, h, &y0, &y1);
        for (int y = y0; y < y1 && !hit; y++) hit = stuck[y];
        if (!hit) continue;
        /* the finer version did not fit: it waits, longer at each failed try */
        f->backoff[f->cur] = f->backoff[f->cur] ? 2 * f->backoff[f->cur] : TBACK0;
        if (f->backoff[f->cur] > 256) f->backoff[f->cur] = 256;
        f->block[f->cur] = frame + f->backoff[f->cur];
        f->cur++;
        f->since = 0;
        n++;
    }
    return n;
}


int yp_tess_refine(yp_tess *t, const hsr_scene *sc, const hsr_ctx *h, const unsigned char *line_lod, int frame)
{
    int n = 0;
    for (int k = 0; t && k < t->n; k++) {
        tfam *f = &t->f[k];
        f->since++;
        if (f->cur == 0 || f->since < TPROBE || frame < f->block[f->cur - 1]) continue;
        /* the finer mesh is tried (the check before emission makes the object coarser again
         * if a line then does not fit at level 0, and the finer mesh waits twice as long),
         * unless a line of the object is at level 0 now: what the coarser mesh needs level 0
         * for, the finer one cannot carry */
        int y0, y1, low = 0;
        fam_rows(t, k, sc, h, &y0, &y1);
        for (int y = y0; y < y1 && !low; y++) low = line_lod[y] == 0;
        if (low) continue;
        f->cur--;
        f->since = 0;
        n++;
    }
    return n;
}

/* yp_lod_fit with tessellation (yproc anim --lod-predict): lines over the capacity are lowered and
 * re-scanned (yp_lod_fit); lines still over at level 0 make the objects with coarser
 * versions on them one version coarser (yp_tess_coarsen), the frame is applied again (the
 * switch is a move for the incremental HSR) and its damaged lines re-scanned, until every
 * line fits or nothing can be made coarser.  [*y0, *y1) is widened by what was re-scanned. */
hsr_status yp_lod_fit_anim(yp_lod *lod, yp_anim *an, int f, hsr_ctx *h, yp_shader *sh, const yp_options *o,
                           yp_frame *fr, int *lowered, int *coarsened, int *y0, int *y1)
{
    if (!lod || !an || !h || !sh || !o || !fr || !lowered || !coarsened || !y0 || !y1) return HSR_EINVAL;
    yp_tess *tess = yp_anim_tess(an);
    int H = fr->height;
    unsigned char *stuck = malloc((size_t)H + 1);
    if (!stuck) return HSR_ENOMEM;
    hsr_status st = HSR_OK;
    *lowered = *coarsened = 0;
    for (int it = 0; it < 4 * YP_TESS_MAX && st == HSR_OK; it++) {
        int low = 0, any = 0;
        st = yp_lod_fit(lod, sh, h, o, fr, &low, y0, y1);
        *lowered += low;
        if (st != HSR_OK || !tess) break;
        for (int y = 0; y < H; y++) {
            stuck[y] = 0;
            for (int c = 0; c < 3; c++) stuck[y] |= fr->st[y].slots[c] > o->capacity;
            any |= stuck[y];
        }
        int n = any ? yp_tess_coarsen(tess, yp_anim_scene(an), h, stuck, f) : 0;
        if (!n) break;
        *coarsened += n;
        int d0 = 0, d1 = 0;
        st = yp_anim_apply(an, f, h, sh, &d0, &d1);
        if (st == HSR_OK && d0 < d1) {
            st = yp_scan(sh, h, o, d0, d1, fr);
            if (*y0 >= *y1) { *y0 = d0; *y1 = d1; }
            if (d0 < *y0) *y0 = d0;
            if (d1 > *y1) *y1 = d1;
        }
    }
    free(stuck);
    return st;
}

