/* test_yp_coh.c - temporally coherent fitting (yp_fit_coherent, docs/yproc.md section
 * 11): the previous frame's spline is kept word for word where it still meets the
 * tolerance, only the failing pixels are refitted and the refit rejoins the old spline;
 * every pixel stays within the tolerance; a target that changed everywhere gets the
 * plain fit; and through yproc's scan of a slowly lit pattern, an incremental frame still
 * equals its full re-render from the same previous frame, within the error bound, with
 * fewer changed instructions than without coherence; a line fitted again against its own
 * commands gets them back (a still teapot, degraded lines included). */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_fixture.h"

#define N 480

/* a smooth, diffuse-like target over N pixels, plus an optional bump at x = at */
static void target(double *f, double bump, double at, double scale)
{
    for (int x = 0; x < N; x++)
        f[x] = scale * (1800 + 900 * sin(x / 70.0) + 300 * cos(x / 23.0)) + bump * exp(-pow((x - at) / 12.0, 2));
}

/* worst |array value - target| of a term's commands (one Eval with its Sets, first
 * command at column 0), by the array model: an Eval1 of 1/2 first makes the pixel the
 * rounded value, so the pixel is within tol + 1/2 when the term is within tol */
static double worst(const yp_cmdlist *l, const double *f)
{
    yp_cmdlist m = {0};
    yp_cmd half = {YP_EVAL, 0, 0, N, {(int64_t)(0.5 * YP_ONE), 0, 0}, 0};
    yp_cmdlist_push(&m, half);
    for (int i = 0; i < l->n; i++) yp_cmdlist_push(&m, l->c[i]);
    uint16_t pix[N];
    yp_simulate_line(&m, N, pix);
    double w = 0;
    for (int x = 0; x < N; x++) w = fmax(w, fabs(pix[x] - f[x]));
    yp_cmdlist_free(&m);
    return w;
}

static void test_coherent_fit_refits_only_a_local_change(void)
{
    double f[N], g[N];
    unsigned char use[N];
    memset(use, 1, sizeof use);
    const double tol = 1;
    target(f, 0, 0, 1);
    yp_cmdlist old = {0}, same = {0}, coh = {0}, plain = {0};
    CHECK(yp_fit(f, use, NULL, N, 0, 2, tol, 0, &old) > 5);
    CHECK(worst(&old, f) <= tol + 0.5);
    /* unchanged target: the old commands, all of them */
    int kept = 0;
    CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, 0, &same, NULL, &kept) >= 0);
    CHECK(kept == 1 && yp_cmdlist_equal(&same, &old));
    CHECK(yp_cmdlist_changed_slots(&old, &same) == 0);
    /* a bump of 40 units around x = 240: only its neighbourhood is refitted */
    target(g, 40, 240, 1);
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, 0, &coh, NULL, &kept) >= 0);
    CHECK(yp_fit(g, use, NULL, N, 0, 2, tol, 0, &plain) >= 0);
    CHECK(kept == 1);
    CHECK(worst(&coh, g) <= tol + 0.5);
    int ch_coh = yp_cmdlist_changed_slots(&old, &coh), ch_plain = yp_cmdlist_changed_slots(&old, &plain);
    fprintf(stderr, "  local bump: changed slots %d coherent, %d plain refit (of %d / %d)\n", ch_coh, ch_plain, coh.slots, plain.slots);
    CHECK(ch_coh > 0 && 2 * ch_coh < ch_plain);
    /* the Sets left of x = 180 and right of x = 300 are the old ones, word for word */
    int outside = 0, found = 0;
    for (int i = 0; i < old.n; i++) {
        const yp_cmd *a = &old.c[i];
        if (a->op == YP_EVAL || (a->x > 180 && a->x < 300)) continue;
        outside++;
        for (int j = 0; j < coh.n; j++) {
            yp_cmdlist p1 = {(yp_cmd *)a, 1, 1, 0}, p2 = {&coh.c[j], 1, 1, 0};
            found += yp_cmdlist_equal(&p1, &p2);
        }
    }
    CHECK(outside > 4 && found == outside);
    /* a bump at the end of the span: the refit runs to the end, the Sets before it stay */
    yp_cmdlist end = {0};
    target(g, 40, N - 8, 1);
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, 0, &end, NULL, &kept) >= 0);
    CHECK(kept == 1 && worst(&end, g) <= tol + 0.5);
    CHECK(yp_cmdlist_changed_slots(&old, &end) < 16);
    yp_cmdlist_free(&end);
    /* a target changed everywhere (10 % brighter): the plain fit */
    yp_cmdlist all = {0}, allp = {0};
    target(g, 0, 0, 1.1);
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, 0, &all, NULL, &kept) >= 0);
    CHECK(yp_fit(g, use, NULL, N, 0, 2, tol, 0, &allp) >= 0);
    CHECK(kept == 0 && yp_cmdlist_equal(&all, &allp));
    /* no candidate (another start column) and no previous line: the plain fit too */
    yp_cmdlist nc = {0}, np = {0}, fp = {0};
    CHECK(yp_fit_coherent(f, use, NULL, N - 1, 1, 2, tol, 0, 1, &old, 0, old.n, 0, &nc, NULL, &kept) >= 0 && kept == 0);
    CHECK(yp_fit(f, use, NULL, N - 1, 1, 2, tol, 0, &fp) >= 0 && yp_cmdlist_equal(&nc, &fp));
    CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, 1, NULL, 0, 0, 0, &np, NULL, &kept) >= 0 && kept == 0);
    yp_cmdlist_free(&old); yp_cmdlist_free(&same); yp_cmdlist_free(&coh); yp_cmdlist_free(&plain);
    yp_cmdlist_free(&all); yp_cmdlist_free(&allp); yp_cmdlist_free(&nc); yp_cmdlist_free(&np); yp_cmdlist_free(&fp);
}

