/* test_yp_tex_lod.c - the textured pattern lit by a wandering point light (Fig. 7.27,
 * yp_tex.c) and the Load Monitor loop (yp_lod.c): the texture is a C1 piecewise
 * quadratic, a point light is brightest under it, the light wanders continuously inside
 * its box, only the light's terms change between frames (incremental == full
 * rebuild), the changed-instruction count is an LCS, and the loop removes overflowing
 * lines within a few frames and restores quality when the load falls. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"
#include "yp_fixture.h"

/* a 48x36 textured quad seen square-on, one point light */
#define PATTERN_SCENE "screen 48 36\ncamera eye 0 0 5 at 0 0 0 up 0 1 0 fov 40\nlight 0 0 1 0.5\nambient 0.1\n" \
    "background 0.05 0.05 0.08\nmaterial pattern 0.55 0.5 0.45 specular 0.2 25\nobj t_quad.obj material pattern\n"
#define PATTERN_ANIM "scene t_tex.scene\nframes 8\ntexture pattern 0.3 0.4 1 0.8 0.55 7 8\n" \
    "pointlight 0 0.4 0.3 0.9 falloff 2.5\nwander 0 2718 3 -1.8 -1.3 0.5 1.8 1.3 1.2 from 0 to 7\n"

static void make_pattern_files(void)
{
    ypt_write_file("build/t_quad.obj", "v -2.1 -1.55 0\nv 2.1 -1.55 0\nv 2.1 1.55 0\nv -2.1 1.55 0\nf 1 2 3 4\n");
    ypt_write_file("build/t_tex.scene", PATTERN_SCENE);
    ypt_write_file("build/t_tex.anim", PATTERN_ANIM);
}

static void test_texture_is_c1_piecewise_quadratic_along_u(void)
{
    make_pattern_files();
    ypt_anim ta;
    if (!ypt_anim_start(&ta, "build/t_tex.anim", 1)) return;
    yp_shader *sh = ta.sh;
    char err[256] = "";
    CHECK(yp_texture_at(sh, 0, (double[3]){0, 0, 0}) >= 0);
    /* along u at fixed v: second differences constant inside a knot interval (0.3 world
     * units), value and slope continuous across a knot, values in [0, 1] */
    const double s = 0.3, h = s / 64, v = 0.137;
    double lo = 1, hi = 0;
    int pieces = 0;
    for (int k = -5; k < 5; k++) {
        double d2[60];
        for (int i = 0; i < 60; i++) {
            double u = k * s + 2 * h + i * h;
            double a = yp_texture_at(sh, 0, (double[3]){u - h, v, 0}), b = yp_texture_at(sh, 0, (double[3]){u, v, 0});
            double c = yp_texture_at(sh, 0, (double[3]){u + h, v, 0});
            d2[i] = a - 2 * b + c;
            lo = fmin(lo, b); hi = fmax(hi, b);
        }
        for (int i = 1; i < 60; i++) CHECK(fabs(d2[i] - d2[0]) < 1e-9);
        /* continuity of value and slope at the knot k * s */
        double e = 1e-7, K = k * s;
        double l0 = yp_texture_at(sh, 0, (double[3]){K - e, v, 0}), r0 = yp_texture_at(sh, 0, (double[3]){K + e, v, 0});
        double l1 = yp_texture_at(sh, 0, (double[3]){K - 2 * e, v, 0}), r1 = yp_texture_at(sh, 0, (double[3]){K + 2 * e, v, 0});
        CHECK(fabs(l0 - r0) < 1e-5);
        CHECK(fabs((l0 - l1) - (r1 - r0)) < 1e-9);
        pieces++;
    }
    CHECK(pieces == 10);
    CHECK(lo >= 0 && hi <= 1 && hi - lo > 0.2);   /* a visible pattern */
    /* a texture that can exceed intensity 1 is refused */
    yp_texture big = {0.3, 0.9, {1, 1, 1}, 1, 8};
    CHECK(yp_shader_set_texture(sh, 1, &big, err, sizeof err) == HSR_EPARSE);
    CHECK(strstr(err, "exceed intensity 1") != NULL);
    ypt_anim_close(&ta);
}

