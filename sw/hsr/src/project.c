/* project.c - scene -> MLR: viewing transform, near-plane clipping,
 * perspective, screen clipping, quantisation to 1/HSR_SUBPIXEL pixel.
 * Depth is z = -1/(eye distance along the view axis), which is affine in
 * screen coordinates for a planar face, so each face keeps a plane. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

static void sub(const double *a, const double *b, double *o) { o[0] = a[0] - b[0]; o[1] = a[1] - b[1]; o[2] = a[2] - b[2]; }
static double dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1]; o[1] = a[2] * b[0] - a[0] * b[2]; o[2] = a[0] * b[1] - a[1] * b[0];
}
static int norm(double *a)
{
    double l = sqrt(dot(a, a));
    if (!(l > 0) || !isfinite(l)) return 0;
    a[0] /= l; a[1] /= l; a[2] /= l;
    return 1;
}

/* clip polygon (3 doubles per point) against dim`axis` * sign <= lim */
static int clip(const double *in, int n, double *out, int axis, double sign, double lim)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const double *a = &in[3 * i], *b = &in[3 * ((i + 1) % n)];
        double da = sign * a[axis] - lim, db = sign * b[axis] - lim;
        if (da <= 0) { memcpy(&out[3 * m], a, 3 * sizeof(double)); m++; }
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
            double t = da / (da - db);
            for (int k = 0; k < 3; k++) out[3 * m + k] = a[k] + t * (b[k] - a[k]);
            m++;
        }
    }
    return m;
}

int hsr_view_make(const hsr_scene *sc, hsr_view *vw)
{
    sub(sc->eye, sc->at, vw->w);
    cross(sc->up, vw->w, vw->u);
    if (!norm(vw->w) || !norm(vw->u)) return 0;
    cross(vw->w, vw->u, vw->v);
    vw->W = sc->width; vw->H = sc->height;
    vw->f = (vw->H / 2) / tan(sc->fov_deg * 3.14159265358979323846 / 360.0);
    return 1;
}

int hsr_face_cap(const hsr_scene *sc)
{
    int maxn = 4;
    for (int i = 0; i < sc->nf; i++) if (sc->f[i].count > maxn) maxn = sc->f[i].count;
    return 2 * maxn + 16;
}

/* Face fi -> quantised screen polygon q (len points, 0 if clipped away or
 * edge-on) and its depth plane.  a, b: scratch of 3*cap doubles, q: 2*cap. */
int hsr_face_project(const hsr_scene *sc, const hsr_view *vw, int fi, double *a, double *b,
                       int64_t *q, hsr_plane *plane)
{
    const hsr_face *F = &sc->f[fi];
    const double W = vw->W, H = vw->H, f = vw->f, S = HSR_SUBPIXEL;
    int n = F->count;
    for (int i = 0; i < n; i++) {
        double d[3];
        sub(&sc->v[3 * sc->fv[F->first + i]], sc->eye, d);
        a[3 * i] = dot(d, vw->u); a[3 * i + 1] = dot(d, vw->v); a[3 * i + 2] = dot(d, vw->w);
    }
    n = clip(a, n, b, 2, 1, -sc->near_z);     /* keep z_eye <= -near */
    for (int i = 0; i < n; i++) {
        double iz = 1.0 / -b[3 * i + 2];
        a[3 * i] = (W / 2 + f * b[3 * i] * iz) * S;
        a[3 * i + 1] = (H / 2 - f * b[3 * i + 1] * iz) * S;
        a[3 * i + 2] = -iz;
    }
    n = clip(a, n, b, 0, -1, 0); n = clip(b, n, a, 0, 1, W * S);
    n = clip(a, n, b, 1, -1, 0); n = clip(b, n, a, 1, 1, H * S);
    hsr_plane pl = {0, 0, 0};
    double nx = 0, ny = 0, nz = 0, cx = 0, cy = 0, cz = 0;
    for (int i = 0; i < n; i++) {
        const double *p = &a[3 * i], *r = &a[3 * ((i + 1) % n)];
        nx += (p[1] - r[1]) * (p[2] + r[2]); ny += (p[2] - r[2]) * (p[0] + r[0]);
        nz += (p[0] - r[0]) * (p[1] + r[1]);
        cx += p[0]; cy += p[1]; cz += p[2];
        q[2 * i] = llround(p[0]); q[2 * i + 1] = llround(p[1]);
    }
    int len = n;
    if (n < 3 || fabs(nz) < 1e-9 * (fabs(nx) + fabs(ny) + 1e-300)) len = 0;   /* clipped or edge-on */
    else {
        cx /= n; cy /= n; cz /= n;
        pl.a = -nx / nz; pl.b = -ny / nz; pl.c = cz - pl.a * cx - pl.b * cy;
        if (!isfinite(pl.a) || !isfinite(pl.b) || !isfinite(pl.c)) { len = 0; pl.a = pl.b = pl.c = 0; }
    }
    *plane = pl;
    return len;
}

hsr_status hsr_scene_build(const hsr_scene *sc, hsr_ctx **out, double **shade_out)
{
    if (!sc || !out || !shade_out) return HSR_EINVAL;
    *out = NULL; *shade_out = NULL;
    double L[3];
    hsr_view vw;
    memcpy(L, sc->light, sizeof L);
    if (!hsr_view_make(sc, &vw) || !norm(L)) return HSR_EINVAL;
    double W = vw.W, H = vw.H, S = HSR_SUBPIXEL;
    hsr_config cfg = {{0, 0, (int64_t)(W * S), (int64_t)(H * S)}, sc->grid, sc->grid};
    hsr_ctx *h;
    hsr_status st = hsr_create(&cfg, &h);
    if (st != HSR_OK) return st;
    int cap = hsr_face_cap(sc);
    double *a = malloc(sizeof(double) * 3 * (size_t)cap), *b = malloc(sizeof(double) * 3 * (size_t)cap);
    int64_t *q = malloc(sizeof(int64_t) * 2 * (size_t)cap);
    double *shade = malloc(sizeof(double) * 4 * (size_t)(sc->nf + 1));
    if (!a || !b || !q || !shade) { st = HSR_ENOMEM; goto done; }
    for (int fi = 0; fi < sc->nf && st == HSR_OK; fi++) {
        const hsr_face *F = &sc->f[fi];
        const hsr_material *m = &sc->mat[F->material];
        double nrm[3] = {0, 0, 0};
        for (int i = 0; i < F->count; i++) {           /* Newell normal, world space */
            const double *p = &sc->v[3 * sc->fv[F->first + i]], *r = &sc->v[3 * sc->fv[F->first + (i + 1) % F->count]];
            nrm[0] += (p[1] - r[1]) * (p[2] + r[2]);
            nrm[1] += (p[2] - r[2]) * (p[0] + r[0]);
            nrm[2] += (p[0] - r[0]) * (p[1] + r[1]);
        }
        double lit = sc->ambient + (norm(nrm) ? sc->light_i * fabs(dot(nrm, L)) : 0);
        for (int k = 0; k < 3; k++) shade[4 * fi + k] = fmin(1.0, fmax(0.0, m->rgb[k] * lit));
        shade[4 * fi + 3] = m->opacity;
        hsr_plane pl;
        int len = hsr_face_project(sc, &vw, fi, a, b, q, &pl);
        int id;
        st = hsr_add(h, q, &len, 1, pl, m->opacity, &id);
    }
done:
    free(a); free(b); free(q);
    if (st != HSR_OK) { free(shade); hsr_destroy(h); return st; }
    *out = h; *shade_out = shade;
    return HSR_OK;
}
