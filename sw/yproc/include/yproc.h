/* yproc.h - the y-processor (docs/yproc.md, docs/shading.md): the visible
 * domains of the HSR (sw/hsr) scan-converted and shaded into per-scanline
 * x-processor command streams; plus the .anim reader of the incremental
 * pipeline.  One public header; errors are hsr_status codes.  Prefix yp_. */
#ifndef YPROC_H
#define YPROC_H
#include "hsr.h"

/* One command of docs/isa.md.  v[] are signed 12.24 values (pixel units
 * times 2^24): Eval (order 0..2): I, dI, ddI; Set*: v[0]; Eval0: v[0] is
 * the 12-bit intensity; Acc_mode: v[0] = 1 on / 0 off. */
typedef enum yp_op { YP_EVAL = 1, YP_EVAL0, YP_SETI, YP_SETDI, YP_SETDDI, YP_DIS,
                     YP_ACCMODE, YP_REFRESH } yp_op;
typedef struct yp_cmd { uint8_t op, order; uint16_t x, dx; int64_t v[3]; } yp_cmd;
typedef struct yp_cmdlist { yp_cmd *c; int n, cap, slots; } yp_cmdlist;
int yp_cmd_slots(const yp_cmd *c);                 /* instructions (Table 7.2) */
hsr_status yp_cmdlist_push(yp_cmdlist *l, yp_cmd c);
void yp_cmdlist_free(yp_cmdlist *l);

typedef enum yp_shading { YP_FLAT = 1, YP_GOURAUD = 2, YP_PHONG = 3 } yp_shading;

typedef struct yp_options {
    int capacity;        /* instruction slots per line and colour (HTotal - 1) */
    int aa;              /* 1: exact unweighted area sampling, 0: point sampling */
    yp_shading shading;  /* best colour function (degradation goes down from it) */
    double tol;          /* fit tolerance of each quadratic term, pixel units */
} yp_options;
void yp_options_default(yp_options *o);            /* 640x480 capacity, aa, phong, tol 1 */
/* slots per line of a video mode "640x480" | "640x485" | "1280x1024"
 * (docs/display-controller.md section 3: HTotal - 1), 0 if unknown */
int yp_mode_capacity(const char *mode, int *width, int *height);

/* Per-scene shading data: view, vertex normals, lights.  Checks the scene
 * against the no-wrap rule A + sum I_l (kd + KS) <= 1 per channel
 * (err: "file:line: message" naming the material line). */
typedef struct yp_shader yp_shader;
hsr_status yp_shader_new(const hsr_scene *sc, yp_shading mode, yp_shader **out,
                         char *err, size_t errlen);
void yp_shader_free(yp_shader *s);
/* Recompute what depends on the vertices / lights after the scene changed. */
hsr_status yp_shader_update(yp_shader *s, const hsr_scene *sc);

typedef struct yp_line_stats {
    int cmds[3], slots[3];   /* per colour, without the end-of-line marker */
    int patterns;            /* visible patterns (pattern rows) on the line */
    int partial;             /* partly covered pixels (one Eval1 each, per colour) */
    int degraded[3];         /* patterns whose colour function was lowered */
    int merged[3];           /* 1: even Eval1 per pattern did not fit; the line is
                              * one spline through the exact values (tolerance raised) */
    int overflow[3];         /* 1 if even that did not fit (the controller drops it) */
} yp_line_stats;

typedef struct yp_frame {
    int width, height;
    yp_cmdlist *line;        /* [3 * height]: colour c, line y at c * height + y */
    yp_line_stats *st;       /* [height] */
    double *ideal;           /* [3 * height * width] exact target, pixel units */
    int n_eval[4];           /* Evals emitted per order+1 (1 = Eval1 ...) */
    int n_knots, n_dis, n_partial, n_spec;
} yp_frame;
hsr_status yp_frame_new(int width, int height, yp_frame **out);
void yp_frame_free(yp_frame *f);

/* Scan-convert lines y0..y1-1 of the LLR in h into fr (those lines are
 * replaced).  Every line starts with the background term. */
hsr_status yp_scan(const yp_shader *sh, const hsr_ctx *h, const yp_options *o,
                   int y0, int y1, yp_frame *fr);
/* Run the commands of one line through the x-processor semantics of
 * docs/isa.md section 6 (the subset yp emits): 12-bit pixels, width px. */
void yp_simulate_line(const yp_cmdlist *l, int width, uint16_t *pix);
/* Streams: .de48 (docs/formats.md section 2) and .cmd text (docs/isa.md
 * section 9, exact hex); each line is followed by a Refresh. */
hsr_status yp_write_de48(const yp_frame *fr, int colour, const char *path);
hsr_status yp_write_cmd(const yp_frame *fr, int colour, const char *path);

/* ---- animation (yproc anim, docs/yproc.md "Animation scenes") ------ */
typedef struct yp_anim yp_anim;
/* Reads an animation file (base scene + per-frame changes). */
hsr_status yp_anim_load(const char *path, yp_anim **out, char *err, size_t errlen);
void yp_anim_free(yp_anim *a);
int yp_anim_frames(const yp_anim *a);
hsr_scene *yp_anim_scene(yp_anim *a);          /* the live scene (frame last applied) */
/* Set the scene to frame f.  With h != NULL also update the HSR
 * incrementally (one hsr_change_many: the moved faces, the new opacities) and the
 * shader; *y0, *y1 receive the lines that may have changed (y0 == y1:
 * none).  With h == NULL only the scene changes (for a full rebuild). */
hsr_status yp_anim_apply(yp_anim *a, int f, hsr_ctx *h, yp_shader *sh, int *y0, int *y1);
int yp_cmdlist_equal(const yp_cmdlist *a, const yp_cmdlist *b);

#endif