static void test_point_light_brightest_under_it_and_follows_it(void)
{
    make_pattern_files();
    char err[256] = "";
    hsr_scene *sc = NULL;
    CHECK(hsr_scene_load("build/t_tex.scene", &sc, err, sizeof err) == HSR_OK);
    if (!sc) return;
    yp_shader *sh = NULL;
    CHECK(yp_shader_new(sc, YP_PHONG, &sh, err, sizeof err) == HSR_OK);
    /* directional (0 0 1): the same diffuse everywhere on the plane */
    double b0[3], b1[3], sp[3];
    yp_shade_face(sh, 0, 5.5, 18.5, b0, sp);
    yp_shade_face(sh, 0, 40.5, 18.5, b1, sp);
    CHECK(fabs(b0[0] - b1[0]) < 1e-6);
    /* a point light near the plane in front of the left part, then the right part */
    int best[2];
    for (int side = 0; side < 2; side++) {
        double pos[3] = {side ? 1.2 : -1.2, 0, 0.4};
        CHECK(yp_shader_set_point_light(sh, 0, pos, 2.5) == HSR_OK);
        double mx = -1;
        for (int x = 0; x < 48; x++) {
            double b[3];
            yp_shade_face(sh, 0, x + 0.5, 18.5, b, sp);
            if (b[0] + sp[0] > mx) { mx = b[0] + sp[0]; best[side] = x; }
        }
    }
    CHECK(best[0] < 18 && best[1] > 30);
    CHECK(yp_shader_set_point_light(sh, 5, (double[3]){0, 0, 1}, 0) == HSR_EINVAL);
    yp_shader_free(sh);
    hsr_scene_free(sc);
}

static void test_wander_moves_continuously_towards_random_points_in_its_box(void)
{
    make_pattern_files();
    ypt_write_file("build/t_w.anim", "scene t_tex.scene\nframes 40\npointlight 0 0.4 0.3 0.9\n"
               "wander 0 99 5 -1.8 -1.3 0.5 1.8 1.3 1.2 from 0 to 39\n");
    ypt_anim ta;
    if (!ypt_anim_start(&ta, "build/t_w.anim", 1)) return;
    yp_anim *an = ta.an;
    yp_shader *sh = ta.sh;
    char err[256] = "";
    double p[40][3];
    for (int f = 0; f < 40; f++) {
        CHECK(yp_anim_apply(an, f, NULL, sh, NULL, NULL) == HSR_OK);
        memcpy(p[f], sh->Lpos[0], sizeof p[f]);
        CHECK(sh->Lpt[0] == 1);
    }
    CHECK(p[0][0] == 0.4 && p[0][1] == 0.3 && p[0][2] == 0.9);
    int turns = 0;
    for (int f = 1; f < 40; f++) {
        double d = 0;
        for (int k = 0; k < 3; k++) d += (p[f][k] - p[f - 1][k]) * (p[f][k] - p[f - 1][k]);
        CHECK(sqrt(d) < 1.0);                 /* a leg of at most the box diagonal (4.5) in 5 frames */
        CHECK(sqrt(d) > 1e-6);                /* it never stops */
        CHECK(p[f][0] >= -1.8 - 1e-9 && p[f][0] <= 1.8 + 1e-9 && p[f][2] >= 0.5 - 1e-9 && p[f][2] <= 1.2 + 1e-9);
        if (f >= 2 && f % 5 == 1) {           /* a waypoint was reached at f - 1: the direction changes */
            double a[3], b[3], dot = 0, na = 0, nb = 0;
            for (int k = 0; k < 3; k++) { a[k] = p[f - 1][k] - p[f - 2][k]; b[k] = p[f][k] - p[f - 1][k]; }
            for (int k = 0; k < 3; k++) { dot += a[k] * b[k]; na += a[k] * a[k]; nb += b[k] * b[k]; }
            turns += dot / sqrt(na * nb) < 0.999;
        }
    }
    CHECK(turns >= 5);
    /* the same frame again: the same place (frames can be applied in any order) */
    CHECK(yp_anim_apply(an, 17, NULL, sh, NULL, NULL) == HSR_OK);
    CHECK(!memcmp(sh->Lpos[0], p[17], sizeof p[17]));
    ypt_anim_close(&ta);
    an = NULL;
    /* errors name the file and line */
    ypt_write_file("build/t_w2.anim", "scene t_tex.scene\nframes 4\nwander 0 1 2 0 0 0 1 1 1 from 0 to 3\n");
    CHECK(yp_anim_load("build/t_w2.anim", &an, err, sizeof err) == HSR_EPARSE);
    CHECK(strstr(err, "t_w2.anim:3:") && strstr(err, "not a point light"));
    ypt_write_file("build/t_w3.anim", "scene t_tex.scene\n\ntexture nosuch 0.3 0.4 1 1 1 7\n");
    CHECK(yp_anim_load("build/t_w3.anim", &an, err, sizeof err) == HSR_EPARSE);
    CHECK(strstr(err, "t_w3.anim:3:") && strstr(err, "unknown material"));
}

