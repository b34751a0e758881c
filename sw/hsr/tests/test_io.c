/* test_io.c - OBJ / scene parsing (errors name file and line), the
 * viewing pipeline and the JSON / SVG writers. */
#include <stdlib.h>
#include <string.h>
#include "t.h"

static const char *CUBE =
    "# unit cube\nv -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
    "vt 0 0\nvn 0 1 0\nusemtl red\nf 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 2/1 3/1 7/1 6/1\nf 3//1 4//1 8//1 7//1\nf -8 -4 -1 -5\n";

static hsr_scene *cube_scene(const char *extra)
{
    hsr_scene *sc = NULL;
    char err[256];
    if (hsr_scene_new(&sc) != HSR_OK) return NULL;
    char text[512];
    snprintf(text, sizeof text, "screen 200 150\ncamera eye 3 2 4 at 0 0 0 up 0 1 0 fov 50\n"
             "material red 1 0 0%s\n", extra);
    if (hsr_scene_parse(sc, text, "t.scene", NULL, err, sizeof err) != HSR_OK
        || hsr_obj_parse(sc, CUBE, "cube.obj", 0, err, sizeof err) != HSR_OK) {
        fprintf(stderr, "%s\n", err);
        hsr_scene_free(sc);
        return NULL;
    }
    return sc;
}

/* A scene through HSR: the scene, its context and the shading, freed by built_free. */
typedef struct {
    hsr_scene *sc;
    hsr_ctx *h;
    double *shade;
} built;

static void built_free(built *b)
{
    free(b->shade);
    hsr_destroy(b->h);
    hsr_scene_free(b->sc);
}

/* The cube scene (extra appended to its material) through HSR: 0 when a step fails. */
static int cube_built(const char *extra, built *b)
{
    b->sc = cube_scene(extra);
    b->h = NULL;
    b->shade = NULL;
    CHECK(b->sc && hsr_scene_build(b->sc, &b->h, &b->shade) == HSR_OK);
    if (!b->h) { hsr_scene_free(b->sc); return 0; }
    return 1;
}

static void test_obj_faces_slashes_negative_indices(void)
{
    hsr_scene *sc = cube_scene("");
    CHECK(sc && sc->nv == 8 && sc->nf == 6 && sc->f[5].count == 4);
    CHECK(sc && sc->fv[sc->f[5].first] == 0 && sc->fv[sc->f[5].first + 2] == 7);
    CHECK(sc && sc->f[0].material == 1);   /* usemtl red */
    hsr_scene_free(sc);
}

static void expect_err(int obj, const char *text, const char *msg)
{
    hsr_scene *sc;
    char err[256] = "";
    hsr_scene_new(&sc);
    hsr_status st = obj ? hsr_obj_parse(sc, text, "m.obj", 0, err, sizeof err)
                        : hsr_scene_parse(sc, text, "s.scene", "/nonexistent", err, sizeof err);
    CHECK(st != HSR_OK);
    if (!strstr(err, msg)) { t_failed_now = 1; fprintf(stderr, "  got '%s', want '%s'\n", err, msg); }
    hsr_scene_free(sc);
}

static void test_malformed_input_errors_name_file_and_line(void)
{
    expect_err(1, "v 0 0 0\nv 1 0 0\nf 1 2 3\n", "m.obj:3: vertex index 3 out of range");
    expect_err(1, "v 0 0 0\nf 0 1 1\n", "m.obj:2: vertex index 0 out of range");
    expect_err(1, "v 0 nan 0\n", "m.obj:1: bad or non-finite number 'nan'");
    expect_err(1, "\n\nv 1e999 0 0\n", "m.obj:3: bad or non-finite");
    expect_err(1, "v 0 0 0\nf 1 1\n", "m.obj:2: face needs at least 3");
    expect_err(1, "v 0 0\n", "m.obj:1: 'v' needs 3");
    expect_err(1, "v 0 0 0\nf 1 x 1\n", "m.obj:2: bad vertex index 'x'");
    expect_err(0, "screen 10 10\nbogus 1\n", "s.scene:2: unknown statement 'bogus'");
    expect_err(0, "screen 0 10\n", "s.scene:1: 'screen W H'");
    expect_err(0, "camera eye 0 0 inf at 0 0 0 up 0 1 0 fov 60\n", "s.scene:1: bad or non-finite");
    expect_err(0, "\ncamera eye 1 2 3 at 1 2 3 up 0 1 0 fov 60\n", "s.scene:2: camera eye and at are the same point");
    expect_err(0, "camera eye 0 0 5 at 0 0 0 up 0 0 2 fov 60\n", "s.scene:1: camera up is zero or parallel");
    expect_err(0, "camera eye 0 0 5 at 0 0 0 up 0 0 0 fov 60\n", "s.scene:1: camera up is zero or parallel");
    expect_err(0, "material m 1 0 0 opacity 2\n", "s.scene:1: opacity must be in [0,1]");
    expect_err(0, "\nobj missing.obj\n", "s.scene:2: cannot read OBJ file '/nonexistent/missing.obj'");
    expect_err(0, "obj a.obj material nope\n", "s.scene:1: unknown material 'nope'");
}

