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

/* One segment of order >= 1 from column k (lower differences v): its highest
 * difference interpolates the target at its last pixel p (so the next segment starts
 * with a small error in value and slope); the longest segment whose pixels k..p all
 * lie within tol, looking a few pixels past the first failure.  stop(ud, p), if
 * given, is asked at every p that fits, in order, and ends the segment there when it
 * says 1.  Returns p (-1: none) and its highest difference in *c. */
static int greedy(const double *f, const unsigned char *use, const double *tolv, int n, int order, double T,
                  double tol, int clamp, int k, const int64_t *v, segtab *tb, int (*stop)(void *, int), void *ud,
                  double *c)
{
    const double S = YP_ONE;
    int bestp = -1, fails = 0;
    tb->filled = 0;   /* new segment start: new terms */
    for (int p = k + order; p < n && fails < 6; p++) {
        if (!use[p]) continue;
        int t = p - k;
        tab_fill(tb, t, order, v);
        double base = 0;
        base += tb->w0[t];
        if (order > 1) base += tb->w1[t];
        double tgt = (clamp && f[p] <= tol) ? fmin(f[p] * S, 0) : f[p] * S;
        double cc = round((tgt - base) / tb->B[t]);
        if (check(f, use, tolv, order, T, tol, clamp, k, tb, cc, p)) {
            bestp = p; *c = cc; fails = 0;
            if (stop && stop(ud, p)) break;
        } else fails++;
    }
    return bestp;
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
            double bestc = 0;
            int bestp = greedy(f, use, tolv, n, order, T, tol, clamp, k, v, &tb, NULL, NULL, &bestc);
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
        yp_cmd s = {(uint8_t)(YP_SETI + order), 0, (uint16_t)(x0 + kp[i]), 1, {kc[i], 0, 0}, 0};
        st = yp_cmdlist_push(out, s);
    }
    yp_cmd ev = {YP_EVAL, (uint8_t)order, (uint16_t)x0, (uint16_t)n, {v0[0], v0[1], v0[2]}, 0};
    if (st == HSR_OK) st = yp_cmdlist_push(out, ev);
    if (!small) { free(kp); free(kc); free(val); free(tab); }
    return bad || st != HSR_OK ? -1 : nk;
}

/* ---- temporally coherent fitting (docs/yproc.md section 11) ----------------------
 * The previous frame's spline of the same term (an Eval of the same order starting at
 * the same column, and the Sets before it) is kept wherever it still meets the
 * tolerance against the new target; only the pixels where it fails are refitted.  A
 * refit starts at the last of the old knots before the first failing pixel and, as
 * soon as the old spline holds again for a while after a pixel the refit has reached,
 * sets the array's registers back onto the old spline there (SetI, SetdI and the top
 * difference: a "resync"), so that the old Sets after it stay valid word for word. */
typedef struct fset { int pos, reg; int64_t v; } fset;   /* a Set: column (relative to x0), register */

static int fset_cmp(const void *pa, const void *pb)
{
    const fset *a = pa, *b = pb;
    return a->pos != b->pos ? (a->pos < b->pos ? -1 : 1) : (a->reg > b->reg) - (a->reg < b->reg);
}

/* values (and, if state != NULL, the registers of every column after its Sets: 3 a
 * column) of an order-p Eval with v0 and the Sets s (sorted by column) over n columns */
static void eval_sets(int order, const int64_t *v0, int n, const fset *s, int ns, int64_t *val, int64_t *state)
{
    uint64_t v[3] = {(uint64_t)v0[0], (uint64_t)v0[1], (uint64_t)v0[2]};
    int k = 0;
    while (k < ns && s[k].pos < 0) k++;
    for (int t = 0; t < n; t++) {
        for (; k < ns && s[k].pos == t; k++) v[s[k].reg] = (uint64_t)s[k].v;
        if (state) for (int r = 0; r < 3; r++) state[3 * t + r] = (int64_t)v[r];
        val[t] = (int64_t)v[0];
        for (int r = 0; r < order; r++) v[r] += v[r + 1];
    }
}

/* the Sets of prev's Eval at index i that act on it: the run of Sets of its registers
 * on its columns (and of its term) right before it (yp_fit and yp_fit_coherent put them
 * there) */
static int gather_sets(const yp_cmdlist *prev, int i0, int i, int n, fset *s)
{
    const yp_cmd *e = &prev->c[i];
    int ns = 0;
    for (int j = i - 1; j >= i0; j--) {
        const yp_cmd *q = &prev->c[j];
        if (q->op < YP_SETI || q->op > YP_SETI + e->order || q->dx != 1 || q->x < e->x || q->x >= e->x + e->dx
            || q->term != e->term) break;
        if (q->x - e->x < n) s[ns++] = (fset){q->x - e->x, q->op - YP_SETI, q->v[0]};
    }
    qsort(s, (size_t)ns, sizeof *s, fset_cmp);
    return ns;
}

typedef struct cohstop { const int *nextfail; int n, from, lmin; } cohstop;

