/* json.c - the JSON writers (schemas in docs/hsr.md):
 *   hsr_write_llr_json (--dump-llr): every visible (LLR) domain with its MLR id,
 *     parents, rings and plane, in pixel coordinates;
 *   hsr_write_input_json (--dump-input): every MLR domain, as the HSR got it;
 *   hsr_write_scene_json (`yproc read`): the scene as the readers understood it, which
 *     is what the Python reference renderer draws from (one scene reader, in C). */
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "internal.h"

/* a domain's rings as [[[x, y], ...], ...] in pixels */
static hsr_status put_rings(FILE *f, const hsr_domain *d)
{
    const double S = HSR_SUBPIXEL;
    double *xy; int *len, nr;
    hsr_status st = hsr_domain_rings(d, &xy, &len, &nr);
    if (st != HSR_OK) return st;
    fputc('[', f);
    for (int r = 0, off = 0; r < nr; off += len[r], r++) {
        fprintf(f, "%s[", r ? ", " : "");
        for (int i = 0; i < len[r]; i++)
            fprintf(f, "%s[%.17g, %.17g]", i ? ", " : "", xy[2 * (off + i)] / S, xy[2 * (off + i) + 1] / S);
        fputc(']', f);
    }
    fputc(']', f);
    free(xy); free(len);
    return HSR_OK;
}

/* The start both domain dumps share: the arguments checked, the file opened (*f) and
 * written up to the opening of its list (named list). */
static hsr_status open_dump(FILE **f, const char *path, const hsr_ctx *h, const hsr_scene *sc,
                            const char *format, const char *list)
{
    if (!path || !h || !sc) return HSR_EINVAL;
    *f = fopen(path, "w");
    if (!*f) return HSR_EIO;
    fprintf(*f, "{\"format\": \"%s\", \"units_per_pixel\": %d, \"width\": %d, \"height\": %d,\n"
                " \"mlr_count\": %d, \"%s\": [", format, HSR_SUBPIXEL, sc->width, sc->height,
            hsr_mlr_slots(h), list);
    return HSR_OK;
}

/* ... and its end: the list closed, the file closed; st, or HSR_EIO if closing failed. */
static hsr_status close_dump(FILE *f, hsr_status st)
{
    fprintf(f, "\n]}\n");
    if (fclose(f) != 0 && st == HSR_OK) st = HSR_EIO;
    return st;
}

hsr_status hsr_write_llr_json(const char *path, const hsr_ctx *h, const hsr_scene *sc)
{
    FILE *f;
    hsr_status st = open_dump(&f, path, h, sc, "hsr-llr-1", "domains");
    if (st != HSR_OK) return st;
    const double S = HSR_SUBPIXEL;
    int first = 1;
    for (int s = 0; s < hsr_llr_slots(h) && st == HSR_OK; s++) {
        const hsr_domain *d; const int *par; int nv, np;
        if (!hsr_llr_get(h, s, &d, &par, &nv, &np)) continue;
        hsr_plane pl = {0, 0, 0};
        hsr_mlr_get(h, par[0], NULL, &pl, NULL, NULL, NULL);
        fprintf(f, "%s\n  {\"mlr\": %d, \"parents\": [", first ? "" : ",", par[0]);
        first = 0;
        for (int i = 0; i < nv; i++) fprintf(f, "%s%d", i ? ", " : "", par[i]);
        fprintf(f, "], \"hidden_parents\": [");
        for (int i = nv; i < np; i++) fprintf(f, "%s%d", i > nv ? ", " : "", par[i]);
        fprintf(f, "], \"area_px2\": %.17g, \"plane\": [%.17g, %.17g, %.17g],\n   \"rings\": ",
                hsr_domain_area(d) / (S * S), pl.a * S, pl.b * S, pl.c);
        st = put_rings(f, d);
        fprintf(f, "}");
    }
    return close_dump(f, st);
}

/* --dump-input: every MLR domain (the projected, clipped, quantised input faces) with id,
 * opacity, plane and rings, pixel coordinates, y down (schema "hsr-input-1" in
 * docs/hsr.md; used by sw/tests/test_hsr_oracle.py). */
hsr_status hsr_write_input_json(const char *path, const hsr_ctx *h, const hsr_scene *sc)
{
    FILE *f;
    hsr_status st = open_dump(&f, path, h, sc, "hsr-input-1", "polygons");
    if (st != HSR_OK) return st;
    const double S = HSR_SUBPIXEL;
    for (int id = 0, first = 1; id < hsr_mlr_slots(h) && st == HSR_OK; id++) {
        const hsr_domain *d; hsr_plane pl; double op;
        if (!hsr_mlr_get(h, id, &d, &pl, &op, NULL, NULL)) continue;   /* removed (--ops) */
        fprintf(f, "%s\n  {\"id\": %d, \"opacity\": %.17g, \"area_px2\": %.17g,"
                   " \"plane\": [%.17g, %.17g, %.17g],\n   \"rings\": ",
                first ? "" : ",", id, op, hsr_domain_area(d) / (S * S), pl.a * S, pl.b * S, pl.c);
        st = put_rings(f, d);
        fprintf(f, "}");
        first = 0;
    }
    return close_dump(f, st);
}