/* a drifting target, frame after frame (a slowly moving light): every frame within the
 * tolerance, fewer changed slots than plain refits, and the line does not grow */
static long drift(double hyst, double bright, int *maxslots, int *plainslots);

static void test_coherent_fit_follows_a_slow_drift(void)
{
    int mx1, pl1, mx5, pl5;
    /* a bump moving 2 pixels a frame */
    long b1 = drift(1, 0, &mx1, &pl1), b5 = drift(0.5, 0, &mx5, &pl5);
    fprintf(stderr, "  moving bump: hysteresis 1: %ld changed slots (line at most %d of a plain %d), 0.5: %ld\n", b1, mx1, pl1, b5);
    /* and the whole target brightening by 0.04 % a frame (about 1 unit): hysteresis pays */
    long g1 = drift(1, 4e-4, &mx1, &pl1), g5 = drift(0.5, 4e-4, &mx5, &pl5);
    fprintf(stderr, "  + brightening: hysteresis 1: %ld changed slots, 0.5: %ld (line at most %d of a plain %d)\n", g1, g5, mx5, pl5);
    CHECK(g5 < g1);
}

/* changed slots of the drifting target over 40 frames with coherent fitting at hyst */
static long drift(double hyst, double bright, int *maxslots, int *plainslots)
{
    double f[N];
    unsigned char use[N];
    memset(use, 1, sizeof use);
    const double tol = 4;
    yp_cmdlist cur = {0}, pcur = {0};
    target(f, 200, 100, 1);
    CHECK(yp_fit(f, use, NULL, N, 0, 2, tol * hyst, 0, &cur) >= 0);
    CHECK(yp_fit(f, use, NULL, N, 0, 2, tol * hyst, 0, &pcur) >= 0);
    long ch_coh = 0, ch_plain = 0;
    *maxslots = *plainslots = 0;
    for (int fr = 1; fr <= 40; fr++) {
        target(f, 200, 100 + 2.0 * fr, 1 + bright * fr);     /* the bump moves 2 pixels a frame */
        yp_cmdlist nxt = {0}, pn = {0};
        int kept;
        CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, hyst, &cur, 0, cur.n, 0, &nxt, NULL, &kept) >= 0);
        CHECK(yp_fit(f, use, NULL, N, 0, 2, tol * hyst, 0, &pn) >= 0);   /* refit every frame, as tight */
        CHECK(worst(&nxt, f) <= tol + 0.5);
        ch_coh += yp_cmdlist_changed_slots(&cur, &nxt);
        ch_plain += yp_cmdlist_changed_slots(&pcur, &pn);
        if (nxt.slots > *maxslots) *maxslots = nxt.slots;
        if (pn.slots > *plainslots) *plainslots = pn.slots;
        yp_cmdlist_free(&cur); yp_cmdlist_free(&pcur);
        cur = nxt; pcur = pn;
    }
    CHECK(2 * ch_coh < ch_plain || hyst < 1 || bright > 0);
    CHECK(4 * *maxslots <= 5 * *plainslots + 4 * 8);   /* the quarter (and 8 slots) above a plain fit */
    yp_cmdlist_free(&cur); yp_cmdlist_free(&pcur);
    return ch_coh;
}

/* The Phong teapot of sw/scenes/teapot (two lights) at 160 x 120: many patterns on a
 * line, small ones that share a partly covered pixel (their spans start at the same
 * pixel), two specular terms per pattern, and lines over the default capacity that are
 * degraded.  Light 0 turns a little at frame 1 and then stands still. */
static void make_still_files(void)
{
    ypt_write_file("build/t_still.scene", "screen 160 120\ncamera eye 0.3 3.2 10.5 at 0.25 1.45 0 up 0 1 0 fov 30\n"
                   "light 0.4 0.8 0.6 0.55\nlight -0.6 0.3 0.7 0.2 0.2 0.25\nambient 0.15\nbackground 0.9 0.92 1\n"
                   "grid 32\nmaterial teapot 0.8 0.45 0.3 specular 0.15 30\n"
                   "obj ../../scenes/teapot/teapot.obj material teapot\n");
    ypt_write_file("build/t_still.anim", "scene t_still.scene\nframes 3\nlight 0 0.41 0.8 0.6 from 0 to 1\n");
}

