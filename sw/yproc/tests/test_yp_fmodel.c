/* test_yp_fmodel.c - yp_simulate_line is sw/fmodel: a line's commands, serialised by yproc
 * and run through fm_render, give the pixels of the same commands given to fm_line_exec
 * directly (fmodel.h), on lines built to exercise every flag the array keeps - Dis, the
 * lock an Eval0 sets, the protect flags of SetI/SetdI/SetddI and their drop at the end
 * of each Eval, Acc_mode - and on random lines (seed printed; YP_FMODEL_SEED=S replays).
 * A few pixels are also checked against values worked out by hand from docs/isa.md §6,
 * so a flag-bit error in either path fails here. */
#include <stdlib.h>
#include <string.h>
#include "t.h"
#include "yp_internal.h"
#include "fmodel.h"
#include "de_isa.h"

#define W 96
#define MAXC 64
#define ONE ((int64_t)1 << 24)      /* 1 pixel unit in 12.24 */

/* the same line twice: as yproc commands and as fmodel commands */
typedef struct { yp_cmdlist yp; fm_cmd fm[MAXC]; int n; } pair;

static void add(pair *p, yp_cmd y, fm_cmd f)
{
    if (p->n >= MAXC) return;
    CHECK(yp_cmdlist_push(&p->yp, y) == HSR_OK);
    p->fm[p->n++] = f;
}
/* Eval of order 0..2 (Eval1..Eval3): values I, dI, ddI */
static void eval(pair *p, int x, int dx, int order, int64_t i, int64_t di, int64_t ddi)
{
    yp_cmd y = {YP_EVAL, (uint8_t)order, (uint16_t)x, (uint16_t)dx, {i, di, ddi}, 0};
    fm_cmd f = {FM_EVAL, x, dx, order + 1, {i, di, ddi}};
    add(p, y, f);
}
static void eval0(pair *p, int x, int dx, int v)
{
    yp_cmd y = {YP_EVAL0, 0, (uint16_t)x, (uint16_t)dx, {v, 0, 0}, 0};
    fm_cmd f = {FM_EVAL0, x, dx, 1, {v}};
    add(p, y, f);
}
/* r = 0, 1, 2: SetI, SetdI, SetddI */
static void set(pair *p, int r, int x, int dx, int64_t v)
{
    yp_cmd y = {(uint8_t)(YP_SETI + r), 0, (uint16_t)x, (uint16_t)dx, {v, 0, 0}, 0};
    fm_cmd f = {FM_SETI + r, x, dx, 1, {v}};
    add(p, y, f);
}
static void dis(pair *p, int x, int dx)
{
    yp_cmd y = {YP_DIS, 0, (uint16_t)x, (uint16_t)dx, {0, 0, 0}, 0};
    fm_cmd f = {FM_DIS, x, dx, 0, {0}};
    add(p, y, f);
}
static void accmode(pair *p, int on)
{
    yp_cmd y = {YP_ACCMODE, 0, 0, 0, {on, 0, 0}, 0};
    fm_cmd f = {FM_ACCMODE, 0, 0, 1, {on}};
    add(p, y, f);
}

/* yp_simulate_line against fm_line_exec of the same commands; 1 if equal (both in *yp,
 * *fm) */
static int same_pixels(const pair *p, int width, uint16_t *yp, uint16_t *fm)
{
    fm_line *l = NULL;
    if (fm_line_new(width, 0, &l) != FM_OK) return 0;
    for (int i = 0; i < p->n; i++) CHECK(fm_line_exec(l, &p->fm[i]) == FM_OK);
    fm_line_pixels(l, fm);
    fm_line_free(l);
    CHECK(yp_simulate_line(&p->yp, width, yp) == HSR_OK);
    int bad = 0;
    for (int x = 0; x < width; x++)
        if (yp[x] != fm[x]) {
            if (bad++ < 4) fprintf(stderr, "     column %d: yp_simulate_line %u, fmodel %u\n", x, yp[x], fm[x]);
        }
    return bad == 0;
}

