/* obj.c - Wavefront OBJ reader: v, f (i, i/j, i//k, i/j/k, negative
 * indices) and usemtl (selects a scene material by name); other
 * statements are ignored.  Errors name file and line. */
#include <math.h>
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

int scene_num(const char *s, double *v)
{
    char *end;
    *v = strtod(s, &end);
    return end != s && *end == 0 && isfinite(*v);
}

hsr_status hsr_obj_parse(hsr_scene *sc, const char *text, const char *name, int material,
                         char *err, size_t errlen)
{
    if (!sc || !text) return HSR_EINVAL;
    if (!name) name = "<obj>";
    int lineno = 0, mat = material, vbase = sc->nv;
    char buf[4096], *tok[512];
    const char *p = text;
    while (*p) {
        const char *e = strchr(p, '\n');
        size_t n = e ? (size_t)(e - p) : strlen(p);
        lineno++;
#define FAIL(st, ...) do { if (err) { int k_ = snprintf(err, errlen, "%s:%d: ", name, lineno); \
        if (k_ >= 0 && (size_t)k_ < errlen) snprintf(err + k_, errlen - (size_t)k_, __VA_ARGS__); } return st; } while (0)
        if (n >= sizeof buf) FAIL(HSR_EPARSE, "line too long");
        memcpy(buf, p, n); buf[n] = 0;
        p = e ? e + 1 : p + n;
        int nt = scene_tokens(buf, tok, 512);
        if (nt < 0) FAIL(HSR_EPARSE, "too many items on one line");
        if (nt == 0) continue;
        if (!strcmp(tok[0], "v")) {
            double x[3];
            if (nt < 4 || nt > 5) FAIL(HSR_EPARSE, "'v' needs 3 coordinates");
            for (int i = 0; i < 3; i++)
                if (!scene_num(tok[1 + i], &x[i])) FAIL(HSR_EPARSE, "bad or non-finite number '%s'", tok[1 + i]);
            if (!scene_grow((void **)&sc->v, &sc->capv, 3 * (sc->nv + 1), sizeof(double))) FAIL(HSR_ENOMEM, "too many vertices");
            memcpy(&sc->v[3 * sc->nv++], x, sizeof x);
        } else if (!strcmp(tok[0], "f")) {
            if (nt < 4) FAIL(HSR_EPARSE, "face needs at least 3 vertices");
            if (!scene_grow((void **)&sc->fv, &sc->capfv, sc->nfv + nt, sizeof(int))
                || !scene_grow((void **)&sc->f, &sc->capf, sc->nf + 1, sizeof(hsr_face)))
                FAIL(HSR_ENOMEM, "too many faces");
            for (int i = 1; i < nt; i++) {
                char *end;
                long v = strtol(tok[i], &end, 10);
                if (end == tok[i] || (*end && *end != '/')) FAIL(HSR_EPARSE, "bad vertex index '%s'", tok[i]);
                long nloc = sc->nv - vbase;
                long idx = v > 0 ? v - 1 : (v < 0 ? nloc + v : -1);
                if (idx < 0 || idx >= nloc) FAIL(HSR_EPARSE, "vertex index %ld out of range (1..%ld)", v, nloc);
                sc->fv[sc->nfv + i - 1] = (int)(vbase + idx);
            }
            sc->f[sc->nf].first = sc->nfv; sc->f[sc->nf].count = nt - 1; sc->f[sc->nf].material = mat;
            sc->f[sc->nf].obj = sc->nobj;
            sc->nf++; sc->nfv += nt - 1;
        } else if (!strcmp(tok[0], "usemtl")) {
            if (nt < 2) FAIL(HSR_EPARSE, "'usemtl' needs a name");
            mat = material;
            for (int i = 0; i < sc->nmat; i++) if (!strcmp(sc->mat[i].name, tok[1])) mat = i;
        }
#undef FAIL
    }
    return HSR_OK;
}
