/* yp_shade.c - the shading model of docs/shading.md: corner normals
 * (authored `vn`, smoothing groups, smooth vertex normals), directional and point lights (yp_shader_set_point_light), Phong illumination (eq. 6.1.a with the
 * surface coefficients of Foley 90), two-sided, local viewer; and the
 * flat / Gouraud colour functions.  Values are in pixel units (4095 = 1). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

static hsr_status read_ppm(const char *path, const char *where, int W, int H, uint16_t **out, char *err, size_t errlen);
static void centroid(const hsr_scene *sc, int fi, double *P);

static double dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static int unit3(double *a)
{
    double l = sqrt(dot3(a, a));
    if (!(l > 0) || !isfinite(l)) return 0;
    a[0] /= l; a[1] /= l; a[2] /= l;
    return 1;
}

static const double *vtx(const hsr_scene *sc, int fi, int k)
{
    return &sc->v[3 * sc->fv[sc->f[fi].first + k]];
}

/* unnormalised Newell normal (length = twice the area) */
static void newell(const hsr_scene *sc, int fi, double *n)
{
    int c = sc->f[fi].count;
    n[0] = n[1] = n[2] = 0;
    for (int i = 0; i < c; i++) {
        const double *p = vtx(sc, fi, i), *r = vtx(sc, fi, (i + 1) % c);
        n[0] += (p[1] - r[1]) * (p[2] + r[2]);
        n[1] += (p[2] - r[2]) * (p[0] + r[0]);
        n[2] += (p[0] - r[0]) * (p[1] + r[1]);
    }
}

/* Phong at world point P with normal N (any length) for material m. */
static void phong(const yp_shader *s, const hsr_material *m, const double *P, const double *Nin,
                  double base[3], double *spec, int split)
{
    double N[3] = {Nin[0], Nin[1], Nin[2]}, E[3];
    for (int k = 0; k < 3; k++) E[k] = s->sc->eye[k] - P[k];
    unit3(E);
    if (!unit3(N)) { N[0] = E[0]; N[1] = E[1]; N[2] = E[2]; }
    if (dot3(N, E) < 0) { N[0] = -N[0]; N[1] = -N[1]; N[2] = -N[2]; }   /* two-sided */
    for (int c = 0; c < 3; c++) base[c] = s->sc->ambient * m->rgb[c];
    for (int l = 0; l < s->nl; l++) {
        const double *L = s->L[l];
        double Lp[3], att = 1;
        if (s->Lpt[l]) {   /* point light: towards its position, with its falloff */
            for (int k = 0; k < 3; k++) Lp[k] = s->Lpos[l][k] - P[k];
            double d2 = dot3(Lp, Lp);
            if (s->Lfall[l] > 0) att = 1 / (1 + d2 / (s->Lfall[l] * s->Lfall[l]));
            if (!unit3(Lp)) { Lp[0] = N[0]; Lp[1] = N[1]; Lp[2] = N[2]; }
            L = Lp;
        }
        double nl = dot3(N, L), d = nl > 0 ? att * nl : 0, sp = 0;
        if (m->ks > 0) {
            double R[3] = {2 * nl * N[0] - L[0], 2 * nl * N[1] - L[1], 2 * nl * N[2] - L[2]};
            double er = dot3(E, R);
            sp = er > 0 ? att * m->ks * pow(er, m->shininess) : 0;
        }
        for (int c = 0; c < 3; c++) {
            base[c] += s->Lrgb[l][c] * m->rgb[c] * d;
            double v = s->Lrgb[l][c] * sp * YP_PIX;
            if (split) spec[3 * l + c] = v; else base[c] += v / YP_PIX;
        }
    }
    for (int c = 0; c < 3; c++) base[c] *= YP_PIX;
}

/* barycentric weights of world point P in triangle (a, b, c) */
static void bary(const double *a, const double *b, const double *c, const double *P, double *w)
{
    double e0[3], e1[3], ep[3];
    for (int k = 0; k < 3; k++) { e0[k] = b[k] - a[k]; e1[k] = c[k] - a[k]; ep[k] = P[k] - a[k]; }
    double d00 = dot3(e0, e0), d01 = dot3(e0, e1), d11 = dot3(e1, e1), dp0 = dot3(ep, e0), dp1 = dot3(ep, e1);
    double den = d00 * d11 - d01 * d01;
    if (!(fabs(den) > 0)) { w[0] = 1; w[1] = w[2] = 0; return; }
    w[1] = (d11 * dp0 - d01 * dp1) / den;
    w[2] = (d00 * dp1 - d01 * dp0) / den;
    w[0] = 1 - w[1] - w[2];
}

