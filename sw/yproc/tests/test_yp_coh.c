/* test_yp_coh.c - temporally coherent fitting (yp_fit_coherent, docs/yproc.md section
 * 11): the previous frame's spline is kept word for word where it still meets the
 * tolerance, only the failing pixels are refitted and the refit rejoins the old spline;
 * every pixel stays within the tolerance; a target that changed everywhere gets the
 * plain fit; and through yproc's scan of a slowly lit pattern, an incremental frame still
 * equals its full re-render from the same previous frame, within the error bound, with
 * fewer changed instructions than without coherence. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"

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
    yp_cmd half = {YP_EVAL, 0, 0, N, {(int64_t)(0.5 * YP_ONE), 0, 0}};
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
    CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, &same, &kept) >= 0);
    CHECK(kept == 1 && yp_cmdlist_equal(&same, &old));
    CHECK(yp_cmdlist_changed_slots(&old, &same) == 0);
    /* a bump of 40 units around x = 240: only its neighbourhood is refitted */
    target(g, 40, 240, 1);
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, &coh, &kept) >= 0);
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
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, &end, &kept) >= 0);
    CHECK(kept == 1 && worst(&end, g) <= tol + 0.5);
    CHECK(yp_cmdlist_changed_slots(&old, &end) < 16);
    yp_cmdlist_free(&end);
    /* a target changed everywhere (10 % brighter): the plain fit */
    yp_cmdlist all = {0}, allp = {0};
    target(g, 0, 0, 1.1);
    CHECK(yp_fit_coherent(g, use, NULL, N, 0, 2, tol, 0, 1, &old, 0, old.n, &all, &kept) >= 0);
    CHECK(yp_fit(g, use, NULL, N, 0, 2, tol, 0, &allp) >= 0);
    CHECK(kept == 0 && yp_cmdlist_equal(&all, &allp));
    /* no candidate (another start column) and no previous line: the plain fit too */
    yp_cmdlist nc = {0}, np = {0}, fp = {0};
    CHECK(yp_fit_coherent(f, use, NULL, N - 1, 1, 2, tol, 0, 1, &old, 0, old.n, &nc, &kept) >= 0 && kept == 0);
    CHECK(yp_fit(f, use, NULL, N - 1, 1, 2, tol, 0, &fp) >= 0 && yp_cmdlist_equal(&nc, &fp));
    CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, 1, NULL, 0, 0, &np, &kept) >= 0 && kept == 0);
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
        CHECK(yp_fit_coherent(f, use, NULL, N, 0, 2, tol, 0, hyst, &cur, 0, cur.n, &nxt, &kept) >= 0);
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

void suite_yp_coh(void);
void suite_yp_coh(void)
{
    RUN(test_coherent_fit_refits_only_a_local_change);
    RUN(test_coherent_fit_follows_a_slow_drift);
}