/* doubles as %.17g: read back by Python's json they are the same doubles */
static void put_vec(FILE *f, const double *v, int n)
{
    fputc('[', f);
    for (int i = 0; i < n; i++) fprintf(f, "%s%.17g", i ? ", " : "", v[i]);
    fputc(']', f);
}

/* a JSON string: the names come from user files, so quote and escape them */
static void put_str(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') fprintf(f, "\\%c", c);
        else if (c < 0x20) fprintf(f, "\\u%04x", c);
        else fputc(c, f);
    }
    fputc('"', f);
}

static void put_ints(FILE *f, const char *key, const int *v, int n, const char *end)
{
    fprintf(f, "\"%s\": [", key);
    for (int i = 0; i < n; i++) fprintf(f, "%s%d", i ? (i % 32 ? ", " : ",\n  ") : "", v[i]);
    fprintf(f, "]%s", end);
}

/* one column of the face table: the fields by offset, so the five columns share a loop */
static void put_face_col(FILE *f, const char *key, const hsr_scene *sc, size_t off, const char *end)
{
    fprintf(f, "\"%s\": [", key);
    for (int i = 0; i < sc->nf; i++) {
        int v;
        memcpy(&v, (const char *)&sc->f[i] + off, sizeof v);
        fprintf(f, "%s%d", i ? (i % 32 ? ", " : ",\n  ") : "", v);
    }
    fprintf(f, "]%s", end);
}

hsr_status hsr_write_scene_json(const char *path, const hsr_scene *sc)
{
    if (!path || !sc) return HSR_EINVAL;
    FILE *f = fopen(path, "w");
    if (!f) return HSR_EIO;
    fprintf(f, "{\"format\": \"hsr-scene-1\", \"file\": ");
    put_str(f, sc->name);
    fprintf(f, ",\n \"screen\": [%d, %d], \"grid\": %d,\n \"camera\": {\"eye\": ", sc->width, sc->height, sc->grid);
    put_vec(f, sc->eye, 3); fprintf(f, ", \"at\": "); put_vec(f, sc->at, 3);
    fprintf(f, ", \"up\": "); put_vec(f, sc->up, 3);
    fprintf(f, ", \"fov\": %.17g, \"near\": %.17g},\n \"ambient\": %.17g, \"background\": ",
            sc->fov_deg, sc->near_z, sc->ambient);
    put_vec(f, sc->bg, 3);
    fprintf(f, ", \"background_image\": ");
    if (sc->bg_image[0]) put_str(f, sc->bg_image); else fprintf(f, "null");
    fprintf(f, ", \"background_image_line\": %d", sc->bg_image_line);
    fprintf(f, ",\n \"lights\": [");
    for (int i = 0; i < sc->nlights; i++) {
        fprintf(f, "%s{\"dir\": ", i ? ", " : "");
        put_vec(f, sc->lights[i].dir, 3); fprintf(f, ", \"rgb\": "); put_vec(f, sc->lights[i].rgb, 3);
        fprintf(f, "}");
    }
    fprintf(f, "],\n \"materials\": [");
    for (int i = 0; i < sc->nmat; i++) {
        const hsr_material *m = &sc->mat[i];
        fprintf(f, "%s\n  {\"name\": ", i ? "," : "");
        put_str(f, m->name);
        fprintf(f, ", \"kd\": "); put_vec(f, m->rgb, 3);
        fprintf(f, ", \"opacity\": %.17g, \"ks\": %.17g, \"n\": %.17g, \"flat\": %s}",
                m->opacity, m->ks, m->shininess, m->flat ? "true" : "false");
    }
    fprintf(f, "],\n \"vertices\": [");
    for (int i = 0; i < sc->nv; i++) { fprintf(f, i ? (i % 8 ? ", " : ",\n  ") : ""); put_vec(f, sc->v + 3 * (size_t)i, 3); }
    fprintf(f, "],\n \"normals\": [");
    for (int i = 0; i < sc->nvn; i++) { fprintf(f, i ? (i % 8 ? ", " : ",\n  ") : ""); put_vec(f, sc->vn + 3 * (size_t)i, 3); }
    fprintf(f, "],\n \"faces\": {");
    put_face_col(f, "first", sc, offsetof(hsr_face, first), ",\n  ");
    put_face_col(f, "count", sc, offsetof(hsr_face, count), ",\n  ");
    put_face_col(f, "material", sc, offsetof(hsr_face, material), ",\n  ");
    put_face_col(f, "smooth", sc, offsetof(hsr_face, smooth), ",\n  ");
    put_face_col(f, "poly", sc, offsetof(hsr_face, poly), "},\n ");
    fprintf(f, "\"corners\": {");
    put_ints(f, "vertex", sc->fv, sc->nfv, ",\n  ");
    put_ints(f, "normal", sc->fvn, sc->nfv, "}}\n");
    int bad = ferror(f);
    return fclose(f) != 0 || bad ? HSR_EIO : HSR_OK;
}
