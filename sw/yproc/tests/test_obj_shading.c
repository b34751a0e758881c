/* test_obj_shading.c - the corner normals and rendering of OBJ as users write
 * it (issue 21): vn with negative indices, smoothing groups, holes and
 * non-manifold edges, and the .mtl no-wrap check naming its line.  Meshes:
 * sw/hsr/tests/obj/ (HSR_TEST_OBJ; also rendered by sw/tests/test_obj_features.py). */
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"

#define load_obj(obj, err, n) t_load_obj(HSR_TEST_OBJ, obj, err, n)

static double angle(const double *a, const double *b)
{
    double d = 0, la = 0, lb = 0;
    for (int k = 0; k < 3; k++) { d += a[k] * b[k]; la += a[k] * a[k]; lb += b[k] * b[k]; }
    double c = d / sqrt(la * lb);
    return acos(c > 1 ? 1 : c < -1 ? -1 : c);
}

/* the corner normal of face fi at its corner holding world vertex (x, y) */
static const double *corner_at(const yp_shader *sh, const hsr_scene *sc, int fi, double x, double y)
{
    for (int i = 0; i < sc->f[fi].count; i++) {
        const double *v = &sc->v[3 * sc->fv[sc->f[fi].first + i]];
        if (fabs(v[0] - x) < 1e-12 && fabs(v[1] - y) < 1e-12) return &sh->cn[3 * (sc->f[fi].first + i)];
    }
    return NULL;
}

static void test_obj_vn_negative_index(void)
{
    char err[512];
    hsr_scene *sc = load_obj("vn_negative.obj", err, sizeof err);
    yp_shader *sh = NULL;
    CHECK(sc && sc->nvn == 4 && sc->nf == 2 && sc->f[1].count == 4);   /* convex planar: kept whole */
    if (!sc) return;
    /* f -5//-3 -2//-1 -1//-1 -4//-2 after 6 v and 4 vn: v 2 5 6 3, vn 2 4 4 3 */
    const int wv[4] = {1, 4, 5, 2}, wn[4] = {1, 3, 3, 2};
    for (int i = 0; i < 4; i++) {
        CHECK(sc->fv[sc->f[1].first + i] == wv[i]);
        CHECK(sc->fvn[sc->f[1].first + i] == wn[i]);
    }
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_OK);
    if (sh) {   /* the shader uses the authored normals, normalised */
        const double vn4[3] = {0.7, -0.3, 1};
        const double *n = &sh->cn[3 * (sc->f[1].first + 1)];
        CHECK(angle(n, vn4) < 1e-12);
        CHECK_NEAR(n[0] * n[0] + n[1] * n[1] + n[2] * n[2], 1, 1e-12);
    }
    yp_shader_free(sh); hsr_scene_free(sc);
}

static void test_obj_smoothing_group_off_is_flat(void)
{
    char err[512];
    hsr_scene *sc = load_obj("smoothing.obj", err, sizeof err);
    yp_shader *sh = NULL;
    if (!sc) { CHECK(0); return; }
    CHECK(sc->nf == 6 && sc->f[0].smooth == 1 && sc->f[2].smooth == 0 && sc->f[4].smooth == 2 && sc->f[5].smooth == 1);
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_OK);
    if (!sh) { hsr_scene_free(sc); return; }
    /* s off: every corner has the face normal */
    for (int fi = 2; fi <= 3; fi++)
        for (int i = 0; i < 4; i++) CHECK(angle(&sh->cn[3 * (sc->f[fi].first + i)], &sh->fn[3 * fi]) < 1e-12);
    /* x = -2 is shared by strips 1 and 2 (both s 1): one smooth normal, between them */
    const double *a = corner_at(sh, sc, 0, -2, -1), *b = corner_at(sh, sc, 1, -2, -1);
    CHECK(a && b && angle(a, b) < 1e-12 && angle(a, &sh->fn[0]) > 0.3);
    /* x = -1: strip 2 (s 1) next to strip 3 (s off): strip 2's own normal */
    a = corner_at(sh, sc, 1, -1, 1);
    CHECK(a && angle(a, &sh->fn[3 * 1]) < 1e-12);
    /* x = 2: strip 5 (s 2) and strip 6 (s 1) do not average */
    a = corner_at(sh, sc, 4, 2, -1); b = corner_at(sh, sc, 5, 2, -1);
    CHECK(a && b && angle(a, &sh->fn[3 * 4]) < 1e-12 && angle(b, &sh->fn[3 * 5]) < 1e-12 && angle(a, b) > 0.5);
    yp_shader_free(sh); hsr_scene_free(sc);
}

