/* mtl.c - Wavefront material library (.mtl), the part our shading model
 * has: newmtl, Kd (diffuse), d / Tr (opacity), Ks + Ns (white specular);
 * other statements are ignored.  Errors name the .mtl file and line
 * (docs/hsr.md, "Materials from .mtl files"). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

static int add_file(hsr_scene *sc, const char *path)
{
    if (!scene_grow((void **)&sc->files, &sc->capfiles, sc->nfiles + 1, sizeof(char *))) return 0;
    size_t n = strlen(path) + 1;
    char *s = malloc(n);
    if (!s) return 0;
    memcpy(s, path, n);
    sc->files[sc->nfiles++] = s;
    return 1;
}

/* 1 or 3 numbers (r, or r g b) into rgb */
static int colour(char **tok, int nt, double *rgb)
{
    if (nt != 2 && nt != 4) return 0;
    for (int c = 0; c < nt - 1; c++) if (!hsr_text_num(tok[1 + c], &rgb[c])) return 0;
    if (nt == 2) rgb[1] = rgb[2] = rgb[0];
    return 1;
}

hsr_status scene_mtl_load(hsr_scene *sc, const char *path, const char *where, char *err, size_t errlen)
{
    char *text;
    hsr_status st = hsr_read_text_file(path, &text);
    if (st != HSR_OK) {
        if (err) snprintf(err, errlen, "%s: cannot read MTL file '%s' (%s)", where, path, hsr_status_str(st));
        return st;
    }
    if (!add_file(sc, path)) { free(text); if (err) snprintf(err, errlen, "%s: out of memory", where); return HSR_ENOMEM; }
    int file = sc->nfiles, lineno = 0, cur = -1;
    char buf[4096], *tok[64];
    const char *p = text;
    st = HSR_OK;
    int nt;
    while ((nt = hsr_text_next(&p, &lineno, buf, sizeof buf, tok, 64, path, err, errlen)) > 0) {
#define FAIL(s_, ...) do { st = hsr_text_error(err, errlen, path, lineno, s_, __VA_ARGS__); goto done; } while (0)
        const char *k = tok[0];
        int known = !strcmp(k, "Kd") || !strcmp(k, "Ks") || !strcmp(k, "Ns") || !strcmp(k, "d") || !strcmp(k, "Tr");
        if (!strcmp(k, "newmtl")) {
            if (nt != 2) FAIL(HSR_EPARSE, "'newmtl' needs one name");
            if (strlen(tok[1]) >= 64) FAIL(HSR_EPARSE, "material name too long");
            if (!scene_grow((void **)&sc->mat, &sc->capmat, sc->nmat + 1, sizeof(hsr_material))) FAIL(HSR_ENOMEM, "out of memory");
            cur = sc->nmat++;
            hsr_material d = {"", {0.8, 0.8, 0.8}, 1.0, 0.0, 1.0, 0, lineno, file};
            snprintf(d.name, sizeof d.name, "%s", tok[1]);
            sc->mat[cur] = d;
            continue;
        }
        if (!known) continue;
        if (cur < 0) FAIL(HSR_EPARSE, "'%s' before 'newmtl'", k);
        hsr_material *m = &sc->mat[cur];
        double v, rgb[3];
        if (!strcmp(k, "Kd")) {
            if (!colour(tok, nt, rgb)) FAIL(HSR_EPARSE, "'Kd' needs 1 or 3 finite numbers (spectral and xyz are not read)");
            memcpy(m->rgb, rgb, sizeof rgb);
        } else if (!strcmp(k, "Ks")) {
            if (!colour(tok, nt, rgb)) FAIL(HSR_EPARSE, "'Ks' needs 1 or 3 finite numbers (spectral and xyz are not read)");
            if (rgb[0] < 0 || rgb[1] < 0 || rgb[2] < 0) FAIL(HSR_EPARSE, "'Ks' must be >= 0");
            m->ks = (rgb[0] + rgb[1] + rgb[2]) / 3;
        } else if (!strcmp(k, "Ns")) {
            if (nt != 2 || !hsr_text_num(tok[1], &v) || v < 0) FAIL(HSR_EPARSE, "'Ns' needs one finite number >= 0");
            m->shininess = v < 1 ? 1 : v;
        } else {    /* d: opacity, Tr: transparency = 1 - opacity */
            if (nt != 2 || !hsr_text_num(tok[1], &v) || v < 0 || v > 1) FAIL(HSR_EPARSE, "'%s' needs one number in [0,1]", k);
            m->opacity = !strcmp(k, "d") ? v : 1 - v;
        }
#undef FAIL
    }
    if (nt < 0) st = HSR_EPARSE;
done:
    free(text);
    return st;
}
