/* test_yp_tess.c - the Load Monitor loop's check before emission (yp_lod_fit) and
 * tessellation as a level of detail (yp_tess.c), docs/yproc.md section 10:
 *   - with the check, no line is ever late in the monitor's model, from frame 0 on, and
 *     quality comes back when the load falls;
 *   - vertex clustering makes coarser versions with fewer faces whose vertices stay near
 *     the mesh; switching versions is an incremental move that equals a full rebuild;
 *   - on a mesh too dense for the line even at level 0, the loop makes it coarser before
 *     the frame is emitted and finer again when its lines get shorter. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"
#include "yp_fixture.h"


static int max_slots(const yp_frame *fr, int y)
{
    int s = 0;
    for (int c = 0; c < 3; c++) if (fr->st[y].slots[c] > s) s = fr->st[y].slots[c];
    return s;
}

/* late lines of the frame in the monitor's model (any colour) */
static int late_lines(const yp_frame *fr, int cap, int *iss, int *late)
{
    int H = fr->height, n = 0, *sl = malloc(sizeof(int) * 3 * (size_t)H);
    if (!sl) return -1;
    int *ic = sl + H, *lc = sl + 2 * H;
    for (int y = 0; y < H; y++) iss[y] = late[y] = 0;
    for (int c = 0; c < 3; c++) {
        for (int y = 0; y < H; y++) sl[y] = fr->st[y].slots[c];
        yp_lod_monitor(sl, H, cap, ic, lc);
        for (int y = 0; y < H; y++) { if (ic[y] > iss[y]) iss[y] = ic[y]; late[y] |= lc[y]; }
    }
    for (int y = 0; y < H; y++) n += late[y];
    free(sl);
    return n;
}

/* 1 if fr equals a full rebuild of the scene as it is now at the same options */
static int equals_full(ypt_anim *t, const yp_options *o)
{
    hsr_ctx *hf;
    double *shade;
    yp_frame *ff;
    if (hsr_scene_build(t->sc, &hf, &shade) != HSR_OK) return 0;
    free(shade);
    int ok = yp_frame_new(t->W, t->H, &ff) == HSR_OK && yp_scan(t->sh, hf, o, 0, t->H, ff) == HSR_OK;
    for (int i = 0; ok && i < 3 * t->H; i++) ok = yp_cmdlist_equal(&ff->line[i], &t->fr->line[i]);
    yp_frame_free(ff);
    hsr_destroy(hf);
    return ok;
}

/* A grid of small Phong tiles over a plate at 60 % of the capacity its busiest line needs
 * (as test_lod_loop_removes_overflow_and_restores_quality), the grid leaving at frames
 * 6-9: with the check before emission no frame has a late line, frame 0 included; only
 * the lines over the capacity are lowered; every frame equals a full scan at its levels;
 * after the grid has gone every line is back at full quality. */
static void test_lod_fit_no_late_line_from_frame_0_and_quality_back(void)
{
    ypt_grid_anim("tf", 24);
    ypt_anim t;
    if (!ypt_anim_start(&t, "build/tf_grid.anim", 1)) return;
    int H = t.H;
    yp_options o = t.o;
    CHECK(yp_scan(t.sh, t.h, &o, 0, H, t.fr) == HSR_OK);
    int busiest = 0, over = 0;
    for (int y = 0; y < H; y++) if (max_slots(t.fr, y) > busiest) busiest = max_slots(t.fr, y);
    o.capacity = busiest * 6 / 10;
    for (int y = 0; y < H; y++) over += max_slots(t.fr, y) > o.capacity;
    o.no_degrade = 1;
    yp_lod *lod = NULL;
    CHECK(yp_lod_new(H, o.capacity, &lod) == HSR_OK);
    o.line_lod = yp_lod_levels(lod);
    int iss[64], late[64], lowered0 = -1;
    double mean = 0;
    for (int f = 0; f < 24; f++) {
        int y0 = 0, y1 = H, low = 0, co = 0;
        if (f) CHECK(yp_anim_apply(t.an, f, t.h, t.sh, &y0, &y1) == HSR_OK);
        CHECK(yp_scan(t.sh, t.h, &o, 0, H, t.fr) == HSR_OK);
        CHECK(yp_lod_fit_anim(lod, t.an, f, t.h, t.sh, &o, t.fr, &low, &co, &y0, &y1) == HSR_OK);
        if (!f) lowered0 = low;
        CHECK(co == 0);                                   /* no tessellation statement */
        CHECK(late_lines(t.fr, o.capacity, iss, late) == 0);
        if (f == 0 || f == 12) CHECK(equals_full(&t, &o));
        mean = 0;
        for (int y = 0; y < H; y++) mean += o.line_lod[y];
        mean /= H;
        if (f == 3) CHECK(mean < YP_LOD_MAX);
        yp_lod_update(lod, iss, late);
    }
    CHECK(over > 0 && lowered0 == over);                  /* exactly the lines over the capacity */
    CHECK(mean == YP_LOD_MAX);                            /* the grid gone: full quality again */
    yp_lod_free(lod);
    ypt_anim_close(&t);
}

