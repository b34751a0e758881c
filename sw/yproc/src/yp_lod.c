/* yp_lod.c - the Load Monitor loop (section 7.5: "based on this information,
 * higher level processes may adapt the level of detail or the quality of the
 * illumination model"; docs/yproc.md section 10): per line a level of detail,
 * lowered where the previous frame's line was late or close to the capacity and
 * raised again where the load predicted at the higher level fits. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"

/* per level: colour-function order cap (3 Eval3, 2 Eval2, 1 Eval1), anti-aliasing,
 * tolerance factor, texture term.  Ordered by cost on the shipped scenes (docs/yproc.md
 * section 10): anti-aliasing is the largest single cost (about 3.5 slots per pattern
 * row), then the order and the tolerance of the colour functions. */
static const struct { int order, aa; double tolf; int tex; } LEV[YP_LOD_MAX + 1] = {
    {2, 0, 64, 0},   /* 0: Eval2, point sampled, tolerance x64, no texture */
    {2, 0, 16, 0},   /* 1: Eval2, point sampled, no texture */
    {2, 0, 4, 1},    /* 2: Eval2, point sampled */
    {3, 0, 4, 1},    /* 3: Eval3, point sampled */
    {3, 1, 4, 1},    /* 4: Eval3, area sampled, tolerance x4 */
    {3, 1, 1, 1},    /* 5: the base options */
};

void yp_lod_line_options(const yp_options *base, int lev, int *maxlev, int *aa, double *tol, int *texture)
{
    if (lev < 0) lev = 0;
    if (lev > YP_LOD_MAX) lev = YP_LOD_MAX;
    int top = base->shading == YP_FLAT ? 1 : base->shading == YP_GOURAUD ? 2 : 3;
    *maxlev = LEV[lev].order < top ? LEV[lev].order : top;
    *aa = LEV[lev].aa && base->aa;
    *tol = base->tol * LEV[lev].tolf;
    *texture = LEV[lev].tex;
}

void yp_lod_monitor(const int *slots, int n, int capacity, int *issued, int *late)
{
    long drain = 0;   /* words of a late line still to be discarded (its marker included) */
    for (int l = 0; l < n; l++) {
        /* slots of this window after the discard.  A discard longer than the window goes on
         * through the line's last cycle, outside the window (HTotal = capacity + 2 cycles per
         * line): in a cascade of late lines the tail shrinks by one word more per line than
         * the window (found with the Verilated controller in the loop, docs/yproc.md 10) */
        long room;
        if (drain > capacity + 1) { room = 0; drain -= capacity + 2; }
        else { room = capacity + 1 - drain; drain = 0; }
        int sl = slots[l];                          /* slots and issued may be one array */
        late[l] = sl + 1 > room;
        issued[l] = late[l] ? (int)room : sl;
        if (late[l]) drain += sl + 1 - room;
    }
}

#define HIGH 0.80       /* high-water mark: lower a line above it */
#define RAISE 0.70      /* raise only if the predicted load stays below this */
#define BACKOFF0 4      /* frames before a level that was late is tried again (doubling) */
#define RMIN 1.25       /* smallest cost ratio between levels believed (measurements during
                         * motion mix the level's cost with the load's change) */
#define PROBE 8         /* with yp_lod_fit: frames at a level before the next one is probed */
#define ROPT 2.0        /* with yp_lod_fit: the largest learned ratio used for a line whose own
                         * is unknown (a raise that does not fit is lowered again before it is
                         * emitted: it costs a re-scan, not an overflow) */

struct yp_lod {
    int H, cap;
    unsigned char *lev;
    int *prev_issued;         /* last frame's issued, -1 unknown */
    unsigned char *prev_lev;
    int *block;               /* per line and level: frame before which it is not tried again */
    int *backoff;             /* per line and level: the last wait, doubled at each late try */
    double *rl;               /* per line and level k: load(k + 1) / load(k) measured on this
                               * line, or a lower bound from a late try; 0 unknown */
    int *rll;                 /* per line and level: the load at that level when rl was set */
    int *barl;                /* per line and level: the load one level below when the level was
                               * barred (first frame after); the bar lifts when it falls by 30 % */
    int *since;               /* per line: frames at its level (yp_lod_fit's lowering included) */
    unsigned char *pending;   /* per line: late last frame, bound the ratio from this frame's load */
    double *pred;             /* per line: its load predicted one level up */
    int frame;
    int fitted;               /* yp_lod_fit guards the frames: raise on an optimistic ratio */
    double ratio[YP_LOD_MAX]; /* learned load(k + 1) / load(k) */
};

