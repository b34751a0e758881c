/* test_obj.c - OBJ as users write it (issue 21): vn with negative indices,
 * smoothing groups, quads and n-gons, mtllib/usemtl, meshes with holes and
 * non-manifold edges, and file:line errors.  Meshes: tests/obj/ (the same
 * files sw/tests/test_obj_features.py renders against the reference). */
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"

#define SCENE_HEAD "screen 32 16\ncamera eye 1.5 1.2 6 at 0 0 0 up 0 1 0 fov 42\nlight 0.3 0.5 0.8 0.7\n" \
                   "ambient 0.2\nmaterial green 0.1 0.7 0.2\nmaterial grey 0.75 0.75 0.75\n"

/* scene text (its obj paths relative to tests/obj) -> scene, or NULL with the error in err */
static hsr_scene *load(const char *text, char *err, size_t n)
{
    hsr_scene *sc = NULL;
    if (hsr_scene_new(&sc) != HSR_OK) return NULL;
    snprintf(sc->name, sizeof sc->name, "tests/obj/t.scene");
    if (hsr_scene_parse(sc, text, "tests/obj/t.scene", "tests/obj", err, n) != HSR_OK) {
        hsr_scene_free(sc);
        return NULL;
    }
    return sc;
}

static hsr_scene *load_obj(const char *obj, char *err, size_t n)
{
    char text[1024];
    snprintf(text, sizeof text, SCENE_HEAD "obj %s material grey\n", obj);
    hsr_scene *sc = load(text, err, n);
    if (!sc) fprintf(stderr, "  %s\n", err);
    return sc;
}

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

/* no `s` statement: one implicit group, all smooth (as before issue 21); faces before
 * the first `s` of a file that has some form that group too */
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

