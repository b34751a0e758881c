/* yproc.h - the y-processor (docs/yproc.md, docs/shading.md): the visible
 * domains of the HSR (sw/hsr) scan-converted and shaded into per-scanline
 * x-processor command streams; plus the .anim reader of the incremental
 * pipeline.  One public header; errors are hsr_status codes.  Prefix yp_.
 * What the array makes of a stream is not modelled here: yp_simulate_line
 * runs the serialised words through sw/fmodel (fmodel.h), the one C model of
 * the x-processor, which sw/tests/test_fmodel.py holds equal to the numpy
 * golden model (sw/diffengine/model). */
#ifndef YPROC_H
#define YPROC_H
#include "hsr.h"

/* One command of docs/isa.md.  v[] are signed 12.24 values (pixel units
 * times 2^24): Eval (order 0..2): I, dI, ddI; Set*: v[0]; Eval0: v[0] is
 * the 12-bit intensity; Acc_mode: v[0] = 1 on / 0 off.  term is the host's, not the
 * instruction's: which term of the line the command was fitted for (a pattern's colour
 * function and texture, or its specular term of one light; yp_scan, 1..65535, unique
 * within the line; 0: none), so that coherent fitting (yp_options.prev) takes up a term's
 * own commands of the previous frame and no other's; it is not written to a stream and
 * yp_cmdlist_equal does not compare it (docs/yproc.md section 11.1). */
typedef enum yp_op { YP_EVAL = 1, YP_EVAL0, YP_SETI, YP_SETDI, YP_SETDDI, YP_DIS,
                     YP_ACCMODE, YP_REFRESH } yp_op;
typedef struct yp_cmd { uint8_t op, order; uint16_t x, dx; int64_t v[3]; uint16_t term; } yp_cmd;
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
    /* level of detail per line (yp_lod.c, docs/yproc.md section 10): NULL = every line
     * at the options above; else line_lod[y] in 0..YP_LOD_MAX caps line y's shading,
     * anti-aliasing, tolerance and texture (yp_lod_line_options) */
    const unsigned char *line_lod;
    int no_degrade;      /* 1: no look-ahead degradation inside a line: a line over the
                          * capacity is emitted as is and overflows (the controller drops
                          * it); the Load Monitor loop (yp_lod_update) adapts instead */
    /* temporally coherent fitting (docs/yproc.md section 11): the previous frame's lines
     * ([3 * height], colour c line y at c * height + y), or NULL.  Where a colour
     * function of the previous frame still meets the tolerance against the new exact
     * shading its instructions are kept, and only the failing spans are refitted: the
     * frame then depends on the one before it (the error bound, not the instruction,
     * is the contract) */
    const yp_cmdlist *prev;
    int coherent;        /* 1: the line structure of coherent fitting, from the first frame
                          * on (a partly covered pixel at either end of a pattern's span gets
                          * its own Eval1, so the spline between them can stay) */
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

/* Point light (docs/yproc.md section 11): light l of the scene (its colour) placed at
 * world position pos instead of being directional; falloff R > 0 scales it by
 * 1 / (1 + (d/R)^2) at distance d (0: no falloff).  Kept across yp_shader_update. */
hsr_status yp_shader_set_point_light(yp_shader *s, int l, const double pos[3], double falloff);

/* Procedural texture of a material (docs/yproc.md section 11): a periodic quadratic
 * B-spline with an n x n grid of pseudo-random coefficients in [0, 1] (seed), knots every
 * `scale` world units along the two world axes the face is least inclined to; it adds
 * amp * t(u, v) * rgb to the material's colour as its own accumulated term (Eval3 +
 * SetddI knots), which does not depend on the lights.  Along a scanline of a plane seen
 * square-on, t is exactly a C1 piecewise quadratic: what the array evaluates.  amp = 0
 * removes the texture.  Fails (HSR_EPARSE, message in err) if the material could then
 * exceed intensity 1 (the no-wrap rule of yp_shader_new). */
