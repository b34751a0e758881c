/* obj.c - Wavefront OBJ reader: v, vn, vt (counted), f (i, i/j, i//k,
 * i/j/k, negative indices; quads and n-gons, cut into triangles unless
 * convex and planar, poly.c), s (smoothing groups), mtllib (mtl.c) and
 * usemtl; other statements are ignored.  Errors name file and line
 * (docs/hsr.md, "OBJ"). */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

#define MAX_ITEMS 50000000

int scene_grow(void **p, int *cap, int need, size_t sz)
{
    if (need <= *cap) return 1;
    if (need > MAX_ITEMS) return 0;
    int c = *cap ? *cap : 64;
    while (c < need) c *= 2;
    void *q = realloc(*p, (size_t)c * sz);
    if (!q) return 0;
    *p = q; *cap = c;
    return 1;
}

int scene_tokens(char *line, char **tok, int max)
{
    int n = 0;
    char *p = line;
    for (;;) {
        while (*p == ' ' || *p == '\t' || *p == '\r') p++;
        if (!*p || *p == '#') break;
        if (n == max) return -1;
        tok[n++] = p;
        while (*p && *p != ' ' && *p != '\t' && *p != '\r') p++;
        if (*p) *p++ = 0;
    }
    return n;
}

int hsr_text_line(const char **p, char *buf, size_t cap, char **tok, int max)
{
    const char *e = strchr(*p, '\n');
    size_t n = e ? (size_t)(e - *p) : strlen(*p);
    if (n >= cap) return -1;
    memcpy(buf, *p, n); buf[n] = 0;
    *p = e ? e + 1 : *p + n;
    int nt = scene_tokens(buf, tok, max);
    return nt < 0 ? -2 : nt;
}

hsr_status hsr_text_error(char *err, size_t errlen, const char *name, int lineno,
                          hsr_status st, const char *fmt, ...)
{
    if (!err) return st;
    int k = snprintf(err, errlen, "%s:%d: ", name, lineno);
    if (k >= 0 && (size_t)k < errlen) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(err + k, errlen - (size_t)k, fmt, ap);
        va_end(ap);
    }
    return st;
}

int hsr_text_next(const char **p, int *lineno, char *buf, size_t cap, char **tok, int max,
                  const char *name, char *err, size_t errlen)
{
    while (**p) {
        ++*lineno;
        int nt = hsr_text_line(p, buf, cap, tok, max);
        if (nt > 0) return nt;
        if (nt < 0) {
            hsr_text_error(err, errlen, name, *lineno, HSR_EPARSE, "%s",
                           nt == -1 ? "line too long" : "too many items on one line");
            return -1;
        }
    }
    return 0;
}

int hsr_text_num(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return end != s && *end == 0 && isfinite(*v);
}

/* one index of a face corner: "" (absent) or a non-zero integer, relative
 * if negative; *out = 0-based index or -1 if absent; 0 if malformed */
static int corner_index(const char *s, size_t len, long count, long *out, long *raw)
{
    *out = -1; *raw = 0;
    if (len == 0) return 1;
    char tmp[32], *end;
    if (len >= sizeof tmp) return 0;
    memcpy(tmp, s, len); tmp[len] = 0;
    long v = strtol(tmp, &end, 10);
    if (end == tmp || *end) return 0;
    *raw = v;
    *out = v > 0 ? v - 1 : (v < 0 ? count + v : -2);
    if (*out < 0 || *out >= count) *out = -2;   /* out of range */
    return 1;
}

static int add_vec(double **a, int *n, int *cap, const double *x)
{
    if (!scene_grow((void **)a, cap, 3 * (*n + 1), sizeof(double))) return 0;
    memcpy(&(*a)[3 * (*n)++], x, 3 * sizeof(double));
    return 1;
}

