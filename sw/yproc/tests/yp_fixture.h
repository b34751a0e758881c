/* Scene fixtures shared by the y-processor tests (one definition, used by
 * test_yp_tex_lod.c and test_yp_tess.c). */
#ifndef YP_FIXTURE_H
#define YP_FIXTURE_H

/* write text to path (a test's build file); a failed open is left to the reader's error */
void ypt_write_file(const char *path, const char *text);

/* The overloading grid: 6 x 14 small Phong tiles in front of a plate at 96 x 48, the grid
 * moving off the screen at frames 6-9. Writes build/<p>_grid.obj, build/<p>_plate.obj,
 * build/<p>_grid.scene and build/<p>_grid.anim (frames frames). */
void ypt_grid_anim(const char *p, int frames);

#endif