typedef struct yp_texture { double scale, amp, rgb[3]; unsigned seed; int n; } yp_texture;
hsr_status yp_shader_set_texture(yp_shader *s, int material, const yp_texture *t, char *err, size_t errlen);
/* texture value t(u, v) in [0, 1] at world point P of face fi (-1 if untextured) */
double yp_texture_at(const yp_shader *s, int fi, const double P[3]);

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
/* The 12-bit pixels pix[0..width-1] the commands of one line give on the array: the
 * list is serialised as yp_write_de48 writes it (with its Refresh) and run through
 * sw/fmodel (fmodel.h, fm_render), the functional model of docs/isa.md section 6 that
 * sw/tests/test_fmodel.py holds equal to the numpy golden model; the correct adder (no
 * carry bug).  yproc has no x-processor model of its own.  HSR_EINVAL for a NULL
 * argument, a width outside 1..FM_MAX_WIDTH or a Refresh inside the list (a list is one
 * line), HSR_ENOMEM when out of memory; on any error pix is all 0 (a black line). */
hsr_status yp_simulate_line(const yp_cmdlist *l, int width, uint16_t *pix);
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
/* instruction slots of b not matched, in order, by a (longest common subsequence of
 * the commands): the instructions a frame delta really changes on a line */
int yp_cmdlist_changed_slots(const yp_cmdlist *a, const yp_cmdlist *b);
/* the same, and in *cmds (if not NULL) the commands of b not matched */
int yp_cmdlist_changed(const yp_cmdlist *a, const yp_cmdlist *b, int *cmds);

/* ---- level of detail from the Load Monitor (yp_lod.c, docs/yproc.md section 10) ---- */
#define YP_LOD_MAX 5
/* the options of line level lev (0..YP_LOD_MAX; YP_LOD_MAX = the base options):
 * 5 base; 4 tolerance x4; 3 also point sampled (no anti-aliasing); 2 also Eval2
 * colour functions; 1 tolerance x16 and no texture term; 0 tolerance x64.  Each step
 * costs fewer slots on the shipped scenes (docs/yproc.md section 10; Eval1 pieces of a
 * Phong-shaded face cost more than Eval2, so "flat" is not a level) */
void yp_lod_line_options(const yp_options *base, int lev, int *maxlev, int *aa, double *tol, int *texture);
/* What the Load Monitor (rtl/ctrl/de_load_monitor.sv) records for the n lines of one
 * colour's frame, line l holding slots[l] instructions (its marker aside), in windows
 * of capacity + 1 slots (HTotal - 1): a line is on time if its instructions and its
 * marker fit in what the window has left after discarding the tail of a late line
 * before it (docs/display-controller.md section 2.4: one word per slot); issued[l] is
 * then slots[l], else the rest of the window, and late[l] = 1 (checked against the
 * Verilated controller, sw/tests/test_fig727_lod.py). */
void yp_lod_monitor(const int *slots, int n, int capacity, int *issued, int *late);
typedef struct yp_lod yp_lod;
hsr_status yp_lod_new(int height, int capacity, yp_lod **out);
void yp_lod_free(yp_lod *l);
const unsigned char *yp_lod_levels(const yp_lod *l);     /* [height], for yp_options.line_lod */
/* One step of the loop: the previous frame's per-line records (issued, late; the Load
 * Monitor's LINE[l]; for three colours the largest count and any late) -> the next
 * frame's levels (docs/yproc.md section 10).  A line raised last frame and late now
 * goes back and bars that level; a line late on its own (its window full) drops two
 * levels and bars the level; one late because a late line above shortened its window,
 * or above the high-water mark (80 % of the capacity), drops one.  A bar lasts 4
 * frames, doubling at each late retry, and lifts early when the line's load falls by
 * 30 %.  A line is raised one level when the next level's predicted load stays under
 * 70 %: its load times its own cost ratio (measured when it changed level, bounded from
 * below by late tries; forgotten when its load moves by 30 %) or the ratio learned over
 * all lines, and the same for its two neighbours.  Returns the lines whose level
 * changed. */
