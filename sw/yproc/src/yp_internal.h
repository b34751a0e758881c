/* yp_internal.h - private types of the y-processor (yp_*.c). */
#ifndef YP_INTERNAL_H
#define YP_INTERNAL_H
#include "yproc.h"

#define YP_PIX 4095.0                 /* intensity 1.0 in pixel units */
#define YP_ONE ((double)(1 << 24))    /* 1 pixel unit in 12.24 */

struct yp_corner { int v, g, poly, face, c; };

struct yp_shader {
    const hsr_scene *sc;
    yp_shading mode;
    hsr_view vw;
    double *cn;          /* 3 per face corner (sc->fv entry): its normal (unit): the
                          * authored `vn`, else the face normal (`s off`), else the
                          * smooth normal of its vertex in its smoothing group */
    struct yp_corner *ck;   /* the corners sorted by (vertex, group, polygon) */
    double *pn;          /* 3 per face: Newell normal of its OBJ polygon (unnormalised) */
    double *fn;          /* 3 per face: unit face normal (Newell), 0 if degenerate */
    double *flat;        /* 3 per face: flat colour, pixel units (flat mode) */
    double *gour;        /* 15 per face: I = a x + b y + c per colour, then min, max (gouraud) */
    int nl;
    double L[HSR_MAX_LIGHTS][3], Lrgb[HSR_MAX_LIGHTS][3];
    double bg[3];        /* pixel units */
    uint16_t *img;       /* background image, 12-bit, [3][H][W], or NULL */
    /* point lights (yp_shader_set_point_light): position and falloff per light */
    int Lpt[HSR_MAX_LIGHTS];
    double Lpos[HSR_MAX_LIGHTS][3], Lfall[HSR_MAX_LIGHTS];
    yp_texture *tex;     /* per material (amp 0: none), or NULL if no texture at all */
    float *texc;         /* per material: n x n coefficients (NULL entries: none) */
    int ntex;            /* materials in tex */
};

/* background at pixel (x, y), colour c, pixel units */
static inline double yp_bg(const yp_shader *s, int c, int x, int y)
{
    return s->img ? s->img[((size_t)c * (size_t)s->vw.H + (size_t)y) * (size_t)s->vw.W + (size_t)x] : s->bg[c];
}

/* Colour of face fi at pixel position (px, py) (pixel coordinates, y
 * down), pixel units: base = ambient + diffuse (+ specular unless Phong
 * mode), spec[3*l + c] = specular of light l (Phong mode; else 0). */
void yp_shade_face(const yp_shader *s, int fi, double px, double py, double base[3], double *spec);
/* yp_tex.c: the texture term of face fi at pixel position (px, py), pixel units;
 * 0 (and tex = 0) if its material has none */
int yp_shade_texture(const yp_shader *s, int fi, double px, double py, double tex[3]);
/* yp_shade.c: the world point of face fi's plane seen through pixel position (px, py) */
void yp_face_point(const yp_shader *s, int fi, double px, double py, double P[3]);

/* yp_tex.c: the .anim statements of the textured, point-lit animation (Fig. 7.27):
 * `pointlight L X Y Z [falloff R]`, `wander L SEED FRAMES X0 Y0 Z0 X1 Y1 Z1 from F0 to F1`,
 * `texture MATERIAL SCALE AMP R G B SEED [N]`.  parse: 1 taken, 0 not ours, -1 error (msg);
 * apply: sets frame f on the shader, returns 1 if a light moved since the last call. */
typedef struct yp_animx yp_animx;
int yp_animx_parse(yp_animx **x, const hsr_scene *sc, char **tok, int nt, char *msg, size_t msglen);
int yp_animx_apply(yp_animx *x, int f, yp_shader *sh, hsr_status *st);
void yp_animx_free(yp_animx *x);
/* yp_tess.c: the `tessellation` statement (1 taken, 0 not ours, -1 error in msg; appends
 * the clustered versions to sc), the offsets of the versions (each follows its object's
 * move in off[3 * obj], the hidden ones parked behind the eye), and free */
int yp_tess_parse(yp_tess **t, hsr_scene *sc, char **tok, int nt, char *msg, size_t msglen);
void yp_tess_offsets(const yp_tess *t, const hsr_scene *sc, double *off);
void yp_tess_free(yp_tess *t);

/* yp_cover.c: signed-area accumulation of a closed ring set (pixel
 * coordinates relative to the buffer origin) into acc (ny rows of
 * stride nx + 2); coverage = |prefix sum along a row|. */
void yp_cover_ring(const double *xy, int n, double *acc, int nx, int ny);

/* yp_fit.c: spline of degree order (0..2) evaluated by one Eval of that
 * order with Set knots.  f[0..n-1] target (pixel units), use[i] = 0:
 * don't care (use[0] must be 1).  clamp: Acc_mode is on (values that go
 * negative count as 0).  Appends the Sets and the Eval for the span
 * starting at column x0 to out (Sets first); returns knots or -1. */
int yp_fit(const double *f, const unsigned char *use, const double *tolv, int n, int x0, int order,
           double tol, int clamp, yp_cmdlist *out);   /* tolv: per-pixel tolerance or NULL */
/* yp_fit, temporally coherent (docs/yproc.md section 11): prev's commands i0..i1-1 (the
 * previous frame's line) are searched for an Eval of the same order at x0 and of the same
 * term (yp_cmd.term: the pattern's, 0 if untagged); where its spline (with the Sets
 * before it) still meets the tolerance against f its Sets are kept word for word, and
 * only the failing pixels are refitted, rejoining the old spline with SetI / SetdI / Set
 * of the top difference.  Falls back to yp_fit (no candidate, or a result more than a
 * quarter above yp_fit's slots).  hyst (0 < hyst <= 1): what is fitted anew is fitted at
 * hyst * tol (and hyst * tolv), so that it can stay while the target drifts by up to
 * (1 - hyst) * tol; prev NULL: yp_fit at hyst * tol.  *kept: 1 if the old spline was
 * used.  plain_out (or NULL) gets the Sets and the Eval of the fit without prev (yp_fit
 * at hyst * tol, computed anyway for the quarter rule).  Same error bound as yp_fit at
 * tol (the result is re-checked). */
int yp_fit_coherent(const double *f, const unsigned char *use, const double *tolv, int n, int x0, int order,
                    double tol, int clamp, double hyst, const yp_cmdlist *prev, int i0, int i1, unsigned term,
                    yp_cmdlist *out, yp_cmdlist *plain_out, int *kept);
/* forward differencing of an order-p Eval with knots (value per column) */
void yp_eval_values(int order, const int64_t *v0, int n, const int *knot_pos,
                    const int64_t *knot_c, int nk, int64_t *val);
void yp_format_cmd(const yp_cmd *c, char *buf, size_t n);   /* yp_emit.c: .cmd text */

#endif
