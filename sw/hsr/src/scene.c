/* scene.c - the scene file (camera, lights, materials, objects); the
 * format is defined in docs/hsr.md.  Errors name file and line. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

#define MAX_FILE (256L << 20)

hsr_status hsr_scene_new(hsr_scene **out)
{
    if (!out) return HSR_EINVAL;
    hsr_scene *sc = calloc(1, sizeof *sc);
    if (!sc) return HSR_ENOMEM;
    sc->width = 640; sc->height = 480; sc->grid = 32;
    sc->eye[2] = 5; sc->up[1] = 1; sc->fov_deg = 60; sc->near_z = 0.1;
    sc->light[0] = 1; sc->light[1] = 1; sc->light[2] = 1; sc->light_i = 0.8; sc->ambient = 0.2;
    sc->bg[0] = sc->bg[1] = sc->bg[2] = 1;
    hsr_light dl = {{1, 1, 1}, {0.8, 0.8, 0.8}, 0};
    sc->lights[0] = dl; sc->nlights = 1;
    if (!scene_grow((void **)&sc->mat, &sc->capmat, 1, sizeof(hsr_material))) { free(sc); return HSR_ENOMEM; }
    hsr_material d = {"default", {0.8, 0.8, 0.8}, 1.0, 0.0, 1.0, 0, 0, 0};
    sc->mat[0] = d; sc->nmat = 1;
    *out = sc;
    return HSR_OK;
}

void hsr_scene_free(hsr_scene *sc)
{
    if (!sc) return;
    for (int i = 0; i < sc->nfiles; i++) free(sc->files[i]);
    free(sc->files);
    free(sc->v); free(sc->fv); free(sc->fvn); free(sc->vn); free(sc->f); free(sc->mat); free(sc);
}

hsr_status hsr_read_text_file(const char *path, char **text)
{
    *text = NULL;
    FILE *f = fopen(path, "rb");
    if (!f) return HSR_EIO;
    char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (cap - n < 65536) {
            if (cap > (size_t)MAX_FILE) { free(buf); fclose(f); return HSR_ELIMIT; }
            char *q = realloc(buf, cap + 65536 + 1);
            if (!q) { free(buf); fclose(f); return HSR_ENOMEM; }
            buf = q; cap += 65536;
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0) break;
    }
    int bad = ferror(f);
    fclose(f);
    if (bad) { free(buf); return HSR_EIO; }
    buf[n] = 0;
    if (strlen(buf) != n) { free(buf); return HSR_EPARSE; }   /* NUL byte */
    *text = buf;
    return HSR_OK;
}

static int nums(char **tok, int n, double *out)
{
    for (int i = 0; i < n; i++) if (!hsr_text_num(tok[i], &out[i])) return 0;
    return 1;
}