static void test_changed_slots_is_the_lcs_of_the_commands(void)
{
    yp_cmdlist a = {0}, b = {0};
    yp_cmd e3 = {YP_EVAL, 2, 0, 40, {1, 2, 3}, 0}, s1 = {YP_SETDDI, 0, 5, 0, {7, 0, 0}, 0}, s2 = {YP_SETDDI, 0, 9, 0, {8, 0, 0}, 0};
    yp_cmd bg = {YP_EVAL, 0, 0, 48, {100, 0, 0}, 0}, e3b = e3;
    e3b.v[0] = 99;
    /* a: bg s1 e3 s2 e3 ; b: bg s1 e3b s2 e3 -> one Eval3 (5 slots) changed */
    yp_cmd la[] = {bg, s1, e3, s2, e3}, lb[] = {bg, s1, e3b, s2, e3};
    for (int i = 0; i < 5; i++) { yp_cmdlist_push(&a, la[i]); yp_cmdlist_push(&b, lb[i]); }
    CHECK(yp_cmdlist_changed_slots(&a, &a) == 0);
    CHECK(yp_cmdlist_changed_slots(&a, &b) == 5);
    /* an inserted knot: 2 slots; a removed one: 0 new slots */
    yp_cmdlist c = {0};
    yp_cmd lc[] = {bg, s1, s2, e3b, s2, e3};
    for (int i = 0; i < 6; i++) yp_cmdlist_push(&c, lc[i]);
    CHECK(yp_cmdlist_changed_slots(&b, &c) == 2);
    CHECK(yp_cmdlist_changed_slots(&c, &b) == 0);
    /* from an empty line: every slot */
    yp_cmdlist z = {0};
    CHECK(yp_cmdlist_changed_slots(&z, &c) == c.slots);
    yp_cmdlist_free(&a); yp_cmdlist_free(&b); yp_cmdlist_free(&c);
}

/* The Fig. 7.27 animation in small: every frame equals its full re-render, the texture
 * term is there (more instructions than without it) and only a part of each line
 * changes from frame to frame (the light's terms, not the texture's). */
/* worst |array pixel - exact shading| of a frame (yp_simulate_line against fr->ideal) */
static double frame_worst(const yp_frame *fr)
{
    uint16_t pix[64];
    double worst = 0;
    for (int c = 0; c < 3; c++)
        for (int y = 0; y < fr->height; y++) {
            yp_simulate_line(&fr->line[c * fr->height + y], fr->width, pix);
            for (int x = 0; x < fr->width; x++) worst = fmax(worst, fabs(pix[x] - fr->ideal[((size_t)c * fr->height + y) * fr->width + x]));
        }
    return worst;
}

/* The animation frame by frame at tolerance tol (coherent: yp_options.coherent and the
 * previous frame's lines as .prev): every incremental frame equals the full rebuild
 * (HSR rebuilt, every line) from the same previous frame; returns the changed slots
 * (LCS), the slots of all frames and the worst pixel against the exact shading. */
