/* test_obj.c - OBJ as users write it (issue 21), as read: quads and n-gons,
 * mtllib/usemtl, and file:line errors (the normals and rendering of the same
 * meshes: sw/yproc/tests/test_obj_shading.c).  Meshes: tests/obj/ (the same
 * files sw/tests/test_obj_features.py renders against the reference). */
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "internal.h"

#define load_obj(obj, err, n) t_load_obj(HSR_TEST_OBJ, obj, err, n)

/* no `s` statement: one implicit group, all smooth (as before issue 21); faces before
 * the first `s` of a file that has some form that group too */
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
    hsr_status st = hsr_read_text_file("build/t_obj.obj", &text) == HSR_OK
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

void suite_obj(void)
{
    RUN(test_obj_quads_and_ngons_triangulated_like_the_reference);
    RUN(test_mtl_kd_sets_diffuse);
    RUN(test_mtl_missing_file_names_line);
    RUN(test_mtl_errors_name_mtl_file_and_line);
    RUN(test_obj_errors_name_file_and_line);
}
