/* yp_fit.c - a colour function along a span as one Eval of order p
 * (Eval1 / Eval2 / Eval3) whose highest difference is replaced at knots by
 * SetI / SetdI / SetddI (docs/yproc.md "Piecewise fit").
 *
 * The array evaluates, from the Eval's first column on, the forward
 * differences of its operands; a Set of the highest difference at column
 * k replaces it from k on while the lower ones continue: a spline of
 * degree p on the integer grid, C^(p-1) at the knots, each knot 2 slots.
 * Greedy, one pass: with the lower differences at a segment start k fixed,
 * the value at k + t is linear in the segment's highest difference c
 * (coefficient binom(t, p)), so each constrained pixel t >= p restricts c
 * to an interval.  The segment ends at the first pixel e where the
 * intersection becomes empty; c is the integer in the middle of the last
 * non-empty intersection (the test is exact 12.24 arithmetic), and the next
 * knot is at e - p, the last column whose outputs c still decides.  So
 * every constrained pixel lies within tol of its target by construction;
 * the result is re-checked by forward differencing before it is used.
 * clamp: Acc_mode is on, a value < 0 contributes 0, so where the target
 * is <= tol any value <= target + tol is good. */
#include <math.h>
#include <stdlib.h>
#include "yp_internal.h"

void yp_eval_values(int order, const int64_t *v0, int n, const int *knot_pos,
                    const int64_t *knot_c, int nk, int64_t *val)
{
    uint64_t v[3] = {(uint64_t)v0[0], (uint64_t)v0[1], (uint64_t)v0[2]};
    int k = 0;
    for (int t = 0; t < n; t++) {
        while (k < nk && knot_pos[k] == t) v[order] = (uint64_t)knot_c[k++];
        val[t] = (int64_t)v[0];
        for (int r = 0; r < order; r++) v[r] += v[r + 1];
    }
}

static int ok_at(double v, double f, double tol, int clamp)
{
    if (clamp && f <= tol && v <= 0) return v >= -2047;
    return fabs(v - f) <= tol;
}

static double binom(int t, int p) { return p == 0 ? 1 : p == 1 ? t : 0.5 * t * (t - 1); }

/* Scan one segment from k with lower differences v: returns the first
 * pixel e where no highest difference fits (n if none), and the feasible
 * interval [lo, hi] of the highest difference for the pixels before e. */
static int segment(const double *f, const unsigned char *use, const double *tolv, int n, int order, double T, double tol,
                   int clamp, int k, const int64_t *v, double *lo_out, double *hi_out)
{
    const double S = YP_ONE;
    double lo = -INFINITY, hi = INFINITY;
    int e = n;
    for (int t = order; k + t < n; t++) {
        int x = k + t;
        if (!use[x]) continue;
        double B = binom(t, order), base = 0;
        for (int r = 0; r < order; r++) base += (double)v[r] * binom(t, r);
        /* with Acc_mode a value below 0 counts as 0, but it must not wrap
         * (the 36-bit A holds -2048 .. 2048 pixel units) */
        double Tx = tolv ? tolv[x] * S * (1 - 1e-9) : T;
        double tgt = f[x] * S, flo = (clamp && f[x] <= tol) ? -2000.0 * S : tgt - Tx, fhi = tgt + Tx;
        double nlo = ceil((flo - base) / B), nhi = floor((fhi - base) / B);
        if (nlo < lo) nlo = lo;
        if (nhi > hi) nhi = hi;
        if (nlo > nhi) { e = x; break; }
        lo = nlo; hi = nhi;
    }
    *lo_out = lo; *hi_out = hi;
    return e;
}

/* The terms of a segment's values at offset t, v[r] * binom(t, r) and
 * binom(t, order), for t < filled: check() is called for every candidate
 * end p and would otherwise recompute them for every pixel before p.
 * The same products in the same order, so the same doubles. */
typedef struct segtab { double *B, *w0, *w1; int filled; } segtab;

static void tab_fill(segtab *tb, int upto, int order, const int64_t *v)
{
    for (int t = tb->filled; t <= upto; t++) {
        tb->B[t] = binom(t, order);
        tb->w0[t] = (double)v[0] * binom(t, 0);
        tb->w1[t] = order > 1 ? (double)v[1] * binom(t, 1) : 0;
    }
    if (upto + 1 > tb->filled) tb->filled = upto + 1;
}

/* 1 if highest difference c from segment start k (lower differences v,
 * terms in tb up to p - k) keeps every constrained pixel k .. p within tol */
static int check(const double *f, const unsigned char *use, const double *tolv, int order, double T, double tol, int clamp,
                 int k, const segtab *tb, double c, int p)
{
    const double S = YP_ONE;
    for (int t = order; k + t <= p; t++) {
        int x = k + t;
        if (!use[x]) continue;
        double val = c * tb->B[t];
        val += tb->w0[t];
        if (order > 1) val += tb->w1[t];
        double tgt = f[x] * S, Tx = tolv ? tolv[x] * S * (1 - 1e-9) : T;
        if (clamp && f[x] <= tol) { if (val > tgt + Tx || val < -2000.0 * S) return 0; }
        else if (fabs(val - tgt) > Tx) return 0;
    }
    return 1;
}

