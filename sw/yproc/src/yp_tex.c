/* yp_tex.c - the textured pattern lit by a nearby moving light of Fig. 7.27
 * (section 7.7.1, docs/yproc.md section 11): point lights, a procedural texture that
 * is a polynomial along every span (a periodic quadratic B-spline), and the .anim
 * statements that place a light, let it wander towards random positions and texture
 * a material. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

hsr_status yp_shader_set_point_light(yp_shader *s, int l, const double pos[3], double falloff)
{
    if (!s || !pos || l < 0 || l >= s->nl || !(falloff >= 0)) return HSR_EINVAL;
    for (int k = 0; k < 3; k++) if (!isfinite(pos[k])) return HSR_EINVAL;
    s->Lpt[l] = 1;
    memcpy(s->Lpos[l], pos, sizeof s->Lpos[l]);
    s->Lfall[l] = falloff;
    return HSR_OK;
}

/* A + sum_l I_l (kd + KS) + amp * rgb: the most the material can reach in colour c */
static double peak(const hsr_scene *sc, int m, const yp_texture *t, int c)
{
    double p = sc->ambient + (t ? t->amp * t->rgb[c] : 0);
    for (int l = 0; l < sc->nlights; l++) p += sc->lights[l].rgb[c] * (sc->mat[m].rgb[c] + sc->mat[m].ks);
    return p;
}

static int tex_check(const hsr_scene *sc, int m, const yp_texture *t, char *err, size_t errlen)
{
    if (m < 0 || m >= sc->nmat || !(t->scale > 0) || !(t->amp >= 0) || t->n < 1 || t->n > 256) {
        if (err) snprintf(err, errlen, "texture: needs a material, scale > 0, amp >= 0, 1 <= N <= 256");
        return 0;
    }
    for (int c = 0; c < 3; c++) {
        if (!(t->rgb[c] >= 0 && t->rgb[c] <= 1)) {
            if (err) snprintf(err, errlen, "texture: colour outside [0,1]");
            return 0;
        }
        double p = peak(sc, m, t, c);
        if (p > 1 + 1e-9) {
            if (err) snprintf(err, errlen, "texture of material '%s' can exceed intensity 1 in %c "
                              "(A + sum I(kd+KS) + amp*rgb = %.4g); lower amp or the material", sc->mat[m].name, "RGB"[c], p);
            return 0;
        }
    }
    return 1;
}

/* coefficient (i, j) of a texture: a hash of (seed, i, j) in [0, 1] (splitmix64) */
static float coef(unsigned seed, int i, int j)
{
    uint64_t z = ((uint64_t)seed << 32) ^ ((uint64_t)(unsigned)i << 16) ^ (uint64_t)(unsigned)j;
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return (float)((double)(z >> 11) / (double)(1ull << 53));
}

hsr_status yp_shader_set_texture(yp_shader *s, int material, const yp_texture *t, char *err, size_t errlen)
{
    if (!s || !t) return HSR_EINVAL;
    const hsr_scene *sc = s->sc;
    if (!tex_check(sc, material, t, err, errlen)) return HSR_EPARSE;
    if (!s->tex) {
        s->tex = calloc((size_t)sc->nmat + 1, sizeof *s->tex);
        s->texc = calloc(((size_t)sc->nmat + 1) * 256 * 256, sizeof *s->texc);
        if (!s->tex || !s->texc) { free(s->tex); free(s->texc); s->tex = NULL; s->texc = NULL; return HSR_ENOMEM; }
        s->ntex = sc->nmat;
    }
    if (material >= s->ntex) return HSR_EINVAL;
    s->tex[material] = *t;
    float *cf = &s->texc[(size_t)material * 256 * 256];
    for (int i = 0; i < t->n; i++)
        for (int j = 0; j < t->n; j++) cf[i * t->n + j] = coef(t->seed, i, j);
    return HSR_OK;
}

/* uniform quadratic B-spline weights of the three coefficients around u */
static void bweights(double u, int n, int *i0, double w[3])
{
    double fl = floor(u), s = u - fl;
    w[0] = 0.5 * (1 - s) * (1 - s);
    w[1] = 0.5 + s * (1 - s);
    w[2] = 0.5 * s * s;
    long k = (long)fl % n;
    if (k < 0) k += n;
    *i0 = (int)k;
}

