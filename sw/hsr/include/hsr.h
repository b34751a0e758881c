/* hsr.h - exact incremental hidden-surface removal on domains
 * (Kuijk 1995, chapter 5). The one public header of sw/hsr.
 *
 * Numeric policy (see docs/hsr.md): 2D coordinates are integers in
 * fixed-point units of 1/HSR_SUBPIXEL pixel, |x|,|y| <= HSR_COORD_MAX.
 * Every edge of every domain lies on a line through two such integer
 * points; edge endpoints have rational y.  All 2D predicates are exact
 * (128-bit integer arithmetic), so the visibility map has no cracks and
 * no overlaps.  Depth (planes) is double; depth order of two surfaces is
 * decided once per side of a snapped integer crossing line. */
#ifndef HSR_H
#define HSR_H

#include <stddef.h>
#include <stdint.h>

typedef enum hsr_status {
    HSR_OK = 0,
    HSR_EINVAL,     /* NULL pointer, bad count, NaN/inf, bad id */
    HSR_ERANGE,     /* coordinate outside [-HSR_COORD_MAX, HSR_COORD_MAX] */
    HSR_ENOMEM,     /* allocation failed */
    HSR_ELIMIT,     /* a documented size limit was exceeded */
    HSR_ENOTFOUND,  /* id not present / nothing at that point */
    HSR_EPARSE,     /* malformed input file */
    HSR_EIO         /* file could not be read or written */
} hsr_status;

const char *hsr_status_str(hsr_status s);

#define HSR_SUBPIXEL 256                    /* units per pixel */
#define HSR_COORD_MAX ((int64_t)8388607)    /* 2^23 - 1 units = 32767.99 px */
#define HSR_MAX_RING_POINTS 1000000         /* per polygon, all rings */
#define HSR_MAX_PREFIX 60                   /* transparent layers per point */

/* ---- extents ------------------------------------------------------ */
typedef struct hsr_extent { int64_t left, bot, right, top; } hsr_extent;
int hsr_extent_overlap(hsr_extent a, hsr_extent b);       /* closed boxes */

/* ---- domains (Sorted-Edge representation, section 5.2.2) ---------- */
typedef struct hsr_domain hsr_domain;

/* Polygon with nrings rings (ring i has ring_len[i] points, xy holds
 * x0,y0,x1,y1,... for all rings in order).  Even-odd fill: concave,
 * self-intersecting, holes and disconnected parts are allowed; zero-area
 * input gives an empty domain (HSR_OK). */
hsr_status hsr_domain_from_rings(const int64_t *xy, const int *ring_len,
                                 int nrings, hsr_domain **out);
hsr_domain *hsr_domain_clone(const hsr_domain *d);
void hsr_domain_free(hsr_domain *d);
int hsr_domain_is_empty(const hsr_domain *d);
int hsr_domain_edge_count(const hsr_domain *d);
double hsr_domain_area(const hsr_domain *d);            /* units^2 */
hsr_extent hsr_domain_extent(const hsr_domain *d);       /* conservative */
/* 1 if (x,y) is inside.  Half-open: a point on a left/bottom boundary is
 * inside, on a right/top boundary outside, so adjacent disjoint domains
 * never both contain a point. */
int hsr_domain_contains(const hsr_domain *d, int64_t x, int64_t y);
/* Edges in Sorted-Edge order (monotone in x for every stabbing query).
 * Endpoints are returned as doubles (x_bot,y_bot,x_top,y_top). */
hsr_status hsr_domain_edge(const hsr_domain *d, int i, double seg[4]);
/* Boundary as closed rings (doubles, units): outer rings counter-clockwise
 * (positive shoelace area), holes clockwise.  free() *xy and *ring_len. */
hsr_status hsr_domain_rings(const hsr_domain *d, double **xy, int **ring_len,
                            int *nrings);