/* end a refit segment at p (resync at p + 1) if it has reached the failing pixel and
 * the old spline holds from p + 1 to the end or for lmin pixels */
static int coh_stop(void *ud, int p)
{
    const cohstop *c = ud;
    int r = p + 1;
    if (p < c->from || r >= c->n) return 0;
    return c->nextfail[r] >= c->n || c->nextfail[r] - r >= c->lmin;
}

static hsr_status push_fset(fset **s, int *ns, int *cap, fset v)
{
    if (*ns == *cap) {
        int nc = *cap ? 2 * *cap : 32;
        fset *p = realloc(*s, sizeof(fset) * (size_t)nc);
        if (!p) return HSR_ENOMEM;
        *s = p; *cap = nc;
    }
    (*s)[(*ns)++] = v;
    return HSR_OK;
}

#define YP_COH_LMIN 24    /* pixels the old spline must hold after a resync [choice] */

/* src's commands from index from on, after dst's (plain: the fit without prev) */
static hsr_status push_from(yp_cmdlist *dst, const yp_cmdlist *src, int from)
{
    hsr_status st = HSR_OK;
    for (int i = from; dst && i < src->n && st == HSR_OK; i++) st = yp_cmdlist_push(dst, src->c[i]);
    return st;
}

int yp_fit_coherent(const double *f, const unsigned char *use, const double *tolv, int n, int x0, int order,
                    double tol, int clamp, double hyst, const yp_cmdlist *prev, int i0, int i1, unsigned term,
                    yp_cmdlist *out, yp_cmdlist *plain_out, int *kept)
{
    if (kept) *kept = 0;
    if (n <= 0) return -1;
    const int out0 = out->n;
    /* what is (re)fitted is fitted at hyst * tol; an old spline is kept while within tol */
    double *th = malloc(sizeof(double) * (size_t)n);
    if (!th) {
        int r = yp_fit(f, use, tolv, n, x0, order, tol, clamp, out);
        return push_from(plain_out, out, out0) == HSR_OK ? r : -1;
    }
    for (int x = 0; x < n; x++) th[x] = (tolv ? tolv[x] : tol) * hyst;
    const double tf = tol * hyst;
    if (!prev || order < 1 || order > 2 || i0 < 0 || i1 > prev->n) {
        int r = yp_fit(f, use, th, n, x0, order, tf, clamp, out);
        free(th);
        return push_from(plain_out, out, out0) == HSR_OK ? r : -1;
    }
    const double S = YP_ONE, T = tf * S * (1 - 1e-9);
    int oldcap = 0;
    for (int i = i0; i < i1; i++) oldcap += prev->c[i].op >= YP_SETI && prev->c[i].op <= YP_SETDDI;
    fset *os = malloc(sizeof(fset) * (size_t)(oldcap + 1)), *ns_ = NULL;
    int64_t *val = malloc(sizeof(int64_t) * (size_t)n), *ost = malloc(sizeof(int64_t) * 3 * (size_t)n);
    int *nextfail = malloc(sizeof(int) * (size_t)(n + 1));
    double *tab = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    yp_cmdlist plain = {0};
    int best = -1, bestfail = n + 1, nos = 0, nns = 0, nscap = 0, rc = -1;
    hsr_status st = HSR_OK;
    if (!os || !val || !ost || !nextfail || !tab) goto fallback;
    /* the candidate of the previous line that fails at the fewest pixels: an Eval of the
     * same term (the same pattern: the column alone does not say whose it is, two patterns
     * sharing the pixel x0 both start there), order and column */
    for (int i = i0; i < i1; i++) {
        const yp_cmd *e = &prev->c[i];
        if (e->op != YP_EVAL || e->order != order || e->x != x0 || e->term != term) continue;
        int no = gather_sets(prev, i0, i, n, os), fails = 0;
        eval_sets(order, e->v, n, os, no, val, NULL);
        for (int x = 0; x < n; x++) fails += use[x] && !ok_at((double)val[x] / S, f[x], tolv ? tolv[x] : tol, clamp);
        if (fails < bestfail) { bestfail = fails; best = i; }
    }
    if (best < 0) goto fallback;
    const yp_cmd *oe = &prev->c[best];
    nos = gather_sets(prev, i0, best, n, os);
    eval_sets(order, oe->v, n, os, nos, val, ost);
    nextfail[n] = n;
    for (int x = n - 1; x >= 0; x--)
        nextfail[x] = use[x] && !ok_at((double)val[x] / S, f[x], tolv ? tolv[x] : tol, clamp) ? x : nextfail[x + 1];
    int64_t hv[3] = {oe->v[0], oe->v[1], oe->v[2]};
    segtab tb = {tab, tab + n + 1, tab + 2 * (n + 1), 0};
    int sync = 0, xf = nextfail[0], io = 0;   /* on the old spline from column sync; io: next old Set */
    int fresh = 0, nold = 0;                  /* a new Eval; old Sets kept */
    while (xf < n && st == HSR_OK) {
        /* refit from the last old knot that still lets the refit reach xf */
        int k = sync;
        for (int j = 0; j < nos; j++) if (os[j].reg == order && os[j].pos > k && os[j].pos <= xf - order) k = os[j].pos;
        /* the old Sets of [sync, k) stay, and those of the lower registers at k */
        for (; io < nos && (os[io].pos < k || (os[io].pos == k && os[io].reg < order)); io++)
            if (os[io].pos >= sync) {
                int dup = 0;   /* a resync at sync already holds the old Set */
                for (int j = 0; j < nns; j++) dup |= ns_[j].pos == os[io].pos && ns_[j].reg == os[io].reg;
                if (!dup) { st = push_fset(&ns_, &nns, &nscap, os[io]); nold++; }
            }
        for (int j = 0; j < nns; j++) if (ns_[j].pos == k && ns_[j].reg == order) ns_[j] = ns_[--nns];
        int64_t v[3];
        if (k == 0) {
            /* the first pixels fail: a new Eval, started as yp_fit starts it */
            int j = 1;
            while (j < n && !use[j]) j++;
            hv[0] = llround(f[0] * S); hv[1] = order == 2 && j < n ? llround((f[j] - f[0]) / j * S) : 0; hv[2] = 0;
            nns = 0; nold = 0; fresh = 1;
        }
        for (int r = 0; r < 3; r++) v[r] = k == 0 ? hv[r] : ost[3 * k + r];
        /* refit segments until the old spline can be taken up again */
        int from = xf;
        for (;;) {
            double c = 0;
            cohstop cs = {nextfail, n, from, YP_COH_LMIN};
            int bestp = greedy(f, use, th, n, order, T, tf, clamp, k, v, &tb, coh_stop, &cs, &c);
            if (bestp < 0) goto fallback;
            if (k == 0) hv[order] = (int64_t)c;
            else if ((st = push_fset(&ns_, &nns, &nscap, (fset){k, order, (int64_t)c})) != HSR_OK) break;
            v[order] = (int64_t)c;
            int last = n - 1;
            while (last > bestp && !use[last]) last--;
            if (last == bestp) { xf = n; io = nos; break; }   /* reaches the end: no old Set after it */
            if (coh_stop(&cs, bestp)) {                          /* back onto the old spline */
                int r = bestp + 1;
                for (int g = 0; g <= order && st == HSR_OK; g++) st = push_fset(&ns_, &nns, &nscap, (fset){r, g, ost[3 * r + g]});
                nold++;                                          /* the old spline from r on */
                sync = r; xf = nextfail[r];
                while (io < nos && os[io].pos <= r) io++;      /* those at r are the resync's values */
                break;
            }
            int knot = bestp + 1 - order;
            if (knot <= k) knot = k + 1;
            for (int x = k; x < knot; x++)
                for (int r = 0; r < order; r++) v[r] = (int64_t)((uint64_t)v[r] + (uint64_t)v[r + 1]);
            k = knot; from = k;
        }
    }
    /* the old Sets after the last resync */
    for (; st == HSR_OK && xf >= n && io < nos; io++)
        if (os[io].pos >= sync) { st = push_fset(&ns_, &nns, &nscap, os[io]); nold++; }
    if (st != HSR_OK) goto fallback;
    if (nns) qsort(ns_, (size_t)nns, sizeof *ns_, fset_cmp);
    /* the re-check, and the cost against a plain refit: more than a quarter (and 8
     * slots) above it and the line starts afresh, so resyncs do not pile up */
    eval_sets(order, hv, n, ns_, nns, val, NULL);
    for (int x = 0; x < n; x++) if (use[x] && !ok_at((double)val[x] / S, f[x], tolv ? tolv[x] : tol, clamp)) goto fallback;
    if (yp_fit(f, use, th, n, x0, order, tf, clamp, &plain) < 0) goto fallback;
    int slots = order + 3 + 2 * nns;
    if (slots > plain.slots + (plain.slots / 4 > 8 ? plain.slots / 4 : 8)) goto fallback;
    for (int j = 0; j < nns && st == HSR_OK; j++) {
        static const uint8_t op[3] = {YP_SETI, YP_SETDI, YP_SETDDI};
        yp_cmd s = {op[ns_[j].reg], 0, (uint16_t)(x0 + ns_[j].pos), 1, {ns_[j].v, 0, 0}, 0};
        st = yp_cmdlist_push(out, s);
    }
    yp_cmd ev = {YP_EVAL, (uint8_t)order, (uint16_t)x0, (uint16_t)n, {hv[0], hv[1], hv[2]}, 0};
    if (st == HSR_OK) st = yp_cmdlist_push(out, ev);
    if (st == HSR_OK) st = push_from(plain_out, &plain, 0);
    rc = st == HSR_OK ? nns : -1;
    if (kept) *kept = !fresh || nold > 0;
    goto done;
fallback:
    rc = yp_fit(f, use, th, n, x0, order, tf, clamp, out);
    if (push_from(plain_out, out, out0) != HSR_OK) rc = -1;
done:
    free(th); free(os); free(ns_); free(val); free(ost); free(nextfail); free(tab); yp_cmdlist_free(&plain);
    return rc;
}