hsr_status hsr_scene_parse(hsr_scene *sc, const char *text, const char *name, const char *dir,
                           char *err, size_t errlen)
{
    if (!sc || !text) return HSR_EINVAL;
    if (!name) name = "<scene>";
    int lineno = 0;
    char buf[4096], *tok[64];
    const char *p = text;
    int nt;
    while ((nt = hsr_text_next(&p, &lineno, buf, sizeof buf, tok, 64, name, err, errlen)) > 0) {
#define FAIL(st, ...) return hsr_text_error(err, errlen, name, lineno, st, __VA_ARGS__)
        double v[16];
        const char *k = tok[0];
        if (!strcmp(k, "screen")) {
            if (nt != 3 || !nums(tok + 1, 2, v) || v[0] < 1 || v[1] < 1 || v[0] > 32767 || v[1] > 32767
                || v[0] != (int)v[0] || v[1] != (int)v[1])
                FAIL(HSR_EPARSE, "'screen W H' needs integers in 1..32767");
            sc->width = (int)v[0]; sc->height = (int)v[1];
        } else if (!strcmp(k, "grid")) {
            if (nt != 2 || !nums(tok + 1, 1, v) || v[0] < 1 || v[0] > 4096 || v[0] != (int)v[0])
                FAIL(HSR_EPARSE, "'grid N' needs an integer in 1..4096");
            sc->grid = (int)v[0];
        } else if (!strcmp(k, "camera")) {
            if (nt != 15 || strcmp(tok[1], "eye") || strcmp(tok[5], "at") || strcmp(tok[9], "up")
                || strcmp(tok[13], "fov"))
                FAIL(HSR_EPARSE, "expected 'camera eye X Y Z at X Y Z up X Y Z fov DEG'");
            double c[10];
            if (!nums(tok + 2, 3, c) || !nums(tok + 6, 3, c + 3) || !nums(tok + 10, 3, c + 6) || !nums(tok + 14, 1, c + 9))
                FAIL(HSR_EPARSE, "bad or non-finite number in camera");
            if (!(c[9] > 1 && c[9] < 179)) FAIL(HSR_EPARSE, "fov must be in (1, 179) degrees");
            memcpy(sc->eye, c, sizeof sc->eye); memcpy(sc->at, c + 3, sizeof sc->at);
            memcpy(sc->up, c + 6, sizeof sc->up); sc->fov_deg = c[9];
            /* the same test the projection makes (hsr_view_make), here where the line is known */
            hsr_view vw;
            if (!hsr_view_make(sc, &vw))
                FAIL(HSR_EPARSE, "%s", c[0] == c[3] && c[1] == c[4] && c[2] == c[5]
                     ? "camera eye and at are the same point: no view direction"
                     : "camera up is zero or parallel to the view direction (eye - at)");
        } else if (!strcmp(k, "near")) {
            if (nt != 2 || !nums(tok + 1, 1, v) || !(v[0] > 0)) FAIL(HSR_EPARSE, "'near D' needs D > 0");
            sc->near_z = v[0];
        } else if (!strcmp(k, "light")) {
            /* light DX DY DZ I  or  light DX DY DZ R G B; every line adds one */
            if ((nt != 5 && nt != 7) || !nums(tok + 1, nt - 1, v))
                FAIL(HSR_EPARSE, "'light DX DY DZ I' or 'light DX DY DZ R G B' needs finite numbers");
            if (!(v[0] != 0 || v[1] != 0 || v[2] != 0)) FAIL(HSR_EPARSE, "light direction is zero");
            if (sc->nlights == 1 && sc->lights[0].line == 0) sc->nlights = 0;   /* replace the default */
            if (sc->nlights == HSR_MAX_LIGHTS) FAIL(HSR_ELIMIT, "more than %d lights", HSR_MAX_LIGHTS);
            hsr_light *l = &sc->lights[sc->nlights++];
            memcpy(l->dir, v, sizeof l->dir);
            for (int c = 0; c < 3; c++) l->rgb[c] = nt == 5 ? v[3] : v[3 + c];
            for (int c = 0; c < 3; c++) if (l->rgb[c] < 0) FAIL(HSR_EPARSE, "light intensity must be >= 0");
            l->line = lineno;
            if (sc->nlights == 1) {
                memcpy(sc->light, v, sizeof sc->light);
                sc->light_i = (l->rgb[0] + l->rgb[1] + l->rgb[2]) / 3;
            }
        } else if (!strcmp(k, "ambient")) {
            if (nt != 2 || !nums(tok + 1, 1, v)) FAIL(HSR_EPARSE, "'ambient A' needs a finite number");
            sc->ambient = v[0]; sc->ambient_line = lineno;
        } else if (!strcmp(k, "background")) {
            if (nt == 3 && !strcmp(tok[1], "image")) {
                if (tok[2][0] == '/' || !dir) snprintf(sc->bg_image, sizeof sc->bg_image, "%s", tok[2]);
                else snprintf(sc->bg_image, sizeof sc->bg_image, "%s/%s", dir, tok[2]);
                sc->bg_image_line = lineno;
                continue;
            }
            if (nt != 4 || !nums(tok + 1, 3, v)) FAIL(HSR_EPARSE, "'background R G B' needs 3 numbers");
            memcpy(sc->bg, v, sizeof sc->bg);
        } else if (!strcmp(k, "material")) {
            /* material NAME R G B [opacity A] [specular KS N] [flat] */
            if (nt < 5 || !nums(tok + 2, 3, v)) FAIL(HSR_EPARSE, "expected 'material NAME R G B [opacity A] [specular KS N] [flat]'");
            double op = 1, ks = 0, shin = 1;
            int flat = 0;
            for (int i = 5; i < nt;) {
                if (!strcmp(tok[i], "opacity") && i + 1 < nt && nums(tok + i + 1, 1, &op)) i += 2;
                else if (!strcmp(tok[i], "specular") && i + 2 < nt && nums(tok + i + 1, 1, &ks) && nums(tok + i + 2, 1, &shin)) i += 3;
                else if (!strcmp(tok[i], "flat")) { flat = 1; i++; }
                else FAIL(HSR_EPARSE, "expected 'material NAME R G B [opacity A] [specular KS N] [flat]'");
            }
            if (!(op >= 0 && op <= 1)) FAIL(HSR_EPARSE, "opacity must be in [0,1]");
            if (!(ks >= 0 && shin >= 1)) FAIL(HSR_EPARSE, "specular needs KS >= 0 and N >= 1");
            if (strlen(tok[1]) >= 64) FAIL(HSR_EPARSE, "material name too long");
            if (!scene_grow((void **)&sc->mat, &sc->capmat, sc->nmat + 1, sizeof(hsr_material))) FAIL(HSR_ENOMEM, "out of memory");
            hsr_material *m = &sc->mat[sc->nmat++];
            snprintf(m->name, sizeof m->name, "%s", tok[1]);
            m->rgb[0] = v[0]; m->rgb[1] = v[1]; m->rgb[2] = v[2]; m->opacity = op;
            m->ks = ks; m->shininess = shin; m->flat = flat; m->line = lineno; m->file = 0;
        } else if (!strcmp(k, "obj")) {
            if (nt != 2 && !(nt == 4 && !strcmp(tok[2], "material"))) FAIL(HSR_EPARSE, "expected 'obj PATH [material NAME]'");
            int mat = 0;
            if (nt == 4) {
                mat = -1;
                for (int i = 0; i < sc->nmat; i++) if (!strcmp(sc->mat[i].name, tok[3])) mat = i;
                if (mat < 0) FAIL(HSR_EPARSE, "unknown material '%s'", tok[3]);
            }
            char path[4096];
            if (tok[1][0] == '/' || !dir) snprintf(path, sizeof path, "%s", tok[1]);
            else snprintf(path, sizeof path, "%s/%s", dir, tok[1]);
            char *text2;
            hsr_status st = hsr_read_text_file(path, &text2);
            if (st != HSR_OK) FAIL(st, "cannot read OBJ file '%s' (%s)", path, hsr_status_str(st));
            int nf0 = sc->nf;
            st = hsr_obj_parse(sc, text2, path, mat, err, errlen);
            free(text2);
            if (st != HSR_OK) return st;
            for (int i = nf0; i < sc->nf; i++) sc->f[i].obj = sc->nobj;
            sc->nobj++;
        } else FAIL(HSR_EPARSE, "unknown statement '%s'", k);
#undef FAIL
    }
    return nt < 0 ? HSR_EPARSE : HSR_OK;
}

hsr_status hsr_scene_load(const char *path, hsr_scene **out, char *err, size_t errlen)
{
    if (!path || !out) return HSR_EINVAL;
    *out = NULL;
    char *text;
    hsr_status st = hsr_read_text_file(path, &text);
    if (st != HSR_OK) {
        if (err) snprintf(err, errlen, "%s: cannot read (%s)", path, hsr_status_str(st));
        return st;
    }
    char dir[4096];
    snprintf(dir, sizeof dir, "%s", path);
    char *slash = strrchr(dir, '/');
    if (slash) *slash = 0; else snprintf(dir, sizeof dir, ".");
    hsr_scene *sc;
    st = hsr_scene_new(&sc);
    if (st == HSR_OK) {
        snprintf(sc->name, sizeof sc->name, "%s", path);
        st = hsr_scene_parse(sc, text, path, dir, err, errlen);
    }
    free(text);
    if (st != HSR_OK) { hsr_scene_free(sc); return st; }
    *out = sc;
    return HSR_OK;
}