typedef enum hsr_boolop { HSR_UNION, HSR_INTERSECT, HSR_SUBTRACT, HSR_XOR } hsr_boolop;
hsr_status hsr_domain_boolean(const hsr_domain *a, const hsr_domain *b,
                              hsr_boolop op, hsr_domain **out);

/* ---- planes and separate(A,B) (section 5.4.1) --------------------- */
/* depth z = a*x + b*y + c (x,y in units); smaller z is nearer. */
typedef struct hsr_plane { double a, b, c; } hsr_plane;

typedef struct hsr_surface {
    const hsr_domain *dom;
    hsr_plane plane;
    int opaque;     /* 1 opaque, 0 transparent */
    int id;         /* tie-break for coincident planes: lower id in front */
} hsr_surface;

typedef enum hsr_sep_case {
    HSR_SEP_DISJOINT = 1,   /* A and B */
    HSR_SEP_OPAQUE,         /* A-B and B-A */
    HSR_SEP_A_TRANSPARENT,  /* A_-B, B-A and A n_B B */
    HSR_SEP_B_TRANSPARENT,  /* A-B, B_-A and B n_A A */
    HSR_SEP_BOTH            /* A_-B, B_-A, A n_B B and B n_A A */
} hsr_sep_case;

typedef struct hsr_separation {
    hsr_sep_case kind;
    hsr_domain *a;        /* A, A-B or A_-B (colour of A) */
    hsr_domain *b;        /* B, B-A or B_-A (colour of B) */
    hsr_domain *a_over_b; /* A n_B B (mixed colour) or NULL */
    hsr_domain *b_over_a; /* B n_A A (mixed colour) or NULL */
} hsr_separation;

hsr_status hsr_separate(const hsr_surface *A, const hsr_surface *B,
                        hsr_separation *out);
void hsr_separation_free(hsr_separation *s);

/* ---- Grid-List (section 5.3.2); Slice-List is the case nx == 1 ----- */
typedef struct hsr_gridlist hsr_gridlist;
hsr_status hsr_gridlist_create(hsr_extent window, int nx, int ny,
                               hsr_gridlist **out);
void hsr_gridlist_free(hsr_gridlist *g);
hsr_status hsr_gridlist_insert(hsr_gridlist *g, int id, hsr_extent e);
hsr_status hsr_gridlist_remove(hsr_gridlist *g, int id);
/* Calls fn(id, ctx) for every stored extent overlapping q; returns the
 * number of list entries visited (for benchmarks) or -1 on error. */
long hsr_gridlist_query(const hsr_gridlist *g, hsr_extent q,
                        void (*fn)(int id, void *ctx), void *ctx);

/* ---- incremental HSR (sections 5.4.2, 5.4.5) ---------------------- */
typedef struct hsr_ctx hsr_ctx;

typedef struct hsr_config {
    hsr_extent window;  /* area of interest (grid), units */
    int grid_nx, grid_ny;  /* 1..4096 each */
} hsr_config;

hsr_status hsr_create(const hsr_config *cfg, hsr_ctx **out);
void hsr_destroy(hsr_ctx *h);

/* Add a polygon (as hsr_domain_from_rings) to the MLR and update the LLR.
 * opacity in [0,1]; opacity >= 1 is opaque.  *id_out receives the id. */
hsr_status hsr_add(hsr_ctx *h, const int64_t *xy, const int *ring_len,
                   int nrings, hsr_plane plane, double opacity, int *id_out);
hsr_status hsr_remove(hsr_ctx *h, int id);
hsr_status hsr_move(hsr_ctx *h, int id, const int64_t *xy,
                    const int *ring_len, int nrings, hsr_plane plane);
hsr_status hsr_set_opacity(hsr_ctx *h, int id, double opacity);
/* Several changes as one (an object's faces dragged, a material's opacity):
 * the changed domains leave the LLR together, the damage is repaired once, then
 * they are added back with their new geometry and opacity.  xy == NULL keeps a
 * domain and its plane; opacity < 0 keeps the opacity.  The same result as the
 * changes one by one (hsr_move, hsr_set_opacity), cheaper.  Every id must be
 * present (HSR_ENOTFOUND) and listed once (HSR_EINVAL); nothing changes on an
 * argument error. */