static void test_obj_no_smoothing_statement_is_all_smooth(void)
{
    hsr_scene *sc;
    yp_shader *sh = NULL;
    char err[256];
    hsr_scene_new(&sc);
    CHECK(hsr_obj_parse(sc, "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 1\nv 2 1 1\nf 1 2 3 4\nf 2 5 6 3\n",
                        "a.obj", 0, err, sizeof err) == HSR_OK);
    CHECK(sc->f[0].smooth == -1 && sc->f[1].smooth == -1);
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_OK);
    if (sh) {
        CHECK(angle(&sh->cn[3 * 1], &sh->cn[3 * 4]) < 1e-12);      /* vertex 2 in both faces */
        CHECK(angle(&sh->cn[3 * 1], &sh->fn[0]) > 0.1);
    }
    yp_shader_free(sh); hsr_scene_free(sc);
}

static void test_mtl_nowrap_check_names_mtl_line(void)
{
    FILE *f = fopen("build/t_hot.mtl", "w");
    if (f) { fputs("newmtl ok\nKd 0.1\nnewmtl hot\nKd 0.9 0.5 0.5\nKs 0.3\n", f); fclose(f); }
    hsr_scene *sc;
    yp_shader *sh = NULL;
    char err[512] = "";
    hsr_scene_new(&sc);
    CHECK(hsr_obj_parse(sc, "mtllib t_hot.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl hot\nf 1 2 3\n",
                        "build/t.obj", 0, err, sizeof err) == HSR_OK);
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_EPARSE);
    CHECK(strstr(err, "build/t_hot.mtl:3: material 'hot' can exceed intensity 1 in R") != NULL);
    if (!strstr(err, "build/t_hot.mtl:3:")) fprintf(stderr, "  got '%s'\n", err);
    yp_shader_free(sh); hsr_scene_free(sc);
}

static void test_obj_holes_and_non_manifold_edges_render(void)
{
    char err[512];
    hsr_scene *sc = load_obj("holes.obj", err, sizeof err);
    if (!sc) { CHECK(0); return; }
    CHECK(sc->nf == 7);
    hsr_ctx *h = NULL;
    double *shade = NULL;
    yp_shader *sh = NULL;
    yp_frame *fr = NULL;
    yp_options o;
    yp_options_default(&o);
    CHECK(hsr_scene_build(sc, &h, &shade) == HSR_OK && hsr_check(h) == HSR_OK);
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_OK);
    CHECK(yp_frame_new(sc->width, sc->height, &fr) == HSR_OK);
    if (h && sh && fr) {
        CHECK(yp_scan(sh, h, &o, 0, sc->height, fr) == HSR_OK);
        for (int fi = 0; fi < sc->nf; fi++)          /* every normal defined */
            for (int i = 0; i < sc->f[fi].count; i++)
                CHECK(isfinite(sh->cn[3 * (sc->f[fi].first + i)]));
        CHECK(t_visible_area(h, 0) > 0);             /* the back wall, seen through the hole */
    }
    yp_frame_free(fr); yp_shader_free(sh); free(shade); hsr_destroy(h); hsr_scene_free(sc);
}

void suite_obj_shading(void)
{
    RUN(test_obj_vn_negative_index);
    RUN(test_obj_smoothing_group_off_is_flat);
    RUN(test_obj_no_smoothing_statement_is_all_smooth);
    RUN(test_mtl_nowrap_check_names_mtl_line);
    RUN(test_obj_holes_and_non_manifold_edges_render);
}