hsr_status yp_lod_new(int height, int capacity, yp_lod **out)
{
    if (!out || height < 1 || capacity < 1) return HSR_EINVAL;
    yp_lod *l = calloc(1, sizeof *l);
    if (!l) return HSR_ENOMEM;
    l->H = height; l->cap = capacity;
    l->lev = malloc((size_t)height);
    l->prev_lev = malloc((size_t)height);
    l->prev_issued = malloc(sizeof(int) * (size_t)height);
    l->block = calloc((size_t)height * (YP_LOD_MAX + 1), sizeof(int));
    l->backoff = calloc((size_t)height * (YP_LOD_MAX + 1), sizeof(int));
    l->rl = calloc((size_t)height * (YP_LOD_MAX + 1), sizeof(double));
    l->rll = calloc((size_t)height * (YP_LOD_MAX + 1), sizeof(int));
    l->barl = calloc((size_t)height * (YP_LOD_MAX + 1), sizeof(int));
    l->pending = calloc((size_t)height, 1);
    l->since = calloc((size_t)height, sizeof(int));
    l->pred = calloc((size_t)height, sizeof(double));
    if (!l->lev || !l->prev_lev || !l->prev_issued || !l->block || !l->backoff || !l->rl || !l->rll || !l->barl || !l->pending || !l->pred || !l->since) { yp_lod_free(l); return HSR_ENOMEM; }
    memset(l->lev, YP_LOD_MAX, (size_t)height);
    memset(l->prev_lev, YP_LOD_MAX, (size_t)height);
    for (int y = 0; y < height; y++) l->prev_issued[y] = -1;
    for (int k = 0; k < YP_LOD_MAX; k++) l->ratio[k] = 1.6;
    *out = l;
    return HSR_OK;
}

void yp_lod_free(yp_lod *l)
{
    if (!l) return;
    free(l->lev); free(l->prev_lev); free(l->prev_issued); free(l->block); free(l->backoff); free(l->rl); free(l->rll); free(l->barl); free(l->pending); free(l->pred); free(l->since); free(l);
}

const unsigned char *yp_lod_levels(const yp_lod *l) { return l ? l->lev : NULL; }