int yp_fit(const double *f, const unsigned char *use, const double *tolv, int n, int x0, int order, double tol,
           int clamp, yp_cmdlist *out)
{
    if (n <= 0 || order < 0 || order > 2) return -1;
    const double S = YP_ONE, T = tol * S * (1 - 1e-9);
    (void)S;
    /* short spans (most: a mesh makes ~10^6 fits of a few pixels) use the
     * stack, not three mallocs */
    enum { NSMALL = 256 };
    int kp_s[NSMALL + 1];
    int64_t kc_s[NSMALL + 1], val_s[NSMALL];
    double tab_s[3 * (NSMALL + 1)];
    int small = n <= NSMALL;
    int *kp = small ? kp_s : malloc(sizeof(int) * (size_t)(n + 1));
    int64_t *kc = small ? kc_s : malloc(sizeof(int64_t) * (size_t)(n + 1));
    int64_t *val = small ? val_s : malloc(sizeof(int64_t) * (size_t)n);
    double *tab = small ? tab_s : malloc(sizeof(double) * 3 * (size_t)(n + 1));
    if (!kp || !kc || !val || !tab) { if (!small) { free(kp); free(kc); free(val); free(tab); } return -1; }
    segtab tb = {tab, tab + n + 1, tab + 2 * (n + 1), 0};
    /* start: exact at the first pixel, slope to the next constrained one */
    int j = 1;
    while (j < n && !use[j]) j++;
    int64_t v0[3] = {llround(f[0] * S), 0, 0};
    if (order == 2 && j < n) v0[1] = llround((f[j] - f[0]) / j * S);
    int64_t v[3] = {v0[0], v0[1], 0};          /* differences at segment start k */
    int nk = 0, k = 0;
    for (;;) {
        double lo, hi, c;
        int e;
        if (order == 0) {
            /* constant pieces: the target at the piece's first pixel if it
             * fits all of them (exact for a constant colour), else the middle */
            e = segment(f, use, tolv, n, order, T, tol, clamp, k, v, &lo, &hi);
            c = isfinite(lo) && isfinite(hi) ? floor(0.5 * (lo + hi)) : isfinite(lo) ? lo : isfinite(hi) ? hi : 0;
            double first = round(f[k] * S);
            if (use[k] && first >= lo && first <= hi) c = first;
        } else {
            /* the segment's highest difference interpolates the target at
             * its last pixel p (so the next segment starts with a small
             * error in value and slope); take the longest segment whose
             * pixels all lie within tol, looking a few pixels past the
             * first failure */
            int bestp = -1, fails = 0;
            double bestc = 0;
            tb.filled = 0;   /* new segment start: new terms */
            for (int p = k + order; p < n && fails < 6; p++) {
                if (!use[p]) continue;
                int t = p - k;
                tab_fill(&tb, t, order, v);
                double base = 0;
                base += tb.w0[t];
                if (order > 1) base += tb.w1[t];
                double tgt = (clamp && f[p] <= tol) ? fmin(f[p] * S, 0) : f[p] * S;
                double cc = round((tgt - base) / tb.B[t]);
                if (check(f, use, tolv, order, T, tol, clamp, k, &tb, cc, p)) { bestp = p; bestc = cc; fails = 0; }
                else fails++;
            }
            if (bestp < 0) {     /* cannot happen: p = k + order is exact up to rounding */
                e = segment(f, use, tolv, n, order, T, tol, clamp, k, v, &lo, &hi);
                c = isfinite(lo) && isfinite(hi) ? floor(0.5 * (lo + hi)) : isfinite(lo) ? lo : isfinite(hi) ? hi : 0;
            } else {
                c = bestc;
                /* the last constrained pixel decided by c: end of span or
                 * bestp; beyond it the next knot */
                int last = n - 1;
                while (last > bestp && !use[last]) last--;
                e = last == bestp ? n : bestp + 1;
            }
        }
        if (nk == 0) v0[order] = (int64_t)c; else kc[nk - 1] = (int64_t)c;
        v[order] = (int64_t)c;
        if (e >= n) break;
        int knot = e - order;
        if (knot <= k) knot = k + 1;    /* cannot happen for tol >= 2^-24; the check below would fail */
        for (int x = k; x < knot; x++)
            for (int r = 0; r < order; r++) v[r] = (int64_t)((uint64_t)v[r] + (uint64_t)v[r + 1]);
        kp[nk++] = knot;
        k = knot;
    }
    yp_eval_values(order, v0, n, kp, kc, nk, val);
    int bad = 0;
    for (int x = 0; x < n && !bad; x++)
        if (use[x] && !ok_at((double)val[x] / S, f[x], tolv ? tolv[x] : tol, clamp)) bad = 1;
    hsr_status st = HSR_OK;
    for (int i = 0; i < nk && st == HSR_OK; i++) {
        yp_cmd s = {(uint8_t)(YP_SETI + order), 0, (uint16_t)(x0 + kp[i]), 1, {kc[i], 0, 0}};
        st = yp_cmdlist_push(out, s);
    }
    yp_cmd ev = {YP_EVAL, (uint8_t)order, (uint16_t)x0, (uint16_t)n, {v0[0], v0[1], v0[2]}};
    if (st == HSR_OK) st = yp_cmdlist_push(out, ev);
    if (!small) { free(kp); free(kc); free(val); free(tab); }
    return bad || st != HSR_OK ? -1 : nk;
}