static void textured_run(const char *path, double tol, int coherent, long *changed, long *total, double *worst)
{
    ypt_anim t;
    *changed = *total = 0; *worst = 0;
    if (!ypt_anim_start(&t, path, 1)) return;
    int H = t.H, W = t.W;
    double *shade;
    t.o.tol = tol; t.o.coherent = coherent;
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, t.fr) == HSR_OK);
    *worst = frame_worst(t.fr);
    yp_cmdlist *prev = calloc(3 * (size_t)H, sizeof(yp_cmdlist));
    for (int f = 1; prev && f < yp_anim_frames(t.an); f++) {
        for (int i = 0; i < 3 * H; i++) {
            yp_cmdlist_free(&prev[i]);
            for (int k = 0; k < t.fr->line[i].n; k++) yp_cmdlist_push(&prev[i], t.fr->line[i].c[k]);
        }
        if (coherent) t.o.prev = prev;
        int y0, y1;
        CHECK(yp_anim_apply(t.an, f, t.h, t.sh, &y0, &y1) == HSR_OK);
        CHECK(y0 == 0 && y1 == H);                 /* a light moved: every line */
        CHECK(yp_scan(t.sh, t.h, &t.o, y0, y1, t.fr) == HSR_OK);
        hsr_ctx *hf = NULL;
        yp_frame *ff = NULL;
        CHECK(hsr_scene_build(t.sc, &hf, &shade) == HSR_OK);
        free(shade);
        CHECK(yp_frame_new(W, H, &ff) == HSR_OK);
        CHECK(yp_scan(t.sh, hf, &t.o, 0, H, ff) == HSR_OK);
        for (int i = 0; i < 3 * H; i++) {
            CHECK(yp_cmdlist_equal(&ff->line[i], &t.fr->line[i]));
            *changed += yp_cmdlist_changed_slots(&prev[i], &t.fr->line[i]);
            *total += t.fr->line[i].slots;
        }
        *worst = fmax(*worst, frame_worst(t.fr));
        yp_frame_free(ff); hsr_destroy(hf);
    }
    for (int i = 0; prev && i < 3 * H; i++) yp_cmdlist_free(&prev[i]);
    free(prev);
    ypt_anim_close(&t);
}

static void test_textured_anim_changes_only_the_light_terms(void)
{
    make_pattern_files();
    ypt_anim t;
    if (!ypt_anim_start(&t, "build/t_tex.anim", 0)) return;
    yp_frame *fr = t.fr, *plain = NULL;
    int H = t.H, W = t.W;
    CHECK(yp_frame_new(W, H, &plain) == HSR_OK);
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, plain) == HSR_OK);          /* no texture yet */
    CHECK(yp_anim_apply(t.an, 0, NULL, t.sh, NULL, NULL) == HSR_OK);
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, fr) == HSR_OK);
    long sl_plain = 0, sl_tex = 0, changed = 0, total = 0;
    for (int i = 0; i < 3 * H; i++) { sl_plain += plain->line[i].slots; sl_tex += fr->line[i].slots; }
    CHECK(sl_tex > sl_plain + 3 * H);
    /* the frame is within the fit's bound of the exact target (texture included) */
    CHECK(frame_worst(fr) <= 0.5 + 4 * t.o.tol + 0.05);
    yp_frame_free(plain);
    ypt_anim_close(&t);
    double worst;
    textured_run("build/t_tex.anim", 1, 0, &changed, &total, &worst);
    CHECK(changed > 0);
    CHECK(changed < total / 2);          /* the texture term (most of a line) never changes */
}

/* Coherent fitting through yp_scan (docs/yproc.md section 11.1): a slow light (legs of
 * 400 frames) at tol 4; every frame equals its full rebuild from the same previous frame
 * and is within 1/2 + 3 tol of the exact shading; fewer slots change than when every
 * frame is refitted. */