/* The shading point and normal for world point P on face fi's plane. P is where the ray
 * through a pixel centre meets the plane, and for a pixel the face only partly covers that
 * is often outside the face: interpolated there, the vertex normals extrapolate, and on a
 * sliver with grazing normals the extrapolated one can face the other way, so the
 * two-sided test leaves the face unlit (short dark streaks along the teapot's rims;
 * docs/yproc.md). So the barycentric weights are clamped to the face (negative weights to
 * 0, then normalised) and P moves with them onto the face. */
static void face_point_normal(const yp_shader *s, int fi, double *P, double *N)
{
    const hsr_scene *sc = s->sc;
    const hsr_face *F = &sc->f[fi];
    if (sc->mat[F->material].flat) { memcpy(N, &s->fn[3 * fi], 3 * sizeof(double)); return; }
    /* n-gons: the fan triangle (0, i, i+1) in which P lies best */
    double best = -1e300, bw[3] = {1, 0, 0};
    int bi = 1;
    for (int i = 1; i + 1 < F->count; i++) {
        double w[3];
        bary(vtx(sc, fi, 0), vtx(sc, fi, i), vtx(sc, fi, i + 1), P, w);
        double mn = fmin(w[0], fmin(w[1], w[2]));
        if (mn > best) { best = mn; bi = i; memcpy(bw, w, sizeof bw); }
    }
    if (best < 0) {
        double sum = 0;
        for (int k = 0; k < 3; k++) sum += bw[k] = fmax(bw[k], 0);
        for (int k = 0; k < 3; k++) bw[k] /= sum;   /* sum > 0: at most two weights are < 0 */
        const double *a = vtx(sc, fi, 0), *b = vtx(sc, fi, bi), *c = vtx(sc, fi, bi + 1);
        for (int k = 0; k < 3; k++) P[k] = bw[0] * a[k] + bw[1] * b[k] + bw[2] * c[k];
    }
    const double *cn = &s->cn[3 * (size_t)F->first];
    for (int k = 0; k < 3; k++)
        N[k] = bw[0] * cn[k] + bw[1] * cn[3 * bi + k] + bw[2] * cn[3 * (bi + 1) + k];
}

static void centroid(const hsr_scene *sc, int fi, double *P)
{
    int c = sc->f[fi].count;
    P[0] = P[1] = P[2] = 0;
    for (int i = 0; i < c; i++) for (int k = 0; k < 3; k++) P[k] += vtx(sc, fi, i)[k] / c;
}

void yp_face_point(const yp_shader *s, int fi, double px, double py, double P[3])
{
    /* ray through the pixel position, intersected with the face's plane */
    const hsr_scene *sc = s->sc;
    const hsr_view *vw = &s->vw;
    double a = (px - vw->W / 2) / vw->f, b = (vw->H / 2 - py) / vw->f, dir[3];
    for (int k = 0; k < 3; k++) dir[k] = a * vw->u[k] + b * vw->v[k] - vw->w[k];
    const double *n = &s->fn[3 * fi], *p0 = vtx(sc, fi, 0);
    double den = dot3(n, dir);
    if (fabs(den) > 1e-12) {
        double d0[3] = {p0[0] - sc->eye[0], p0[1] - sc->eye[1], p0[2] - sc->eye[2]};
        double t = dot3(n, d0) / den;
        for (int k = 0; k < 3; k++) P[k] = sc->eye[k] + t * dir[k];
    } else centroid(sc, fi, P);
}

void yp_shade_face(const yp_shader *s, int fi, double px, double py, double base[3], double *spec)
{
    const hsr_scene *sc = s->sc;
    if (spec) for (int i = 0; i < 3 * s->nl; i++) spec[i] = 0;
    if (s->mode == YP_FLAT) { memcpy(base, &s->flat[3 * fi], 3 * sizeof(double)); return; }
    if (s->mode == YP_GOURAUD) {
        for (int c = 0; c < 3; c++) {
            const double *g = &s->gour[15 * fi + 3 * c], *mm = &s->gour[15 * fi + 9 + 2 * c];
            base[c] = fmin(mm[1], fmax(mm[0], g[0] * px + g[1] * py + g[2]));   /* no extrapolation */
        }
        return;
    }
    double P[3], N[3];
    yp_face_point(s, fi, px, py, P);
    face_point_normal(s, fi, P, N);
    phong(s, &sc->mat[sc->f[fi].material], P, N, base, spec, 1);
}

