/* Scene fixtures shared by the y-processor tests (yp_fixture.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_fixture.h"

void ypt_write_file(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    if (f) { fputs(text, f); fclose(f); }
}

void ypt_grid_anim(const char *p, int frames)
{
    static char obj[65536];
    char path[256], text[1024];
    int k = 0, nv = 0;
    for (int gy = 0; gy < 6; gy++)
        for (int gx = 0; gx < 14; gx++) {
            double x0 = -1.9 + gx * 0.27, y0 = -0.9 + gy * 0.3, x1 = x0 + 0.2, y1 = y0 + 0.22;
            k += snprintf(obj + k, sizeof obj - (size_t)k, "v %g %g 0.3\nv %g %g 0.35\nv %g %g 0.3\nv %g %g 0.25\nf %d %d %d %d\n",
                          x0, y0, x1, y0, x1, y1, x0, y1, nv + 1, nv + 2, nv + 3, nv + 4);
            nv += 4;
        }
    snprintf(path, sizeof path, "build/%s_grid.obj", p);
    ypt_write_file(path, obj);
    snprintf(path, sizeof path, "build/%s_plate.obj", p);
    ypt_write_file(path, "v -2.4 -1.8 0\nv 2.4 -1.8 0\nv 2.4 1.8 0\nv -2.4 1.8 0\nf 1 2 3 4\n");
    snprintf(path, sizeof path, "build/%s_grid.scene", p);
    snprintf(text, sizeof text, "screen 96 48\ncamera eye 0 0 5 at 0 0 0 up 0 1 0 fov 40\nlight 0.3 0.4 1 0.6\nambient 0.2\n"
             "background 0.1 0.1 0.1\nmaterial plate 0.5 0.5 0.5\nmaterial tile 0.7 0.4 0.2 specular 0.15 20\n"
             "obj %s_plate.obj material plate\nobj %s_grid.obj material tile\n", p, p);
    ypt_write_file(path, text);
    snprintf(path, sizeof path, "build/%s_grid.anim", p);
    snprintf(text, sizeof text, "scene %s_grid.scene\nframes %d\nmove 1 5 0 0 from 6 to 9\n", p, frames);
    ypt_write_file(path, text);
}

int ypt_anim_open(ypt_anim *t, const char *path, int ext)
{
    memset(t, 0, sizeof *t);
    char err[256] = "";
    double *shade;
    yp_options_default(&t->o);
    if (yp_anim_load(path, &t->an, err, sizeof err) != HSR_OK) { fprintf(stderr, "%s\n", err); return 0; }
    t->sc = yp_anim_scene(t->an);
    t->W = t->sc->width; t->H = t->sc->height;
    if (yp_anim_apply(t->an, 0, NULL, NULL, NULL, NULL) != HSR_OK || yp_shader_new(t->sc, YP_PHONG, &t->sh, err, sizeof err) != HSR_OK
        || (ext && yp_anim_apply(t->an, 0, NULL, t->sh, NULL, NULL) != HSR_OK) || hsr_scene_build(t->sc, &t->h, &shade) != HSR_OK) return 0;
    free(shade);
    return yp_frame_new(t->W, t->H, &t->fr) == HSR_OK;
}

void ypt_anim_close(ypt_anim *t)
{
    yp_frame_free(t->fr); hsr_destroy(t->h); yp_shader_free(t->sh); yp_anim_free(t->an);
}

int ypt_anim_start(ypt_anim *t, const char *path, int ext)
{
    const int ok = ypt_anim_open(t, path, ext);
    CHECK(ok);
    if (!ok) ypt_anim_close(t);
    return ok;
}