static void test_coherent_scan_keeps_what_still_fits(void)
{
    make_pattern_files();
    ypt_write_file("build/t_slow.anim", "scene t_tex.scene\nframes 10\ntexture pattern 0.3 0.4 1 0.8 0.55 7 8\n"
               "pointlight 0 0.4 0.3 0.9 falloff 2.5\nwander 0 2718 400 -1.8 -1.3 0.5 1.8 1.3 1.2 from 0 to 9\n");
    long ch_coh, tot_coh, ch_plain, tot_plain;
    double w_coh, w_plain;
    textured_run("build/t_slow.anim", 4, 1, &ch_coh, &tot_coh, &w_coh);
    textured_run("build/t_slow.anim", 4, 0, &ch_plain, &tot_plain, &w_plain);
    fprintf(stderr, "  48x36, 9 frames: changed slots %ld coherent (of %ld), %ld plain (of %ld); worst pixel %.2f / %.2f\n",
            ch_coh, tot_coh, ch_plain, tot_plain, w_coh, w_plain);
    CHECK(w_coh <= 0.5 + 3 * 4 + 0.05 && w_plain <= 0.5 + 3 * 4 + 0.05);
    CHECK(ch_coh > 0 && 4 * ch_coh < 3 * ch_plain);
}

static void test_lod_update_lowers_late_lines_and_raises_when_load_falls(void)
{
    yp_lod *l = NULL;
    CHECK(yp_lod_new(4, 100, &l) == HSR_OK);
    if (!l) return;
    const unsigned char *lv = yp_lod_levels(l);
    CHECK(lv[0] == YP_LOD_MAX && lv[3] == YP_LOD_MAX);
    int iss[4] = {101, 95, 40, 10}, late[4] = {1, 0, 0, 0};
    yp_lod_update(l, iss, late);
    CHECK(lv[0] == YP_LOD_MAX - 2);      /* late: two levels */
    CHECK(lv[1] == YP_LOD_MAX - 1);      /* above the high-water mark: one */
    CHECK(lv[2] == YP_LOD_MAX && lv[3] == YP_LOD_MAX);
    /* line 0 now fits at 60: not raised back into the level that was late at once (the
     * neighbour's 95 also counts), and not while its load has not fallen */
    int iss2[4] = {60, 70, 40, 10}, late2[4] = {0};
    yp_lod_update(l, iss2, late2);
    CHECK(lv[0] == YP_LOD_MAX - 2);
    /* the load falls: the line climbs back one level per frame to the top */
    int iss3[4] = {20, 20, 20, 10};
    for (int k = 0; k < 8; k++) yp_lod_update(l, iss3, late2);
    CHECK(lv[0] == YP_LOD_MAX && lv[1] == YP_LOD_MAX);
    /* the monitor model: a late line fills its window (capacity + 1 slots) and its tail
     * is discarded in the next window, which can make that line late too */
    int sl[5] = {120, 90, 40, 100, 3}, is[5], lt[5];
    yp_lod_monitor(sl, 5, 100, is, lt);
    /* 120 + marker: 101 issued, 20 left; 90 + 1 > 101 - 20: late, 81 issued, 10 left;
     * 40 fits in 91; 100 fits exactly; 3 */
    CHECK(is[0] == 101 && lt[0] == 1 && is[1] == 81 && lt[1] == 1);
    CHECK(is[2] == 40 && lt[2] == 0 && is[3] == 100 && lt[3] == 0 && is[4] == 3 && lt[4] == 0);
    yp_lod_monitor(sl, 5, 100, sl, lt);  /* in place, as yproc anim calls it */
    CHECK(!memcmp(sl, is, sizeof is));
    int sl2[3] = {350, 10, 10};         /* a tail longer than a window */
    yp_lod_monitor(sl2, 3, 100, is, lt);
    CHECK(is[0] == 101 && is[1] == 0 && lt[1] == 1 && is[2] == 0 && lt[2] == 1);
    yp_lod_free(l);
    /* the level's options: the top is the base, lower levels cheaper */
    yp_options o;
    yp_options_default(&o);
    int ml, aa, tx;
    double tol;
    yp_lod_line_options(&o, YP_LOD_MAX, &ml, &aa, &tol, &tx);
    CHECK(ml == 3 && aa == 1 && tol == o.tol && tx == 1);
    yp_lod_line_options(&o, 0, &ml, &aa, &tol, &tx);
    CHECK(ml == 2 && aa == 0 && tol == 64 * o.tol && tx == 0);
}