/* flat colour (Phong at the centroid with the face normal) and the
 * Gouraud plane (Phong at the vertices, affine in screen space) */
static void face_functions(yp_shader *s, int fi)
{
    const hsr_scene *sc = s->sc;
    const hsr_material *m = &sc->mat[sc->f[fi].material];
    double P[3], base[3];
    centroid(sc, fi, P);
    phong(s, m, P, &s->fn[3 * fi], base, NULL, 0);
    memcpy(&s->flat[3 * fi], base, sizeof base);
    double *g = &s->gour[15 * fi];
    for (int c = 0; c < 3; c++) { g[3 * c] = g[3 * c + 1] = 0; g[3 * c + 2] = base[c]; g[9 + 2 * c] = g[10 + 2 * c] = base[c]; }
    if (sc->f[fi].count < 3) return;
    double xs[3], ys[3], I[3][3];
    const hsr_view *vw = &s->vw;
    for (int i = 0; i < 3; i++) {
        const double *V = vtx(sc, fi, i);
        double d[3] = {V[0] - sc->eye[0], V[1] - sc->eye[1], V[2] - sc->eye[2]};
        double ze = dot3(d, vw->w);
        if (!(ze < -1e-9)) return;           /* behind the eye: keep flat */
        xs[i] = vw->W / 2 + vw->f * dot3(d, vw->u) / -ze;
        ys[i] = vw->H / 2 - vw->f * dot3(d, vw->v) / -ze;
        const double *N = m->flat ? &s->fn[3 * fi] : &s->cn[3 * (size_t)(sc->f[fi].first + i)];
        phong(s, m, V, N, I[i], NULL, 0);
    }
    double det = (xs[1] - xs[0]) * (ys[2] - ys[0]) - (xs[2] - xs[0]) * (ys[1] - ys[0]);
    if (!(fabs(det) > 1e-9)) return;
    for (int c = 0; c < 3; c++) {
        double d1 = I[1][c] - I[0][c], d2 = I[2][c] - I[0][c];
        double ga = (d1 * (ys[2] - ys[0]) - d2 * (ys[1] - ys[0])) / det;
        double gb = (d2 * (xs[1] - xs[0]) - d1 * (xs[2] - xs[0])) / det;
        g[3 * c] = ga; g[3 * c + 1] = gb; g[3 * c + 2] = I[0][c] - ga * xs[0] - gb * ys[0];
        g[9 + 2 * c] = fmin(I[0][c], fmin(I[1][c], I[2][c]));
        g[10 + 2 * c] = fmax(I[0][c], fmax(I[1][c], I[2][c]));
    }
}

static int corner_cmp(const void *pa, const void *pb)
{
    const struct yp_corner *a = pa, *b = pb;
    if (a->v != b->v) return a->v < b->v ? -1 : 1;
    if (a->g != b->g) return a->g < b->g ? -1 : 1;
    if (a->poly != b->poly) return a->poly < b->poly ? -1 : 1;
    return (a->c > b->c) - (a->c < b->c);
}