typedef struct hsr_change {
    int id;
    const int64_t *xy; const int *ring_len; int nrings;   /* as hsr_move */
    hsr_plane plane;
    double opacity;
} hsr_change;
hsr_status hsr_change_many(hsr_ctx *h, const hsr_change *c, int n);
/* Discard the LLR and re-add every MLR domain in id order. */
hsr_status hsr_rebuild(hsr_ctx *h);

typedef enum hsr_pick_mode {
    HSR_PICK_VISIBLE = 0,   /* first parent */
    HSR_PICK_NEXT_BEHIND,   /* second parent */
    HSR_PICK_FIRST_OPAQUE   /* first opaque parent */
} hsr_pick_mode;
hsr_status hsr_pick(const hsr_ctx *h, int64_t x, int64_t y,
                    hsr_pick_mode mode, int *id_out);

/* LLR iteration: slots 0..hsr_llr_slots()-1, hsr_llr_get returns 0 for an
 * empty slot.  parents[0..nvis-1] are ordered front to back up to and
 * including the first opaque one; parents[nvis..npar-1] are hidden
 * parents (unordered, conservative: may include non-covering ones). */
int hsr_llr_slots(const hsr_ctx *h);
int hsr_llr_get(const hsr_ctx *h, int slot, const hsr_domain **dom,
                const int **parents, int *nvis, int *npar);
int hsr_mlr_slots(const hsr_ctx *h);
/* 1 if id is present; fills its counts of visibles / invisibles. */
int hsr_mlr_get(const hsr_ctx *h, int id, const hsr_domain **dom,
                hsr_plane *plane, double *opacity, int *nvisibles,
                int *ninvisibles);
/* Check internal consistency (administration lists, grid). */
hsr_status hsr_check(const hsr_ctx *h);

/* ---- scenes: Wavefront OBJ + scene file (docs/hsr.md) ------------- */
/* ks, shininess: white specular coefficient and exponent (default 0, 1);
 * flat: shade with the face normal; line: line of its definition in the
 * scene file (file == 0) or in the .mtl file sc->files[file - 1]. */
typedef struct hsr_material {
    char name[64]; double rgb[3]; double opacity;
    double ks, shininess; int flat, line, file;
} hsr_material;
/* obj: index of the `obj` statement the face came from (0-based).
 * smooth: OBJ smoothing group: -1 none given (the file's implicit group),
 * 0 `s off` (shaded with the face normal), N > 0 `s N`.
 * poly: index of the OBJ polygon; a polygon that is not convex and planar
 * is stored as consecutive triangle faces with the same poly (docs/hsr.md). */
typedef struct hsr_face { int first, count, material, obj, smooth, poly; } hsr_face;
#define HSR_MAX_LIGHTS 16
/* Directional light: dir points from the surface to the light (not
 * normalised here), rgb intensity, scene-file line. */
typedef struct hsr_light { double dir[3], rgb[3]; int line; } hsr_light;

typedef struct hsr_scene {
    double *v; int nv, capv;          /* world x,y,z per vertex */
    int *fv; int nfv, capfv;          /* 0-based vertex indices of faces */
    int *fvn; int capfvn;             /* per fv entry: 0-based index into vn, -1 = none */
    double *vn; int nvn, capvn;       /* world x,y,z per OBJ `vn` (as written) */
    int npoly;                        /* OBJ polygons read (hsr_face.poly) */
    char **files; int nfiles, capfiles;   /* .mtl paths (hsr_material.file - 1) */
    hsr_face *f; int nf, capf;
    hsr_material *mat; int nmat, capmat;  /* mat[0] is "default" */
    int width, height, grid;
    double eye[3], at[3], up[3], fov_deg, near_z;
    double light[3], light_i, ambient, bg[3];
    /* every `light` statement (light[]/light_i above mirror lights[0]);
     * the default is one light (1 1 1, 0.8) with line 0, replaced by the
     * first `light` statement */
    hsr_light lights[HSR_MAX_LIGHTS]; int nlights;
    int nobj;                         /* `obj` statements read */
    int ambient_line;                 /* scene-file line of `ambient` (0: default) */
    char bg_image[4096];              /* `background image FILE` (binary PPM), "" = none */
    int bg_image_line;                /* its scene-file line (messages) */
    char name[1024];                  /* scene file path (messages), "" if parsed from text */
} hsr_scene;

