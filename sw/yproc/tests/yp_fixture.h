/* Scene fixtures shared by the y-processor tests (one definition, used by
 * test_yp_tex_lod.c and test_yp_tess.c). */
#ifndef YP_FIXTURE_H
#define YP_FIXTURE_H

#include "yp_internal.h"

/* write text to path (a test's build file); a failed open is left to the reader's error */
void ypt_write_file(const char *path, const char *text);

/* The overloading grid: 6 x 14 small Phong tiles in front of a plate at 96 x 48, the grid
 * moving off the screen at frames 6-9. Writes build/<p>_grid.obj, build/<p>_plate.obj,
 * build/<p>_grid.scene and build/<p>_grid.anim (frames frames). */
void ypt_grid_anim(const char *p, int frames);

/* An animation at frame 0: its scene, a Phong shader (with the .anim's point lights and
 * textures only when ext), HSR built, a frame, default options. */
typedef struct ypt_anim {
    yp_anim *an; hsr_scene *sc; yp_shader *sh; hsr_ctx *h; yp_frame *fr; yp_options o; int W, H;
} ypt_anim;

/* 1 when all of it was made; 0 after a failure (what was made is left for ypt_anim_close) */
int ypt_anim_open(ypt_anim *t, const char *path, int ext);
void ypt_anim_close(ypt_anim *t);
/* ypt_anim_open, a test failure when it fails (and what it made freed): 0 then */
int ypt_anim_start(ypt_anim *t, const char *path, int ext);

#endif