double yp_texture_at(const yp_shader *s, int fi, const double P[3])
{
    if (!s || !s->tex) return -1;
    int m = s->sc->f[fi].material;
    if (m >= s->ntex || !(s->tex[m].amp > 0)) return -1;
    const yp_texture *t = &s->tex[m];
    const double *fn = &s->fn[3 * fi];
    /* the two world axes the face is least inclined to (drop the normal's largest) */
    int drop = fabs(fn[0]) >= fabs(fn[1]) && fabs(fn[0]) >= fabs(fn[2]) ? 0 : fabs(fn[1]) >= fabs(fn[2]) ? 1 : 2;
    int au = drop == 0 ? 1 : 0, av = drop == 2 ? 1 : 2;
    int iu, iv, n = t->n;
    double wu[3], wv[3], v = 0;
    bweights(P[au] / t->scale, n, &iu, wu);
    bweights(P[av] / t->scale, n, &iv, wv);
    const float *cf = &s->texc[(size_t)m * 256 * 256];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) v += wu[a] * wv[b] * cf[((iu + a) % n) * n + (iv + b) % n];
    return v;
}

int yp_shade_texture(const yp_shader *s, int fi, double px, double py, double tex[3])
{
    tex[0] = tex[1] = tex[2] = 0;
    if (!s->tex) return 0;
    int m = s->sc->f[fi].material;
    if (m >= s->ntex || !(s->tex[m].amp > 0)) return 0;
    double P[3];
    yp_face_point(s, fi, px, py, P);
    double v = yp_texture_at(s, fi, P);
    for (int c = 0; c < 3; c++) tex[c] = v * s->tex[m].amp * s->tex[m].rgb[c] * YP_PIX;
    return 1;
}

/* ---- .anim statements ---------------------------------------------------- */
typedef struct wander { int light, f0, f1, frames; unsigned seed; double lo[3], hi[3]; } wander;

struct yp_animx {
    int npt, pt_light[HSR_MAX_LIGHTS];
    double pt_pos[HSR_MAX_LIGHTS][3], pt_fall[HSR_MAX_LIGHTS];
    wander wd[HSR_MAX_LIGHTS]; int nwd;
    yp_texture tx[64]; int tx_mat[64], ntx;
    double cur[HSR_MAX_LIGHTS][3];      /* positions last set on the shader */
    const yp_shader *done;              /* shader the textures were set on */
};

void yp_animx_free(yp_animx *x) { free(x); }

static int num(const char *t, double *v) { return hsr_text_num(t, v) && isfinite(*v); }