int yp_lod_update(yp_lod *l, const int *issued, const int *late)
{
    if (!l || !issued || !late) return 0;
    const int H = l->H;
    const double cap = l->cap;
    /* learn the cost ratio between adjacent levels from lines that moved by one level
     * between two frames without being late in either (load here / load there) */
    double sum[YP_LOD_MAX] = {0};
    int cnt[YP_LOD_MAX] = {0};
    for (int y = 0; y < H; y++) {
        int a = l->prev_lev[y], b = l->lev[y];
        if (l->prev_issued[y] <= 0 || issued[y] <= 0 || late[y] || abs(a - b) != 1 || l->prev_issued[y] > cap) continue;
        int k = a < b ? a : b;
        double lo = a < b ? l->prev_issued[y] : issued[y], hi = a < b ? issued[y] : l->prev_issued[y];
        sum[k] += hi / lo; cnt[k]++;
    }
    for (int k = 0; k < YP_LOD_MAX; k++)
        if (cnt[k]) l->ratio[k] = fmax(RMIN, 0.5 * l->ratio[k] + 0.5 * sum[k] / cnt[k]);
    int changed = 0;
    for (int y = 0; y < H; y++) {
        int lv = l->lev[y];
        double *rl = &l->rl[y * (YP_LOD_MAX + 1)];
        int *rll = &l->rll[y * (YP_LOD_MAX + 1)];
        int pl = l->prev_lev[y], pi = l->prev_issued[y];
        /* a ratio belongs to the line's content: forget it when the load at its level
         * has moved by more than 30 % since it was set */
        if (rl[lv] > 0 && !late[y] && rll[lv] > 0 && abs(issued[y] - rll[lv]) > 0.3 * rll[lv]) rl[lv] = 0;
        /* this line's own cost ratios: measured when it moved by one level on time, and
         * bounded from below when a level was late: the window (capacity + 1) was not
         * enough for what fitted in `issued` one or two levels down */
        if (!late[y] && pi > 0 && issued[y] > 0 && !l->pending[y] && abs(pl - lv) == 1) {
            rl[pl < lv ? pl : lv] = fmax(RMIN, pl < lv ? (double)issued[y] / pi : (double)pi / issued[y]);
            rll[pl < lv ? pl : lv] = pl < lv ? pi : issued[y];
        }
        if (l->pending[y] && !late[y] && issued[y] > 0 && lv < YP_LOD_MAX) {
            rl[lv] = fmax(rl[lv], (cap + 1) / issued[y]);
            rll[lv] = issued[y];
        }
        /* late on its own: the window was full of its words; a line late with fewer words
         * lost the start of its window to the tail of a late line above it */
        int own = late[y] && issued[y] >= cap + 1;
        if (own && pl == lv - 1 && pi > 0)                /* a raise that failed */
        {
            rl[pl] = fmax(rl[pl], (cap + 1) / pi);
            rll[pl] = pi;
        }
        l->pending[y] = (unsigned char)own;
        double gr = l->fitted ? fmin(l->ratio[lv < YP_LOD_MAX ? lv : 0], ROPT) : l->ratio[lv < YP_LOD_MAX ? lv : 0];
        l->pred[y] = lv < YP_LOD_MAX ? issued[y] * (rl[lv] > 0 ? rl[lv] : gr) : issued[y];
    }
    for (int y = 0; y < H; y++) {
        int lv = l->lev[y], nl = lv;
        int *bo = &l->backoff[y * (YP_LOD_MAX + 1)], *bl = &l->block[y * (YP_LOD_MAX + 1)];
        int own = late[y] && issued[y] >= cap + 1;
        int *barl = &l->barl[y * (YP_LOD_MAX + 1)];
        if (!late[y] && lv < YP_LOD_MAX && l->frame < bl[lv + 1]) {
            if (!barl[lv + 1]) barl[lv + 1] = issued[y] > 0 ? issued[y] : 1;
            else if (issued[y] < 0.7 * barl[lv + 1]) bl[lv + 1] = l->frame;   /* the load fell */
        }
        /* the load predicted one level up, of the line and of its neighbours (what moves
         * vertically brings its load along), each at its own cost ratio */
        double pred = l->pred[y];
        if (lv < YP_LOD_MAX && bl[lv + 1] > 0 && l->frame >= bl[lv + 1] && !late[y]) {
            /* the bar on the next level has run out: probe it once with the ratio of all
             * lines (the load one level down may not show that what overflowed is gone) */
            l->rl[y * (YP_LOD_MAX + 1) + lv] = 0;
            bl[lv + 1] = 0;
            pred = issued[y] * (l->fitted ? fmin(l->ratio[lv], ROPT) : l->ratio[lv]);
        }
        if (y > 0 && l->pred[y - 1] > pred) pred = l->pred[y - 1];
        if (y + 1 < H && l->pred[y + 1] > pred) pred = l->pred[y + 1];
        if (late[y] && l->prev_lev[y] == lv - 1) {
            /* raised last frame and late now (on its own, or hidden behind the tail of a
             * line above that was raised with it): back down, and wait before retrying */
            nl = lv - 1;
            bo[lv] = bo[lv] ? 2 * bo[lv] : BACKOFF0;
            if (bo[lv] > 256) bo[lv] = 256;
            bl[lv] = l->frame + bo[lv];
        } else if (late[y] && !own) {
            nl = lv > 0 ? lv - 1 : 0;   /* fewer words help it through the shortened window */
        } else if (late[y]) {
            /* the excess is unknown (a late line's count is its window): two levels down,
             * and this level is not tried again for a while (doubling at each late try) */
            nl = lv >= 2 ? lv - 2 : 0;
            bo[lv] = bo[lv] ? 2 * bo[lv] : BACKOFF0;
            if (bo[lv] > 256) bo[lv] = 256;
            bl[lv] = l->frame + bo[lv];
        } else if (issued[y] > (l->fitted ? 1.0 : HIGH) * cap) {
            nl = lv > 0 ? lv - 1 : 0;
        } else if (lv < YP_LOD_MAX && l->frame >= bl[lv + 1]
                   && (pred < RAISE * cap || (l->fitted && l->since[y] >= PROBE))) {
            /* with yp_lod_fit a line also probes the next level after PROBE frames at its
             * own: a raise that does not fit is lowered before it is emitted */
            nl = lv + 1;
            barl[nl] = 0;
        } else if (l->frame >= bl[lv] + 4 * bo[lv]) {
            bo[lv] = 0;   /* on time at this level long enough: forget its late tries */
        }
        l->prev_lev[y] = (unsigned char)lv;
        l->prev_issued[y] = issued[y];
        l->lev[y] = (unsigned char)nl;
        l->since[y] = nl != lv || l->prev_lev[y] != lv ? 0 : l->since[y] + 1;
        changed += nl != lv;
    }
    l->frame++;
    return changed;
}