/* The loop on a scene that overloads: a dense grid of small Phong quads (many patterns
 * per line) in front of a plate, with a capacity the full quality does not fit; the
 * grid then moves off the screen.  Without look-ahead degradation (no_degrade), frame 0
 * overflows; the Load Monitor loop removes every overflow within 3 frames, and after the
 * grid has left, the levels climb back to full quality. */
static void test_lod_loop_removes_overflow_and_restores_quality(void)
{
    ypt_grid_anim("t", 14);
    ypt_anim t;
    if (!ypt_anim_start(&t, "build/t_grid.anim", 1)) return;
    yp_shader *sh = t.sh;
    hsr_ctx *h = t.h;
    yp_frame *fr = t.fr;
    yp_options o = t.o;
    int H = t.H;
    /* the capacity: 60 % of the busiest line at full quality */
    CHECK(yp_scan(sh, h, &o, 0, H, fr) == HSR_OK);
    int busiest = 0;
    for (int y = 0; y < H; y++) for (int c = 0; c < 3; c++) if (fr->st[y].slots[c] > busiest) busiest = fr->st[y].slots[c];
    o.capacity = busiest * 6 / 10;
    o.no_degrade = 1;
    yp_lod *lod = NULL;
    CHECK(yp_lod_new(H, o.capacity, &lod) == HSR_OK);
    o.line_lod = yp_lod_levels(lod);
    int ovl[14], iss[64], late[64];
    double mean[14];
    for (int f = 0; f < 14; f++) {
        int y0 = 0, y1 = H;
        if (f) CHECK(yp_anim_apply(t.an, f, h, sh, &y0, &y1) == HSR_OK);
        CHECK(yp_scan(sh, h, &o, 0, H, fr) == HSR_OK);   /* every line: the levels may change anywhere */
        ovl[f] = 0; mean[f] = 0;
        for (int y = 0; y < H; y++) iss[y] = late[y] = 0;
        for (int c = 0; c < 3; c++) {
            int sl[64], ic[64], lc[64];
            for (int y = 0; y < H; y++) sl[y] = fr->st[y].slots[c];
            yp_lod_monitor(sl, H, o.capacity, ic, lc);
            for (int y = 0; y < H; y++) {
                if (ic[y] > iss[y]) iss[y] = ic[y];
                late[y] |= lc[y];
                CHECK(!fr->st[y].overflow[c] || lc[y]);   /* a line over the capacity is late */
            }
        }
        for (int y = 0; y < H; y++) { ovl[f] += late[y]; mean[f] += o.line_lod[y]; }
        mean[f] /= H;
        if (getenv("T_VERBOSE")) {
            fprintf(stderr, "frame %d: overflow %d, mean level %.2f, capacity %d:", f, ovl[f], mean[f], o.capacity);
            for (int y = 0; y < H; y++) fprintf(stderr, " %d/%d", o.line_lod[y], iss[y]);
            fprintf(stderr, "\n");
        }
        yp_lod_update(lod, iss, late);
    }
    CHECK(ovl[0] > 0);
    for (int f = 3; f < 14; f++) CHECK(ovl[f] == 0);
    CHECK(mean[5] < YP_LOD_MAX);          /* the grid still there: quality lowered */
    CHECK(mean[13] == YP_LOD_MAX);        /* the grid gone: full quality everywhere again */
    yp_lod_free(lod);
    ypt_anim_close(&t);
}

void suite_yp_tex_lod(void)
{
    RUN(test_texture_is_c1_piecewise_quadratic_along_u);
    RUN(test_point_light_brightest_under_it_and_follows_it);
    RUN(test_wander_moves_continuously_towards_random_points_in_its_box);
    RUN(test_changed_slots_is_the_lcs_of_the_commands);
    RUN(test_textured_anim_changes_only_the_light_terms);
    RUN(test_coherent_scan_keeps_what_still_fits);
    RUN(test_lod_update_lowers_late_lines_and_raises_when_load_falls);
    RUN(test_lod_loop_removes_overflow_and_restores_quality);
}