hsr_status hsr_obj_parse(hsr_scene *sc, const char *text, const char *name, int material,
                         char *err, size_t errlen)
{
    if (!sc || !text) return HSR_EINVAL;
    if (!name) name = "<obj>";
    int lineno = 0, mat = material, vbase = sc->nv, vnbase = sc->nvn, mbase = sc->nmat, group = -1;
    long nvt = 0;
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", name);
    char *slash = strrchr(dir, '/');
    if (slash) slash[1] = 0; else dir[0] = 0;
    char buf[4096], *tok[512];
    int cv[512], cn[512], tri[3 * 510];
    double pts[3 * 512];
    const char *p = text;
    int nt;
    while ((nt = hsr_text_next(&p, &lineno, buf, sizeof buf, tok, 512, name, err, errlen)) > 0) {
#define FAIL(st, ...) return hsr_text_error(err, errlen, name, lineno, st, __VA_ARGS__)
        if (!strcmp(tok[0], "v") || !strcmp(tok[0], "vn") || !strcmp(tok[0], "vt")) {
            int isv = tok[0][1] == 0, isn = tok[0][1] == 'n';
            double x[6];
            if (isv && nt != 4 && nt != 5 && nt != 7) FAIL(HSR_EPARSE, "'v' needs 3 coordinates (then w, or r g b)");
            if (isn && nt != 4) FAIL(HSR_EPARSE, "'vn' needs 3 numbers");
            if (!isv && !isn && (nt < 2 || nt > 4)) FAIL(HSR_EPARSE, "'vt' needs 1 to 3 numbers");
            for (int i = 1; i < nt; i++)
                if (!hsr_text_num(tok[i], &x[i - 1])) FAIL(HSR_EPARSE, "bad or non-finite number '%s'", tok[i]);
            if (isv) {
                if (!add_vec(&sc->v, &sc->nv, &sc->capv, x)) FAIL(HSR_ENOMEM, "too many vertices");
            } else if (isn) {
                if (x[0] == 0 && x[1] == 0 && x[2] == 0) FAIL(HSR_EPARSE, "'vn' has zero length");
                if (!add_vec(&sc->vn, &sc->nvn, &sc->capvn, x)) FAIL(HSR_ENOMEM, "too many normals");
            } else nvt++;
        } else if (!strcmp(tok[0], "f")) {
            int nc = nt - 1;
            if (nc < 3) FAIL(HSR_EPARSE, "face needs at least 3 vertices");
            long nloc = sc->nv - vbase, nnloc = sc->nvn - vnbase;
            for (int i = 0; i < nc; i++) {
                const char *t = tok[1 + i], *s1 = strchr(t, '/'), *s2 = s1 ? strchr(s1 + 1, '/') : NULL;
                size_t l0 = s1 ? (size_t)(s1 - t) : strlen(t);
                long iv, it, in, rv, rt, rn;
                if (!l0 || (s2 && strchr(s2 + 1, '/'))
                    || !corner_index(t, l0, nloc, &iv, &rv)
                    || !corner_index(s1 ? s1 + 1 : "", s1 ? (s2 ? (size_t)(s2 - s1 - 1) : strlen(s1 + 1)) : 0, nvt, &it, &rt)
                    || !corner_index(s2 ? s2 + 1 : "", s2 ? strlen(s2 + 1) : 0, nnloc, &in, &rn)
                    || (s1 && !s2 && it == -1))
                    FAIL(HSR_EPARSE, "bad vertex index '%s' (v, v/vt, v//vn or v/vt/vn)", t);
                if (iv < 0) FAIL(HSR_EPARSE, "vertex index %ld out of range (1..%ld)", rv, nloc);
                if (it == -2) FAIL(HSR_EPARSE, "texture index %ld out of range (1..%ld)", rt, nvt);
                if (in == -2) FAIL(HSR_EPARSE, "normal index %ld out of range (1..%ld)", rn, nnloc);
                cv[i] = (int)(vbase + iv);
                cn[i] = in < 0 ? -1 : (int)(vnbase + in);
                memcpy(&pts[3 * i], &sc->v[3 * cv[i]], 3 * sizeof(double));
            }
            int whole, ntri = poly_triangulate(pts, nc, tri, &whole);
            int nfaces = whole ? 1 : ntri, ncorner = whole ? nc : 3 * ntri;
            if (!scene_grow((void **)&sc->fv, &sc->capfv, sc->nfv + ncorner, sizeof(int))
                || !scene_grow((void **)&sc->fvn, &sc->capfvn, sc->nfv + ncorner, sizeof(int))
                || !scene_grow((void **)&sc->f, &sc->capf, sc->nf + nfaces, sizeof(hsr_face)))
                FAIL(HSR_ENOMEM, "too many faces");
            for (int k = 0; k < nfaces; k++) {
                int cnt = whole ? nc : 3;
                for (int i = 0; i < cnt; i++) {
                    int c = whole ? i : tri[3 * k + i];
                    sc->fv[sc->nfv + i] = cv[c]; sc->fvn[sc->nfv + i] = cn[c];
                }
                hsr_face F = {sc->nfv, cnt, mat, sc->nobj, group, sc->npoly};
                sc->f[sc->nf++] = F;
                sc->nfv += cnt;
            }
            sc->npoly++;
        } else if (!strcmp(tok[0], "s")) {
            char *end;
            long g = nt == 2 ? strtol(tok[1], &end, 10) : -1;
            if (nt == 2 && !strcmp(tok[1], "off")) g = 0;
            else if (nt != 2 || end == tok[1] || *end || g < 0 || g > 2147483647L)
                FAIL(HSR_EPARSE, "'s' needs a group number >= 0 or 'off'");
            group = (int)g;
        } else if (!strcmp(tok[0], "mtllib")) {
            if (nt < 2) FAIL(HSR_EPARSE, "'mtllib' needs a file name");
            for (int i = 1; i < nt; i++) {
                char path[8192], where[4200];
                if (tok[i][0] == '/') snprintf(path, sizeof path, "%s", tok[i]);
                else snprintf(path, sizeof path, "%s%s", dir, tok[i]);
                snprintf(where, sizeof where, "%s:%d", name, lineno);
                hsr_status st = scene_mtl_load(sc, path, where, err, errlen);
                if (st != HSR_OK) return st;
            }
        } else if (!strcmp(tok[0], "usemtl")) {
            /* a scene-file material of that name, else one of this file's .mtl
             * libraries read so far, else the obj statement's material */
            if (nt != 2) FAIL(HSR_EPARSE, "'usemtl' needs one name");
            int ms = -1, mm = -1;       /* the last definition of a name counts */
            for (int i = 0; i < sc->nmat; i++)
                if (!strcmp(sc->mat[i].name, tok[1])) {
                    if (sc->mat[i].file == 0) ms = i;
                    else if (i >= mbase) mm = i;
                }
            mat = ms >= 0 ? ms : mm >= 0 ? mm : material;
        }
#undef FAIL
    }
    return nt < 0 ? HSR_EPARSE : HSR_OK;
}