static void test_flags_dis_lock_protect_acc_mode_give_fmodels_pixels(void)
{
    pair p = {0};
    eval(&p, 0, W, 0, 100 * ONE + ONE / 2, 0, 0);  /* background 100 (+ 1/2) everywhere */
    dis(&p, 10, 10);                            /* 10..19 disabled ... */
    eval0(&p, 15, 10, 700);                     /* ... so Eval0 locks 20..24 only */
    eval(&p, 10, 20, 0, 5 * ONE, 0, 0);         /* +5: 10..14 still disabled (the Eval0 dropped Dis in
                                                 * its own span only), 20..24 locked */
    eval0(&p, 20, 2, 900);                      /* a locked pixel keeps its Eval0 value */
    set(&p, 0, 40, 1, 50 * ONE);                /* knots: A at 40 ... */
    set(&p, 1, 44, 1, 2 * ONE);                 /* ... dI at 44 ... */
    set(&p, 2, 48, 1, -ONE / 4);                /* ... ddI at 48 */
    eval(&p, 32, 24, 2, 10 * ONE, ONE, 0);      /* Eval3 over 32..55 honours all three */
    eval(&p, 40, 10, 0, 3 * ONE, 0, 0);         /* the protect flags dropped: plain +3 */
    set(&p, 2, 60, 1, ONE);                     /* ddI knot under an Eval2: not honoured */
    set(&p, 1, 62, 1, -3 * ONE);                /* dI knot: honoured by the Eval2 */
    eval(&p, 58, 10, 1, 20 * ONE, ONE, 0);
    accmode(&p, 1);                             /* negative A adds nothing ... */
    eval(&p, 70, 20, 1, 8 * ONE, -ONE, 0);      /* ... A = 8, 7, ..., 0, -1, ... */
    accmode(&p, 0);
    dis(&p, 88, 4);
    eval(&p, 86, 10, 0, 2 * ONE, 0, 0);         /* 88..91 disabled for this Eval only */
    eval(&p, 86, 10, 0, ONE, 0, 0);
    uint16_t yp[W], fm[W];
    CHECK(same_pixels(&p, W, yp, fm));
    /* by hand (docs/isa.md §6) */
    CHECK(yp[5] == 100);                        /* background only */
    CHECK(yp[12] == 100 && yp[17] == 105);      /* 15..19: disabled for the Eval0, not after it */
    CHECK(yp[22] == 700 && yp[20] == 700);      /* locked by the first Eval0: no +5, no 900 */
    CHECK(yp[25] == 105 && yp[30] == 100);
    CHECK(yp[32] == 110 && yp[33] == 111);      /* Eval3 from 32: I = 10, dI = 1 */
    CHECK(yp[40] == 153);                       /* A knot 50 at 40, then +3 */
    CHECK(yp[41] == 154);                       /* I = 51 (dI 1 continues), +3 */
    CHECK(yp[45] == 100 + 50 + 1 + 1 + 1 + 1 + 2 + 3); /* dI 2 from 44 on: 50,51,52,53,54,56 */
    CHECK(yp[60] == 122);                       /* Eval2: the ddI knot is not its register */
    CHECK(yp[62] == 124 && yp[63] == 121);      /* I = 24 at 62, then dI = -3 */
    CHECK(yp[70] == 108 && yp[78] == 100 && yp[79] == 100 && yp[85] == 100); /* Acc_mode */
    CHECK(yp[86] == 103 && yp[88] == 101 && yp[91] == 101 && yp[92] == 103);
    yp_cmdlist_free(&p.yp);
}

/* random lines of every command yproc emits, clipped and overlapping */
static void test_random_lines_give_fmodels_pixels(void)
{
    unsigned long long seed = 20261126, s;
    const char *env = getenv("YP_FMODEL_SEED");
    if (env) seed = strtoull(env, NULL, 10);
    printf("     seed %llu (YP_FMODEL_SEED=%llu replays)\n", seed, seed);
    s = seed;
    int lines = t_quick ? 200 : 2000, bad = 0;
    for (int k = 0; k < lines; k++) {
        pair p = {0};
        int width = 1 + (int)(t_rand(&s) % W);
        int n = 1 + (int)(t_rand(&s) % (MAXC - 1));
        for (int i = 0; i < n; i++) {
            int x = (int)(t_rand(&s) % (unsigned)(width + 4)), dx = (int)(t_rand(&s) % (unsigned)(width + 1));
            int64_t v[3];       /* any 36-bit pattern, as signed 12.24 */
            for (int j = 0; j < 3; j++) {
                uint64_t r = ((uint64_t)t_rand(&s) << 32 | t_rand(&s)) & DE_WORD_MASK;
                v[j] = (int64_t)r - (int64_t)(r >> (DE_WORD_BITS - 1) << DE_WORD_BITS);
            }
            switch (t_rand(&s) % 8) {
            case 0: case 1: eval(&p, x, dx, (int)(t_rand(&s) % 3), v[0], v[1] >> (t_rand(&s) % 8), v[2] >> 8); break;
            case 2: eval0(&p, x, dx, (int)(t_rand(&s) % 4096)); break;
            case 3: case 4: set(&p, (int)(t_rand(&s) % 3), x, 1 + (int)(t_rand(&s) % 3), v[0]); break;
            case 5: dis(&p, x, dx); break;
            case 6: accmode(&p, (int)(t_rand(&s) % 2)); break;
            default: eval(&p, 0, width, 0, v[0] >> 4, 0, 0); break;
            }
        }
        uint16_t yp[W], fm[W];
        if (!same_pixels(&p, width, yp, fm) && bad++ < 3) fprintf(stderr, "     line %d of seed %llu differs\n", k, seed);
        yp_cmdlist_free(&p.yp);
    }
    CHECK(bad == 0);
}

static void test_errors_give_a_status_and_a_black_line(void)
{
    pair p = {0};
    eval(&p, 0, 8, 0, 7 * ONE, 0, 0);
    uint16_t pix[8];
    CHECK(yp_simulate_line(&p.yp, 8, pix) == HSR_OK && pix[3] == 7);
    CHECK(yp_simulate_line(&p.yp, 8, NULL) == HSR_EINVAL);
    CHECK(yp_simulate_line(NULL, 8, pix) == HSR_EINVAL && pix[3] == 0);
    CHECK(yp_simulate_line(&p.yp, 0, pix) == HSR_EINVAL);
    /* a Refresh inside the list would end the line: a list is one line */
    yp_cmd r = {YP_REFRESH, 0, 0, 0, {0, 0, 0}, 0};
    CHECK(yp_cmdlist_push(&p.yp, r) == HSR_OK);
    memset(pix, 0xff, sizeof pix);
    CHECK(yp_simulate_line(&p.yp, 8, pix) == HSR_EINVAL && pix[0] == 0 && pix[7] == 0);
    /* an empty line is the cleared array */
    yp_cmdlist e = {0};
    CHECK(yp_simulate_line(&e, 8, pix) == HSR_OK && pix[0] == 0);
    yp_cmdlist_free(&p.yp);
}

void suite_yp_fmodel(void)
{
    RUN(test_flags_dis_lock_protect_acc_mode_give_fmodels_pixels);
    RUN(test_random_lines_give_fmodels_pixels);
    RUN(test_errors_give_a_status_and_a_black_line);
}