/* A dense mesh: a 40 x 30 grid of triangles (2,400 faces) on a wavy sheet in front of a
 * plate.  `tessellation 1 0.25 3` makes two clustered versions: fewer faces each, their
 * vertices within a cell of the sheet; a switch is an incremental move (equal to a full
 * rebuild), the parked version does not show, and the coarse version costs fewer slots. */
static const char *make_sheet(void)
{
    static char obj[1 << 17];
    int k = 0;
    for (int j = 0; j <= 30; j++)
        for (int i = 0; i <= 40; i++) {
            double x = -2 + i * 0.1, y = -1.5 + j * 0.1;
            k += snprintf(obj + k, sizeof obj - (size_t)k, "v %.4f %.4f %.4f\n", x, y, 0.4 + 0.08 * sin(3 * x) * cos(2 * y));
        }
    for (int j = 0; j < 30; j++)
        for (int i = 0; i < 40; i++) {
            int a = j * 41 + i + 1, b = a + 1, c = a + 41, d = c + 1;
            k += snprintf(obj + k, sizeof obj - (size_t)k, "f %d %d %d\nf %d %d %d\n", a, b, d, a, d, c);
        }
    ypt_write_file("build/ts_sheet.obj", obj);
    ypt_write_file("build/ts_plate.obj", "v -2.4 -1.8 0\nv 2.4 -1.8 0\nv 2.4 1.8 0\nv -2.4 1.8 0\nf 1 2 3 4\n");
    ypt_write_file("build/ts.scene", "screen 128 96\ncamera eye 0 0 5 at 0 0 0 up 0 1 0 fov 50\nlight 0.3 0.4 1 0.6\nambient 0.2\n"
          "background 0.1 0.1 0.1\nmaterial plate 0.5 0.5 0.5\nmaterial sheet 0.7 0.4 0.2 specular 0.15 20\n"
          "obj ts_plate.obj material plate\nobj ts_sheet.obj material sheet\n");
    return "build/ts.scene";
}

/* the sheet scene and an animation of it (path, the lines after its scene line), opened at
 * frame 0 (ypt_anim_start) */
static int sheet_start(ypt_anim *t, const char *path, const char *anim)
{
    char text[512];
    make_sheet();
    snprintf(text, sizeof text, "scene ts.scene\n%s", anim);
    ypt_write_file(path, text);
    return ypt_anim_start(t, path, 1);
}