hsr_status yp_shader_update(yp_shader *s, const hsr_scene *sc)
{
    s->sc = sc;
    if (!hsr_view_make(sc, &s->vw)) return HSR_EINVAL;
    s->nl = sc->nlights;
    for (int l = 0; l < s->nl; l++) {
        memcpy(s->L[l], sc->lights[l].dir, sizeof s->L[l]);
        if (!unit3(s->L[l])) return HSR_EINVAL;
        memcpy(s->Lrgb[l], sc->lights[l].rgb, sizeof s->Lrgb[l]);
    }
    for (int c = 0; c < 3; c++) s->bg[c] = sc->bg[c] * YP_PIX;
    for (int fi = 0; fi < sc->nf; fi++) {
        double n[3];
        newell(sc, fi, n);
        memcpy(&s->pn[3 * fi], n, sizeof n);
        if (!unit3(n)) n[0] = n[1] = n[2] = 0;
        memcpy(&s->fn[3 * fi], n, sizeof n);
    }
    /* a polygon stored as triangles: their Newell normals add up to the polygon's */
    for (int a = 0, b; a < sc->nf; a = b) {
        double n[3] = {0, 0, 0};
        for (b = a; b < sc->nf && sc->f[b].poly == sc->f[a].poly; b++)
            for (int k = 0; k < 3; k++) n[k] += s->pn[3 * b + k];
        for (int i = a; i < b; i++) memcpy(&s->pn[3 * i], n, sizeof n);
    }
    /* smooth normals: per vertex and smoothing group, the sum of the Newell normals of
     * the polygons of that group that use the vertex (each polygon once) */
    for (int a = 0, b; a < sc->nfv; a = b) {
        const struct yp_corner *A = &s->ck[a];
        double n[3] = {0, 0, 0};
        for (b = a; b < sc->nfv && s->ck[b].v == A->v && s->ck[b].g == A->g; b++)
            if (b == a || s->ck[b].poly != s->ck[b - 1].poly)
                for (int k = 0; k < 3; k++) n[k] += s->pn[3 * s->ck[b].face + k];
        unit3(n);
        for (int i = a; i < b; i++) memcpy(&s->cn[3 * (size_t)s->ck[i].c], n, sizeof n);
    }
    for (int fi = 0; fi < sc->nf; fi++)
        for (int i = 0; i < sc->f[fi].count; i++) {
            int c = sc->f[fi].first + i, k = sc->fvn ? sc->fvn[c] : -1;
            double *N = &s->cn[3 * (size_t)c];
            if (k >= 0) { memcpy(N, &sc->vn[3 * k], 3 * sizeof(double)); unit3(N); }   /* authored */
            else if (sc->f[fi].smooth == 0) memcpy(N, &s->fn[3 * fi], 3 * sizeof(double));   /* s off */
        }
    /* the flat colours and Gouraud planes are read only in those modes (yp_shade_face);
     * Phong mode would evaluate 4 Phong terms per face for nothing (~25 ms on 69K faces) */
    if (s->mode != YP_PHONG)
        for (int fi = 0; fi < sc->nf; fi++) face_functions(s, fi);
    return HSR_OK;
}

hsr_status yp_shader_new(const hsr_scene *sc, yp_shading mode, yp_shader **out, char *err, size_t errlen)
{
    if (!sc || !out) return HSR_EINVAL;
    *out = NULL;
    if (err && errlen) err[0] = 0;
    /* no-wrap rule: A + sum_l I_l,c (kd_c + KS) <= 1 for every used material */
    char *used = calloc((size_t)sc->nmat + 1, 1);
    if (!used) return HSR_ENOMEM;
    for (int fi = 0; fi < sc->nf; fi++) used[sc->f[fi].material] = 1;
    for (int mi = 0; mi < sc->nmat; mi++) {
        if (!used[mi]) continue;
        const hsr_material *m = &sc->mat[mi];
        for (int c = 0; c < 3; c++) {
            double t = sc->ambient;
            for (int l = 0; l < sc->nlights; l++) t += sc->lights[l].rgb[c] * (m->rgb[c] + m->ks);
            if (t > 1 + 1e-9 || sc->ambient < 0 || m->rgb[c] < 0) {
                /* the material's own line: in the scene file or in its .mtl file */
                const char *where = m->file > 0 && m->file <= sc->nfiles ? sc->files[m->file - 1]
                                    : sc->name[0] ? sc->name : "<scene>";
                if (err) snprintf(err, errlen, "%s:%d: material '%s' can exceed intensity 1 in %c "
                                  "(A + sum I(kd+KS) = %.4g with %d light(s), first light on line %d); "
                                  "lower kd, KS or the lights", where,
                                  m->line, m->name, "RGB"[c], t, sc->nlights, sc->lights[0].line);
                free(used);
                return HSR_EPARSE;
            }
        }
    }
    free(used);
    for (int c = 0; c < 3; c++)
        if (!(sc->bg[c] >= 0 && sc->bg[c] <= 1)) {
            if (err) snprintf(err, errlen, "%s: background colour outside [0,1]", sc->name[0] ? sc->name : "<scene>");
            return HSR_EPARSE;
        }
    yp_shader *s = calloc(1, sizeof *s);
    if (!s) return HSR_ENOMEM;
    s->mode = mode;
    s->cn = malloc(sizeof(double) * 3 * (size_t)(sc->nfv + 1));
    s->ck = malloc(sizeof(struct yp_corner) * (size_t)(sc->nfv + 1));
    s->pn = malloc(sizeof(double) * 3 * (size_t)(sc->nf + 1));
    s->fn = malloc(sizeof(double) * 3 * (size_t)(sc->nf + 1));
    s->flat = malloc(sizeof(double) * 3 * (size_t)(sc->nf + 1));
    s->gour = malloc(sizeof(double) * 15 * (size_t)(sc->nf + 1));
    if (!s->cn || !s->ck || !s->pn || !s->fn || !s->flat || !s->gour) { yp_shader_free(s); return HSR_ENOMEM; }
    /* The corners sorted by (vertex, group, polygon, corner); the order depends on the
     * topology only. A counting sort by vertex, then an insertion sort by (group,
     * polygon) inside each vertex's few corners: the keys are unique (c), so this is the
     * order qsort with corner_cmp gives, in O(n) instead of O(n log n) (the 69K-triangle
     * bunny's 208K corners took ~30 ms in qsort). */
    int *start = calloc((size_t)sc->nv + 1, sizeof(int));
    if (!start) { yp_shader_free(s); return HSR_ENOMEM; }
    for (int c = 0; c < sc->nfv; c++) start[sc->fv[c] + 1]++;
    for (int v = 0; v < sc->nv; v++) start[v + 1] += start[v];
    for (int fi = 0; fi < sc->nf; fi++)     /* corners in increasing c */
        for (int i = 0; i < sc->f[fi].count; i++) {
            int c = sc->f[fi].first + i;
            struct yp_corner k = {sc->fv[c], sc->f[fi].smooth, sc->f[fi].poly, fi, c};
            s->ck[start[k.v]++] = k;
        }
    free(start);
    for (int a = 0, b; a < sc->nfv; a = b) {
        for (b = a + 1; b < sc->nfv && s->ck[b].v == s->ck[a].v; b++) {
            struct yp_corner k = s->ck[b];
            int j = b;
            for (; j > a && corner_cmp(&s->ck[j - 1], &k) > 0; j--) s->ck[j] = s->ck[j - 1];
            s->ck[j] = k;
        }
    }
    hsr_status st = yp_shader_update(s, sc);
    if (st == HSR_OK && sc->bg_image[0]) {
        char where[1100];   /* "scene:line" of the `background image` statement */
        snprintf(where, sizeof where, "%s:%d", sc->name[0] ? sc->name : "scene", sc->bg_image_line);
        st = read_ppm(sc->bg_image, where, sc->width, sc->height, &s->img, err, errlen);
    }
    if (st != HSR_OK) { yp_shader_free(s); return st; }
    *out = s;
    return HSR_OK;
}