static void test_obj_quads_and_ngons_triangulated_like_the_reference(void)
{
    char err[512];
    hsr_scene *sc = load_obj("polygons.obj", err, sizeof err);
    if (!sc) { CHECK(0); return; }
    /* pentagon whole; L hexagon 4 triangles; dart 2; saddle 2; band whole */
    CHECK(sc->nf == 1 + 4 + 2 + 2 + 1 && sc->npoly == 5);
    CHECK(sc->f[0].count == 5 && sc->f[0].poly == 0);
    for (int fi = 1; fi < 9; fi++) CHECK(sc->f[fi].count == 3);
    CHECK(sc->f[4].poly == 1 && sc->f[5].poly == 2 && sc->f[6].poly == 2 && sc->f[8].poly == 3);
    /* the dart (v 12..15): ears (15, 12, 13) then (13, 14, 15), as reference._triangulate */
    const int dart[6] = {14, 11, 12, 12, 13, 14};
    for (int i = 0; i < 6; i++) CHECK(sc->fv[sc->f[5].first + i] == dart[i]);
    CHECK(sc->fvn[sc->f[5].first] == 3 && sc->fvn[sc->f[5].first + 1] == 0);
    /* poly_triangulate directly: convex planar quad -> whole fan; concave -> ears */
    const double sq[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
    int tri[6], whole;
    CHECK(poly_triangulate(sq, 4, tri, &whole) == 2 && whole && tri[3] == 0 && tri[4] == 2 && tri[5] == 3);
    const double saddle[12] = {0, 0, 0.3, 1, 0, -0.3, 1, 1, 0.3, 0, 1, -0.3};
    CHECK(poly_triangulate(saddle, 4, tri, &whole) == 2 && !whole && tri[0] == 0 && tri[2] == 2);
    /* the HSR sees the saddle as two planes, the band between them */
    hsr_ctx *h = NULL;
    double *shade = NULL;
    CHECK(hsr_scene_build(sc, &h, &shade) == HSR_OK && hsr_check(h) == HSR_OK);
    CHECK(h && t_visible_area(h, 7) > 0 && t_visible_area(h, 8) > 0 && t_visible_area(h, 9) > 0);
    free(shade); hsr_destroy(h); hsr_scene_free(sc);
}

static void test_mtl_kd_sets_diffuse(void)
{
    char err[512];
    hsr_scene *sc = load_obj("mtl.obj", err, sizeof err);
    if (!sc) { CHECK(0); return; }
    CHECK(sc->nfiles == 1 && strstr(sc->files[0], "tests/obj/mats.mtl"));
    const hsr_material *m = sc->mat;
    const hsr_face *f = sc->f;
    CHECK(sc->nf == 5);
    CHECK(!strcmp(m[f[0].material].name, "red") && m[f[0].material].file == 1 && m[f[0].material].line == 2);
    CHECK(m[f[0].material].rgb[0] == 0.8 && m[f[0].material].rgb[1] == 0.1 && m[f[0].material].opacity == 1);
    CHECK(!strcmp(m[f[1].material].name, "glass") && m[f[1].material].opacity == 0.5);
    CHECK_NEAR(m[f[1].material].ks, 0.2, 1e-15);
    CHECK(m[f[1].material].shininess == 20);
    CHECK(m[f[2].material].rgb[2] == 0.2 && m[f[2].material].opacity == 0.75);   /* Kd 0.2, Tr 0.25 */
    CHECK_NEAR(m[f[2].material].ks, 0.3, 1e-15);
    /* usemtl green: the scene file's green (file 0), not mats.mtl's */
    CHECK(!strcmp(m[f[3].material].name, "green") && m[f[3].material].file == 0 && m[f[3].material].rgb[1] == 0.7);
    CHECK(!strcmp(m[f[4].material].name, "grey"));         /* unknown name: the obj line's */
    hsr_scene_free(sc);
}

static void expect(const char *obj, const char *mtl, const char *msg)
{
    char err[512] = "";
    FILE *f = fopen("build/t_obj.obj", "w");
    if (f) { fputs(obj, f); fclose(f); }
    f = mtl ? fopen("build/t_obj.mtl", "w") : NULL;
    if (f) { fputs(mtl, f); fclose(f); }
    hsr_scene *sc = NULL;
    char *text = NULL;
    hsr_scene_new(&sc);
    hsr_status st = scene_read_file("build/t_obj.obj", &text) == HSR_OK
                    ? hsr_obj_parse(sc, text, "build/t_obj.obj", 0, err, sizeof err) : HSR_EIO;
    CHECK(st != HSR_OK);
    if (!strstr(err, msg)) { t_failed_now = 1; fprintf(stderr, "  got '%s', want '%s'\n", err, msg); }
    free(text); hsr_scene_free(sc);
}

static void test_mtl_missing_file_names_line(void)
{
    expect("# x\n\nmtllib nosuch.mtl\n", NULL, "build/t_obj.obj:3: cannot read MTL file 'build/nosuch.mtl'");
}

static void test_mtl_errors_name_mtl_file_and_line(void)
{
    expect("mtllib t_obj.mtl\n", "# c\nKd 1 0 0\n", "build/t_obj.mtl:2: 'Kd' before 'newmtl'");
    expect("mtllib t_obj.mtl\n", "newmtl a\nKd 1 0\n", "build/t_obj.mtl:2: 'Kd' needs 1 or 3 finite");
    expect("mtllib t_obj.mtl\n", "newmtl a\nKd spectral a.spd\n", "build/t_obj.mtl:2: 'Kd' needs 1 or 3");
    expect("mtllib t_obj.mtl\n", "newmtl a\n\nd 1.5\n", "build/t_obj.mtl:3: 'd' needs one number in [0,1]");
    expect("mtllib t_obj.mtl\n", "newmtl a\nTr x\n", "build/t_obj.mtl:2: 'Tr' needs one number in [0,1]");
    expect("mtllib t_obj.mtl\n", "newmtl a\nNs -1\n", "build/t_obj.mtl:2: 'Ns' needs one finite number");
    expect("mtllib t_obj.mtl\n", "newmtl a\nKs -1\n", "build/t_obj.mtl:2: 'Ks' must be >= 0");
    expect("mtllib t_obj.mtl\n", "newmtl\n", "build/t_obj.mtl:1: 'newmtl' needs one name");
}

static void test_obj_errors_name_file_and_line(void)
{
    expect("v 0 0 0\nvn 0 0 x\n", NULL, "build/t_obj.obj:2: bad or non-finite number 'x'");
    expect("v 0 0 0\nvn 0 0\n", NULL, "build/t_obj.obj:2: 'vn' needs 3 numbers");
    expect("vn 0 0 0\n", NULL, "build/t_obj.obj:1: 'vn' has zero length");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//2 3//1\n", NULL,
           "build/t_obj.obj:5: normal index 2 out of range (1..1)");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//-2 2//1 3//1\n", NULL,
           "build/t_obj.obj:5: normal index -2 out of range (1..1)");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1 2/1 3/1\n", NULL, "build/t_obj.obj:4: texture index 1 out of range (1..0)");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -4 2 3\n", NULL, "build/t_obj.obj:4: vertex index -4 out of range (1..3)");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/ 2 3\n", NULL, "build/t_obj.obj:4: bad vertex index '1/'");
    expect("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/1/1/1 2 3\n", NULL, "build/t_obj.obj:4: bad vertex index '1/1/1/1'");
    expect("v 0 0 0 1 2\n", NULL, "build/t_obj.obj:1: 'v' needs 3 coordinates");
    expect("s on\n", NULL, "build/t_obj.obj:1: 's' needs a group number >= 0 or 'off'");
    expect("usemtl\n", NULL, "build/t_obj.obj:1: 'usemtl' needs one name");
    expect("\nmtllib\n", NULL, "build/t_obj.obj:2: 'mtllib' needs a file name");
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

void suite_obj(void)
{
    RUN(test_obj_vn_negative_index);
    RUN(test_obj_smoothing_group_off_is_flat);
    RUN(test_obj_no_smoothing_statement_is_all_smooth);
    RUN(test_obj_quads_and_ngons_triangulated_like_the_reference);
    RUN(test_mtl_kd_sets_diffuse);
    RUN(test_mtl_missing_file_names_line);
    RUN(test_mtl_errors_name_mtl_file_and_line);
    RUN(test_obj_errors_name_file_and_line);
    RUN(test_mtl_nowrap_check_names_mtl_line);
    RUN(test_obj_holes_and_non_manifold_edges_render);
}