int yp_lod_update(yp_lod *l, const int *issued, const int *late);
/* The y-processor's own check before a frame is emitted (docs/yproc.md section 10): it
 * knows every line's instruction count when it has built it, so a line of fr (scanned
 * with o->line_lod == yp_lod_levels(l)) whose count in some colour exceeds the capacity
 * (a line the Load Monitor would record late) is lowered one level and re-scanned, until
 * it fits or is at level 0.  The exact counts at both levels set the line's cost ratio, and
 * the level above is barred as after a failed raise.  *lowered: lines lowered; [*y0, *y1)
 * (may be NULL) widened by the re-scanned lines.  The frame then equals a full scan at the
 * new levels. */
hsr_status yp_lod_fit(yp_lod *l, const yp_shader *sh, const hsr_ctx *h, const yp_options *o,
                      yp_frame *fr, int *lowered, int *y0, int *y1);

/* ---- tessellation as a level of detail (yp_tess.c, docs/yproc.md section 10) ----
 * `tessellation OBJ CELL [VERSIONS]` in an .anim: versions 1..VERSIONS-1 of obj statement
 * OBJ made by vertex clustering with grid cells CELL, 2 CELL, 4 CELL ... (world units),
 * appended to the scene as obj statements; the version shown follows OBJ's moves, the
 * others are parked behind the eye (empty domains).  A change takes effect at the next
 * yp_anim_apply (an ordinary move for the incremental HSR: its lines are damaged). */
#define YP_TESS_MAX 6
typedef struct yp_tess yp_tess;
yp_tess *yp_anim_tess(yp_anim *a);                 /* NULL: no tessellation statement */
int yp_tess_count(const yp_tess *t);               /* objects with coarser versions */
int yp_tess_versions(const yp_tess *t, int k);     /* versions of object k, its own mesh (0) included */
int yp_tess_get(const yp_tess *t, int k);          /* the version shown, 0 = the finest */
int yp_tess_obj(const yp_tess *t, int k, int v);   /* the scene's obj index of version v */
hsr_status yp_tess_set(yp_tess *t, int k, int v);
/* The loop's rules (tessellation is below level 0: the finest mesh the lines can carry at
 * some level is kept): an object whose shown version covers a line in stuck[] (over the
 * capacity at level 0, after yp_lod_fit) goes one version coarser, and the finer one waits
 * 4 frames, doubling at each failed try (up to 256).  An object that has been at its
 * version for 6 frames, none of whose lines is at level 0 (line_lod), tries the finer one:
 * the check before emission makes it coarser again if it does not fit, so a try costs
 * host time, never a late line.  frame: the frame's number.  Both return the objects
 * changed. */
int yp_tess_coarsen(yp_tess *t, const hsr_scene *sc, const hsr_ctx *h, const unsigned char *stuck, int frame);
int yp_tess_refine(yp_tess *t, const hsr_scene *sc, const hsr_ctx *h, const unsigned char *line_lod, int frame);
/* The check before emission of frame f of an animation (yproc anim --lod-predict):
 * yp_lod_fit, then, while lines are still over the capacity at level 0, yp_tess_coarsen
 * on them, the frame applied again (yp_anim_apply: the switch is a move for the
 * incremental HSR), its damaged lines re-scanned and yp_lod_fit again.  fr holds frame f
 * scanned at o->line_lod == yp_lod_levels(lod); [*y0, *y1) is widened by the re-scanned
 * lines; *lowered, *coarsened: lines lowered, objects made coarser. */
hsr_status yp_lod_fit_anim(yp_lod *lod, yp_anim *an, int f, hsr_ctx *h, yp_shader *sh, const yp_options *o,
                           yp_frame *fr, int *lowered, int *coarsened, int *y0, int *y1);

#endif