/* binary PPM (P6, maxval 1..65535) -> 12-bit [3][H][W], scaled to the
 * screen by nearest neighbour; simple enough to read without a library. */
static hsr_status read_ppm(const char *path, const char *where, int W, int H, uint16_t **out, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) { if (err) snprintf(err, errlen, "%s: cannot read background image %s", where, path); return HSR_EIO; }
    int w, h, maxv;
    char m[3] = {0};
    if (fscanf(f, "%2s %d %d %d", m, &w, &h, &maxv) != 4 || strcmp(m, "P6") || maxv < 1 || maxv > 65535 || fgetc(f) == EOF) {
        fclose(f);
        if (err) snprintf(err, errlen, "%s: %s: not a binary PPM (P6)", where, path);
        return HSR_EPARSE;
    }
    /* any size: scaled to the screen by nearest neighbour */
    int bytes = maxv > 255 ? 2 : 1;
    uint16_t *src = malloc(sizeof(uint16_t) * 3 * (size_t)w * (size_t)h);
    uint16_t *img = malloc(sizeof(uint16_t) * 3 * (size_t)W * (size_t)H);
    if (!img || !src) { free(img); free(src); fclose(f); return HSR_ENOMEM; }
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++) {
        int v = fgetc(f);
        if (bytes == 2 && v >= 0) { int lo = fgetc(f); v = lo < 0 ? -1 : (v << 8) | lo; }
        if (v < 0) { free(img); free(src); fclose(f); if (err) snprintf(err, errlen, "%s: %s: truncated", where, path); return HSR_EPARSE; }
        src[i] = (uint16_t)lround((double)v * 4095.0 / maxv);
    }
    for (int y = 0; y < H; y++)
        for (int x = 0; x < W; x++) {
            size_t sx = (size_t)x * (size_t)w / (size_t)W, sy = (size_t)y * (size_t)h / (size_t)H;
            for (int c = 0; c < 3; c++) img[((size_t)c * H + y) * W + x] = src[3 * (sy * (size_t)w + sx) + (size_t)c];
        }
    free(src);
    fclose(f);
    *out = img;
    return HSR_OK;
}

void yp_shader_free(yp_shader *s)
{
    if (!s) return;
    free(s->img); free(s->tex); free(s->texc);
    free(s->cn); free(s->ck); free(s->pn); free(s->fn); free(s->flat); free(s->gour); free(s);
}