/* the largest slot count of line y over the three colours */
static int line_slots(const yp_frame *fr, int y)
{
    int s = 0;
    for (int c = 0; c < 3; c++) if (fr->st[y].slots[c] > s) s = fr->st[y].slots[c];
    return s;
}

hsr_status yp_lod_fit(yp_lod *l, const yp_shader *sh, const hsr_ctx *h, const yp_options *o,
                      yp_frame *fr, int *lowered, int *y0, int *y1)
{
    if (lowered) *lowered = 0;
    if (!l || !sh || !h || !o || !fr || o->line_lod != l->lev || fr->height != l->H) return HSR_EINVAL;
    const int H = l->H, L1 = YP_LOD_MAX + 1;
    int *above = malloc(sizeof(int) * (size_t)H);   /* slots one level up of a lowered line, 0 if none */
    unsigned char *now = calloc((size_t)H, 1);
    if (!above || !now) { free(above); free(now); return HSR_ENOMEM; }
    hsr_status st = HSR_OK;
    int n = 0;
    l->fitted = 1;
    for (int y = 0; y < H; y++) above[y] = 0;
    for (;;) {
        int any = 0;
        for (int y = 0; y < H; y++) {
            int s = line_slots(fr, y);
            now[y] = s > l->cap && l->lev[y] > 0;
            if (!now[y]) continue;
            n += !above[y];
            above[y] = s;
            l->lev[y]--;
            any = 1;
        }
        if (!any) break;
        /* re-scan the runs of lowered lines (runs closer than 8 lines together: one scan
         * of a few lines costs about as much as the coverage of the groups it touches) */
        for (int y = 0; y < H && st == HSR_OK;) {
            if (!now[y]) { y++; continue; }
            int a = y, b = y + 1;
            for (int g = b; g < H && g < b + 8; g++) if (now[g]) b = g + 1;
            while (b < H && now[b]) b++;
            st = yp_scan(sh, h, o, a, b, fr);
            if (y0 && y1) {
                if (*y0 >= *y1) { *y0 = a; *y1 = b; }
                if (a < *y0) *y0 = a;
                if (b > *y1) *y1 = b;
            }
            y = b;
        }
        if (st != HSR_OK) break;
    }
    /* what the fit learned: the cost ratio between the line's level and the one above it
     * (both counts known exactly), and the level above is barred like a failed raise */
    for (int y = 0; y < H && st == HSR_OK; y++) {
        if (!above[y]) continue;
        int k = l->lev[y], s = line_slots(fr, y);
        if (k >= YP_LOD_MAX) continue;
        double *rl = &l->rl[y * L1];
        int *rll = &l->rll[y * L1], *bo = &l->backoff[y * L1], *bl = &l->block[y * L1];
        if (s > 0) { rl[k] = fmax(RMIN, (double)above[y] / s); rll[k] = s; }
        bo[k + 1] = bo[k + 1] ? 2 * bo[k + 1] : BACKOFF0;
        if (bo[k + 1] > 256) bo[k + 1] = 256;
        bl[k + 1] = l->frame + bo[k + 1];
        l->barl[y * L1 + k + 1] = 0;
    }
    free(above); free(now);
    if (lowered) *lowered = n;
    return st;
}