static void test_tessellation_versions_cluster_and_switch_incrementally(void)
{
    ypt_anim t;
    if (!sheet_start(&t, "build/ts.anim", "frames 4\ntessellation 1 0.25 3\nmove 1 0.3 0 0 from 1 to 3\n")) return;
    yp_tess *ts = yp_anim_tess(t.an);
    CHECK(yp_tess_count(ts) == 1 && yp_tess_versions(ts, 0) == 3 && yp_tess_get(ts, 0) == 0);
    CHECK(yp_tess_obj(ts, 0, 0) == 1 && yp_tess_obj(ts, 0, 1) == 2 && yp_tess_obj(ts, 0, 2) == 3);
    int nf[3] = {0, 0, 0};
    for (int fi = 0; fi < t.sc->nf; fi++) if (t.sc->f[fi].obj >= 1) nf[t.sc->f[fi].obj - 1]++;
    CHECK(nf[0] == 2400 && nf[1] > 40 && nf[1] < nf[0] / 4 && nf[2] > 8 && nf[2] < nf[1] / 2);
    /* vertices of version 2 (cells of 0.5): within a cell diagonal of the sheet's x-y box,
     * z between the sheet's extremes (a mean of its vertices); parked versions aside */
    CHECK(yp_tess_set(ts, 0, 2) == HSR_OK);
    CHECK(yp_anim_apply(t.an, 0, NULL, NULL, NULL, NULL) == HSR_OK);
    for (int fi = 0; fi < t.sc->nf; fi++) {
        if (t.sc->f[fi].obj != 3) continue;
        for (int i = 0; i < t.sc->f[fi].count; i++) {
            const double *v = &t.sc->v[3 * t.sc->fv[t.sc->f[fi].first + i]];
            CHECK(v[0] >= -2 && v[0] <= 2 && v[1] >= -1.5 && v[1] <= 1.5 && v[2] >= 0.31 && v[2] <= 0.49);
        }
    }
    CHECK(yp_tess_set(ts, 0, 0) == HSR_OK);
    CHECK(yp_anim_apply(t.an, 0, NULL, NULL, NULL, NULL) == HSR_OK);
    /* frame 0 at version 0, then each frame at another version: incremental == full */
    yp_options o = t.o;
    CHECK(yp_scan(t.sh, t.h, &o, 0, t.H, t.fr) == HSR_OK);
    long slots[3] = {0, 0, 0};
    for (int y = 0; y < t.H; y++) slots[0] += max_slots(t.fr, y);
    for (int f = 1; f < 4; f++) {
        int v = f == 3 ? 0 : f, y0, y1;
        CHECK(yp_tess_set(ts, 0, v) == HSR_OK);
        CHECK(yp_anim_apply(t.an, f, t.h, t.sh, &y0, &y1) == HSR_OK);
        CHECK(y0 < y1);                                   /* the switch damages its lines */
        CHECK(yp_scan(t.sh, t.h, &o, y0, y1, t.fr) == HSR_OK);
        CHECK(equals_full(&t, &o));
        if (f < 3) for (int y = 0; y < t.H; y++) slots[f] += max_slots(t.fr, y);
    }
    CHECK(slots[1] < slots[0] && slots[2] < slots[1]);
    char err[256] = "";
    yp_anim *bad = NULL;
    ypt_write_file("build/ts_bad.anim", "scene ts.scene\ntessellation 7 0.25\n");
    CHECK(yp_anim_load("build/ts_bad.anim", &bad, err, sizeof err) == HSR_EPARSE && strstr(err, "ts_bad.anim:2:"));
    ypt_write_file("build/ts_bad.anim", "scene ts.scene\ntessellation 1 0.25 9\n");
    CHECK(yp_anim_load("build/ts_bad.anim", &bad, err, sizeof err) == HSR_EPARSE && strstr(err, "VERSIONS"));
    ypt_anim_close(&t);
}

/* The sheet with a capacity that its lines do not fit even at level 0, but its clustered
 * version does: the check before emission makes it coarser in frame 0 (no late line);
 * then the sheet slides mostly off the screen (its lines get shorter) and the loop goes
 * back to the finer mesh without a late line; every frame equals its full rebuild. */