/* err receives "file:line: message" on failure (may be NULL).
 * hsr_obj_parse: name is the OBJ's path, for messages and as the directory
 * `mtllib` files are relative to; material is the `obj` line's material
 * (docs/hsr.md "OBJ": usemtl precedence). */
hsr_status hsr_scene_new(hsr_scene **out);
void hsr_scene_free(hsr_scene *sc);
hsr_status hsr_obj_parse(hsr_scene *sc, const char *text, const char *name,
                         int material, char *err, size_t errlen);
hsr_status hsr_scene_parse(hsr_scene *sc, const char *text, const char *name,
                           const char *dir, char *err, size_t errlen);
hsr_status hsr_scene_load(const char *path, hsr_scene **out, char *err, size_t errlen);
/* Viewing + perspective + near/screen clipping; MLR id i == face i (a
 * face clipped away or seen edge-on becomes an empty domain).  shade
 * receives 4 doubles per face: r, g, b (lit) and opacity; free() it. */
hsr_status hsr_scene_build(const hsr_scene *sc, hsr_ctx **out, double **shade);
/* --dump-llr JSON and SVG writers (schema in docs/hsr.md). */
hsr_status hsr_write_llr_json(const char *path, const hsr_ctx *h, const hsr_scene *sc);
hsr_status hsr_write_input_json(const char *path, const hsr_ctx *h, const hsr_scene *sc);
/* `yproc read`: the scene as read (camera, lights, materials, vertices, `vn`, faces with
 * their corners, smoothing groups and polygons), schema "hsr-scene-1" in docs/hsr.md:
 * the geometry the Python reference renderer draws, so the formats have one reader. */
hsr_status hsr_write_scene_json(const char *path, const hsr_scene *sc);
hsr_status hsr_write_svg(const char *path, const hsr_ctx *h, const hsr_scene *sc,
                         const double *shade);

/* ---- viewing (project.c) and the text readers' helpers, shared with the
 * y-processor (sw/yproc) and its .anim reader ---------------------------- */

/* camera basis (u right, v up, w backwards), focal length in px, screen size;
 * hsr_view_make returns 0 when eye == at or up is parallel to the view */
typedef struct hsr_view { double u[3], v[3], w[3], f, W, H; } hsr_view;
int hsr_view_make(const hsr_scene *sc, hsr_view *vw);
/* scratch size (points) hsr_face_project needs for any face of sc */
int hsr_face_cap(const hsr_scene *sc);
/* Face fi -> quantised screen polygon q (returns its point count, 0 if clipped away
 * or edge-on) and its depth plane.  a, b: scratch of 3*cap doubles, q: 2*cap. */
int hsr_face_project(const hsr_scene *sc, const hsr_view *vw, int fi, double *a, double *b,
                     int64_t *q, hsr_plane *plane);
/* The next line at *p (moved past it), copied into buf and split into at most max
 * tokens: the token count, -1 if the line does not fit in cap bytes, -2 if it has more
 * than max items. */
int hsr_text_line(const char **p, char *buf, size_t cap, char **tok, int max);
int hsr_text_num(const char *s, double *v);          /* a finite number: 1, else 0 */
/* a whole text file (NUL bytes rejected); free() *text */
hsr_status hsr_read_text_file(const char *path, char **text);

#endif