/* The readers' shared line loop (hsr_text_next): a line longer than the line buffer and
 * one with more items than a reader takes are errors at their line in every reader. */
static void test_long_and_crowded_lines_name_file_and_line(void)
{
    static char text[8192];
    int n = snprintf(text, sizeof text, "screen 10 10\n# comment\nscreen");
    while (n < 4200) text[n++] = ' ';
    snprintf(text + n, sizeof text - (size_t)n, "10 10\n");
    expect_err(0, text, "s.scene:3: line too long");
    n = snprintf(text, sizeof text, "\n\ngrid");
    for (int i = 0; i < 64; i++) n += snprintf(text + n, sizeof text - (size_t)n, " 1");
    expect_err(0, text, "s.scene:3: too many items on one line");
    n = snprintf(text, sizeof text, "v 0 0 0\nf");
    for (int i = 0; i < 512; i++) n += snprintf(text + n, sizeof text - (size_t)n, " 1");
    expect_err(1, text, "m.obj:2: too many items on one line");
    expect_err(1, "v 0 0 0\n\nv 1 0 0 0 0\n", "m.obj:3: 'v' needs 3");
}

static void test_cube_scene_three_faces_visible(void)
{
    built b;
    if (!cube_built("", &b)) return;
    hsr_scene *sc = b.sc;
    hsr_ctx *h = b.h;
    int vis = 0;
    for (int id = 0; id < 6; id++) vis += t_visible_area(h, id) > 0;
    CHECK(vis == 3);
    CHECK(hsr_check(h) == HSR_OK);
    CHECK(hsr_write_llr_json("build/test_cube.json", h, sc) == HSR_OK);
    CHECK(hsr_write_svg("build/test_cube.svg", h, sc, b.shade) == HSR_OK);
    FILE *f = fopen("build/test_cube.json", "r");
    char buf[256] = "";
    CHECK(f && fgets(buf, sizeof buf, f) && strstr(buf, "hsr-llr-1"));
    if (f) fclose(f);
    CHECK(hsr_write_svg("/nonexistent/x.svg", h, sc, b.shade) == HSR_EIO);
    built_free(&b);
}

static void test_transparent_cube_shows_back_faces(void)
{
    built b;
    if (!cube_built(" opacity 0.5", &b)) return;
    hsr_ctx *h = b.h;
    int maxdepth = 0;
    for (int s = 0; s < hsr_llr_slots(h); s++) {
        int nv;
        if (hsr_llr_get(h, s, NULL, NULL, &nv, NULL) && nv > maxdepth) maxdepth = nv;
    }
    CHECK(maxdepth == 2);      /* front face over back face everywhere */
    CHECK(hsr_check(h) == HSR_OK);
    built_free(&b);
}

static void test_face_behind_camera_is_clipped(void)
{
    hsr_scene *sc;
    char err[256];
    hsr_scene_new(&sc);
    CHECK(hsr_scene_parse(sc, "camera eye 0 0 0 at 0 0 -1 up 0 1 0 fov 60\n", "c", NULL, err, sizeof err) == HSR_OK);
    CHECK(hsr_obj_parse(sc, "v -1 -1 1\nv 1 -1 1\nv 0 1 1\nf 1 2 3\nv -1 -1 -1\nv 1 -1 1\nv 0 1 -3\nf 4 5 6\n",
                        "c.obj", 0, err, sizeof err) == HSR_OK);
    hsr_ctx *h = NULL;
    double *shade = NULL;
    CHECK(hsr_scene_build(sc, &h, &shade) == HSR_OK);
    CHECK(h && t_visible_area(h, 0) == 0 && t_visible_area(h, 1) > 0);
    free(shade); hsr_destroy(h); hsr_scene_free(sc);
}

void suite_io(void)
{
    RUN(test_obj_faces_slashes_negative_indices);
    RUN(test_malformed_input_errors_name_file_and_line);
    RUN(test_long_and_crowded_lines_name_file_and_line);
    RUN(test_cube_scene_three_faces_visible);
    RUN(test_transparent_cube_shows_back_faces);
    RUN(test_face_behind_camera_is_clipped);
}