static void test_tessellation_loop_coarser_when_overloaded_finer_when_load_falls(void)
{
    ypt_anim t;
    if (!sheet_start(&t, "build/ts_loop.anim", "frames 24\ntessellation 1 0.25 3\nmove 1 3.6 0 0 from 4 to 8\n")) return;
    yp_tess *ts = yp_anim_tess(t.an);
    int H = t.H, iss[128], late[128];
    yp_options o = t.o;
    /* the capacity: between the busiest line at level 0 with the fine and the coarse sheet */
    unsigned char zero[128];
    memset(zero, 0, sizeof zero);
    o.line_lod = zero;
    CHECK(yp_scan(t.sh, t.h, &o, 0, H, t.fr) == HSR_OK);
    int fine0 = 0;
    for (int y = 0; y < H; y++) if (max_slots(t.fr, y) > fine0) fine0 = max_slots(t.fr, y);
    o.capacity = fine0 * 7 / 10;
    o.no_degrade = 1;
    yp_lod *lod = NULL;
    CHECK(yp_lod_new(H, o.capacity, &lod) == HSR_OK);
    o.line_lod = yp_lod_levels(lod);
    int ver[24];
    for (int f = 0; f < 24; f++) {
        int y0 = 0, y1 = H, low = 0, co = 0;
        if (f) {
            yp_tess_refine(ts, t.sc, t.h, o.line_lod, f);
            CHECK(yp_anim_apply(t.an, f, t.h, t.sh, &y0, &y1) == HSR_OK);
        }
        CHECK(yp_scan(t.sh, t.h, &o, 0, H, t.fr) == HSR_OK);
        CHECK(yp_lod_fit_anim(lod, t.an, f, t.h, t.sh, &o, t.fr, &low, &co, &y0, &y1) == HSR_OK);
        CHECK(late_lines(t.fr, o.capacity, iss, late) == 0);
        if (f == 0) CHECK(co > 0);
        if (f == 0 || f == 23) CHECK(equals_full(&t, &o));
        ver[f] = yp_tess_get(ts, 0);
        if (getenv("T_VERBOSE")) fprintf(stderr, "frame %d: version %d, lowered %d, coarsened %d\n", f, ver[f], low, co);
        yp_lod_update(lod, iss, late);
    }
    CHECK(ver[0] > 0 && ver[3] > 0);     /* coarser while the whole sheet is in view */
    CHECK(ver[23] < ver[3]);             /* finer again once its lines are short */
    yp_lod_free(lod);
    ypt_anim_close(&t);
}


/* The monitor's model on a cascade of 81 late lines, against what the Verilated
 * display_controller recorded (blue, frame 3 of lod_comb.anim at 160x120, HTotal 200:
 * capacity 198; `diffengine anim --lod-loop --rtl --htotal 200`, 2026-11-26).  A discard
 * longer than the window also takes the line's cycle outside it: the model without that
 * said 7 words for line 109 (the RTL: 82) and line 110 late (the RTL: on time). */
static void test_lod_monitor_equals_the_rtl_on_a_long_cascade(void)
{
    static const int slots[120] = {3,3,3,3,3,3,3,3,133,101,95,103,103,109,109,109,115,113,105,97,103,103,101,105,101,97,95,99,170,242,244,242,242,242,238,232,238,240,242,252,248,246,178,250,250,258,258,180,178,170,176,176,252,252,176,182,252,246,238,234,238,240,252,250,248,244,248,248,246,242,240,244,250,246,246,240,242,232,230,232,99,226,234,226,226,224,216,216,210,214,194,186,93,93,99,97,103,107,105,97,93,87,91,95,97,95,99,99,99,101,105,113,3,3,3,3,3,3,3,3};
    static const int rtl_issued[120] = {3,3,3,3,3,3,3,3,133,101,95,103,103,109,109,109,115,113,105,97,103,103,101,105,101,97,95,99,170,199,155,109,65,21,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,82,105,113,3,3,3,3,3,3,3,3};
    int is[120], lt[120], nlate = 0;
    yp_lod_monitor(slots, 120, 198, is, lt);
    for (int y = 0; y < 120; y++) {
        CHECK(is[y] == rtl_issued[y]);
        CHECK(lt[y] == (y >= 29 && y <= 109));
        nlate += lt[y];
    }
    CHECK(nlate == 81);
}

void suite_yp_tess(void)
{
    RUN(test_lod_monitor_equals_the_rtl_on_a_long_cascade);
    RUN(test_lod_fit_no_late_line_from_frame_0_and_quality_back);
    RUN(test_tessellation_versions_cluster_and_switch_incrementally);
    RUN(test_tessellation_loop_coarser_when_overloaded_finer_when_load_falls);
}