int yp_animx_parse(yp_animx **xp, const hsr_scene *sc, char **tok, int nt, char *msg, size_t msglen)
{
    int pl = !strcmp(tok[0], "pointlight"), wd = !strcmp(tok[0], "wander"), tx = !strcmp(tok[0], "texture");
    if (!pl && !wd && !tx) return 0;
    if (!*xp && !(*xp = calloc(1, sizeof **xp))) { snprintf(msg, msglen, "out of memory"); return -1; }
    yp_animx *x = *xp;
    double v[12];
    if (pl) {
        if ((nt != 5 && nt != 7) || (nt == 7 && strcmp(tok[5], "falloff"))) {
            snprintf(msg, msglen, "expected 'pointlight L X Y Z [falloff R]'"); return -1;
        }
        for (int i = 1; i < nt; i++) if (i != 5 && !num(tok[i], &v[i])) { snprintf(msg, msglen, "bad number '%s'", tok[i]); return -1; }
        int l = (int)v[1];
        if (v[1] != l || l < 0 || l >= sc->nlights) { snprintf(msg, msglen, "light %s does not exist", tok[1]); return -1; }
        for (int i = 0; i < x->npt; i++) if (x->pt_light[i] == l) { snprintf(msg, msglen, "light %d is already a point light", l); return -1; }
        double fall = nt == 7 ? v[6] : 0;
        if (!(fall >= 0)) { snprintf(msg, msglen, "falloff must be >= 0"); return -1; }
        x->pt_light[x->npt] = l;
        memcpy(x->pt_pos[x->npt], &v[2], 3 * sizeof(double));
        x->pt_fall[x->npt++] = fall;
        return 1;
    }
    if (wd) {
        /* wander L SEED FRAMES X0 Y0 Z0 X1 Y1 Z1 from F0 to F1 */
        if (nt != 14 || strcmp(tok[10], "from") || strcmp(tok[12], "to")) {
            snprintf(msg, msglen, "expected 'wander L SEED FRAMES X0 Y0 Z0 X1 Y1 Z1 from F0 to F1'"); return -1;
        }
        double w[14];
        for (int i = 1; i < nt; i++) if (i != 10 && i != 12 && !num(tok[i], &w[i])) { snprintf(msg, msglen, "bad number '%s'", tok[i]); return -1; }
        int k = -1;
        for (int i = 0; i < x->npt; i++) if (x->pt_light[i] == (int)w[1] && w[1] == (int)w[1]) k = i;
        if (k < 0) { snprintf(msg, msglen, "light %s is not a point light ('pointlight' first)", tok[1]); return -1; }
        if (w[3] < 1 || w[3] != (int)w[3]) { snprintf(msg, msglen, "FRAMES per leg must be an integer >= 1"); return -1; }
        if (w[11] < 0 || w[13] <= w[11] || w[11] != (int)w[11] || w[13] != (int)w[13]) { snprintf(msg, msglen, "frame range must be 0 <= F0 < F1"); return -1; }
        if (w[2] < 0 || w[2] != (unsigned)w[2]) { snprintf(msg, msglen, "SEED must be an integer >= 0"); return -1; }
        if (x->nwd == HSR_MAX_LIGHTS) { snprintf(msg, msglen, "too many 'wander'"); return -1; }
        wander *q = &x->wd[x->nwd++];
        q->light = (int)w[1]; q->seed = (unsigned)w[2]; q->frames = (int)w[3]; q->f0 = (int)w[11]; q->f1 = (int)w[13];
        for (int i = 0; i < 3; i++) { q->lo[i] = fmin(w[4 + i], w[7 + i]); q->hi[i] = fmax(w[4 + i], w[7 + i]); }
        return 1;
    }
    /* texture MATERIAL SCALE AMP R G B SEED [N] */
    if (nt != 8 && nt != 9) { snprintf(msg, msglen, "expected 'texture MATERIAL SCALE AMP R G B SEED [N]'"); return -1; }
    for (int i = 2; i < nt; i++) if (!num(tok[i], &v[i])) { snprintf(msg, msglen, "bad number '%s'", tok[i]); return -1; }
    int m = -1;
    for (int i = 0; i < sc->nmat; i++) if (!strcmp(sc->mat[i].name, tok[1])) m = i;
    if (m < 0) { snprintf(msg, msglen, "unknown material '%s'", tok[1]); return -1; }
    if (x->ntx == 64) { snprintf(msg, msglen, "too many textures"); return -1; }
    yp_texture t = {v[2], v[3], {v[4], v[5], v[6]}, (unsigned)v[7], nt == 9 ? (int)v[8] : 8};
    if (v[7] < 0 || v[7] != (unsigned)v[7] || (nt == 9 && v[8] != (int)v[8])) { snprintf(msg, msglen, "SEED and N must be integers >= 0"); return -1; }
    if (!tex_check(sc, m, &t, msg, msglen)) return -1;
    x->tx[x->ntx] = t;
    x->tx_mat[x->ntx++] = m;
    return 1;
}

/* waypoint k of a wander (k >= 1): uniform in its box */
static void waypoint(const wander *q, int k, double *p)
{
    for (int i = 0; i < 3; i++) p[i] = q->lo[i] + (q->hi[i] - q->lo[i]) * coef(q->seed, k, i);
}

int yp_animx_apply(yp_animx *x, int f, yp_shader *sh, hsr_status *st)
{
    *st = HSR_OK;
    if (!x || !sh) return 0;
    int moved = 0;
    for (int i = 0; i < x->npt; i++) {
        int l = x->pt_light[i];
        double p[3];
        memcpy(p, x->pt_pos[i], sizeof p);
        for (int w = 0; w < x->nwd; w++) {
            const wander *q = &x->wd[w];
            if (q->light != l || f <= q->f0) continue;
            /* from the light's place through waypoints 1, 2, ...: one leg per `frames` */
            double t = (double)((f < q->f1 ? f : q->f1) - q->f0) / q->frames, a[3], b[3];
            int k = (int)floor(t);
            double s = t - k;
            if (k == 0) memcpy(a, p, sizeof a); else waypoint(q, k, a);
            waypoint(q, k + 1, b);
            for (int c = 0; c < 3; c++) p[c] = a[c] + s * (b[c] - a[c]);
        }
        if (sh != x->done || memcmp(p, x->cur[i], sizeof p)) moved = 1;
        memcpy(x->cur[i], p, sizeof p);
        if ((*st = yp_shader_set_point_light(sh, l, p, x->pt_fall[i])) != HSR_OK) return 0;
    }
    if (sh != x->done)
        for (int i = 0; i < x->ntx; i++)
            if ((*st = yp_shader_set_texture(sh, x->tx_mat[i], &x->tx[i], NULL, 0)) != HSR_OK) return 0;
    x->done = sh;
    return moved;
}