static void copy_frame(yp_cmdlist *dst, const yp_frame *fr)
{
    for (int i = 0; i < 3 * fr->height; i++) {
        yp_cmdlist_free(&dst[i]);
        for (int k = 0; k < fr->line[i].n; k++) CHECK(yp_cmdlist_push(&dst[i], fr->line[i].c[k]) == HSR_OK);
    }
}

/* lines of a equal to b's, word for word */
static int same_lines(const yp_frame *a, const yp_frame *b)
{
    int n = 0;
    for (int i = 0; i < 3 * a->height; i++) n += yp_cmdlist_equal(&a->line[i], &b->line[i]);
    return n;
}

/* The degenerate case of yproc anim --coherent (docs/yproc.md section 11.1): a scene that
 * does not move keeps its lines (the incremental path re-scans none), so a line fitted
 * again against its own previous commands must give them back word for word, degraded
 * lines included.  Twice: frame 0 (fitted without a previous frame) against itself, and
 * after the light turned (a frame fitted against a different one) the next, still frame
 * against it.  Before the fix, a pattern took another pattern's Eval that started at the
 * same pixel, or another light's specular term, as its own (term identity by column), and
 * a degraded line chose its levels on costs of fits made against an older frame. */
static void test_coherent_still_scene_degraded_lines_refit_to_themselves(void)
{
    make_still_files();
    ypt_anim t;
    if (!ypt_anim_start(&t, "build/t_still.anim", 0)) return;
    const int H = t.H, W = t.W;
    t.o.coherent = 1;
    yp_frame *g = NULL;
    yp_cmdlist *prev = calloc(3 * (size_t)H, sizeof(yp_cmdlist));
    CHECK(prev != NULL && yp_frame_new(W, H, &g) == HSR_OK);
    if (!prev || !g) { free(prev); yp_frame_free(g); ypt_anim_close(&t); return; }
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, t.fr) == HSR_OK);
    /* what the fixture must have: degraded lines, and Evals of two patterns of one order
     * starting at one column */
    int deg = 0, shared = 0;
    for (int y = 0; y < H; y++)
        for (int c = 0; c < 3; c++) {
            deg += t.fr->st[y].degraded[c] > 0 && !t.fr->st[y].merged[c];
            const yp_cmdlist *l = &t.fr->line[c * H + y];
            for (int i = 0; i < l->n; i++)
                for (int j = i + 1; j < l->n; j++)
                    shared += l->c[i].op == YP_EVAL && l->c[j].op == YP_EVAL && l->c[i].order == l->c[j].order
                              && l->c[i].x == l->c[j].x && l->c[i].term != l->c[j].term && l->c[i].term && l->c[j].term;
        }
    copy_frame(prev, t.fr);
    t.o.prev = prev;
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, g) == HSR_OK);
    const int still0 = same_lines(g, t.fr);
    /* the light turns (every line re-fitted against frame 0), then stands still */
    int y0, y1, deg1 = 0, moved = 0;
    CHECK(yp_anim_apply(t.an, 1, t.h, t.sh, &y0, &y1) == HSR_OK && y0 == 0 && y1 == H);
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, t.fr) == HSR_OK);
    for (int i = 0; i < 3 * H; i++) moved += !yp_cmdlist_equal(&prev[i], &t.fr->line[i]);
    for (int y = 0; y < H; y++)
        for (int c = 0; c < 3; c++) deg1 += t.fr->st[y].degraded[c] > 0 && !t.fr->st[y].merged[c];
    copy_frame(prev, t.fr);
    CHECK(yp_anim_apply(t.an, 2, t.h, t.sh, &y0, &y1) == HSR_OK && y0 == y1);   /* nothing to re-scan */
    CHECK(yp_scan(t.sh, t.h, &t.o, 0, H, g) == HSR_OK);
    const int still2 = same_lines(g, t.fr);
    fprintf(stderr, "  %dx%d, capacity %d: degraded lines %d / %d, Evals of two terms at one column %d, lines the light changed %d; "
            "re-fitted and equal %d and %d of %d\n", W, H, t.o.capacity, deg, deg1, shared, moved, still0, still2, 3 * H);
    CHECK(deg >= 3 && deg1 >= 3 && shared >= 10 && moved >= H);
    CHECK(still0 == 3 * H);
    CHECK(still2 == 3 * H);
    for (int i = 0; i < 3 * H; i++) yp_cmdlist_free(&prev[i]);
    free(prev);
    yp_frame_free(g);
    ypt_anim_close(&t);
}

void suite_yp_coh(void);
void suite_yp_coh(void)
{
    RUN(test_coherent_fit_refits_only_a_local_change);
    RUN(test_coherent_fit_follows_a_slow_drift);
    RUN(test_coherent_still_scene_degraded_lines_refit_to_themselves);
}
