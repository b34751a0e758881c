/* test_fmodel.c - the C tests of sw/fmodel: each command against hand-computed PE state,
 * the tight loop against the general one, the carry-bug adder, the stream decoder's
 * refusals (slot for slot as binfmt.deserialise), whole streams into images.
 * The comparison with the numpy golden model, command by command, is
 * sw/tests/test_fmodel.py. Prints "N passed, M failed" last (t_report). */
#include <string.h>
#include "t.h"          /* the harness of the C libraries (sw/hsr/tests/t.h, t.c) */
#include "fmodel.h"
#include "de_isa.h"

#define ONE (INT64_C(1) << DE_FRAC_BITS)
#define W 64

static fm_cmd cmd(int op, int x, int dx, int n, int64_t v0, int64_t v1, int64_t v2)
{
    fm_cmd c = {op, x, dx, n, {v0, v1, v2, 0, 0, 0, 0, 0}};
    return c;
}
static fm_cmd eval(int x, int dx, int n, int64_t v0, int64_t v1, int64_t v2)
{
    return cmd(FM_EVAL, x, dx, n, v0, v1, v2);
}

static uint64_t regs[4 * W];
static uint8_t flags[5 * W];
#define REG(k, c) regs[(k) * W + (c)]
#define FLAG(k, c) flags[(k) * W + (c)]

static fm_line *line(int bug)
{
    fm_line *l = NULL;
    CHECK(fm_line_new(W, bug, &l) == FM_OK);
    return l;
}

static void state(fm_line *l) { int am; fm_line_state(l, regs, flags, &am); }

static void test_eval_orders(void)
{
    fm_line *l = line(0);
    fm_cmd c = eval(10, 20, 3, 5 * ONE, ONE / 2, ONE / 8);
    CHECK(fm_line_exec(l, &c) == FM_OK);
    state(l);
    for (int col = 0; col < W; col++) {
        int64_t m = col - 10, want = 0;
        if (col >= 10 && col < 30) want = 5 * ONE + m * (ONE / 2) + m * (m - 1) / 2 * (ONE / 8);
        CHECK(REG(FM_REG_D, col) == ((uint64_t)want & DE_WORD_MASK));
        if (col >= 10 && col < 30) {
            CHECK(REG(FM_REG_A, col) == (uint64_t)want);
            CHECK(REG(FM_REG_B, col) == (uint64_t)(ONE / 2 + m * (ONE / 8)));
            CHECK(REG(FM_REG_C, col) == (uint64_t)(ONE / 8));
        }
    }
    uint16_t px[W];
    fm_line_pixels(l, px);
    CHECK(px[10] == 5 && px[12] == 6 && px[9] == 0 && px[30] == 0);
    /* a negative value wraps modulo 2^36 and a second Eval adds on */
    fm_line_reset(l);
    c = eval(0, 4, 1, -ONE, 0, 0);
    fm_line_exec(l, &c);
    fm_line_exec(l, &c);
    state(l);
    CHECK(REG(FM_REG_D, 0) == ((uint64_t)(-2 * ONE) & DE_WORD_MASK));
    fm_line_pixels(l, px);
    CHECK(px[3] == 4094 && px[4] == 0);
    /* order 4: A scratch (level 0), B = d^3, C = d^4; the value is sum C(m,k) v_k */
    fm_line_reset(l);
    fm_cmd c4 = {FM_EVAL, 0, 8, 5, {ONE, 2 * ONE, 3 * ONE, 4 * ONE, 5 * ONE, 0, 0, 0}};
    CHECK(fm_line_exec(l, &c4) == FM_OK);
    state(l);
    for (int64_t m = 0; m < 8; m++) {
        int64_t b[5] = {1, m, m * (m - 1) / 2, m * (m - 1) * (m - 2) / 6, m * (m - 1) * (m - 2) * (m - 3) / 24};
        int64_t want = 0;
        for (int k = 0; k < 5; k++) want += b[k] * (k + 1) * ONE;
        CHECK(REG(FM_REG_D, m) == (uint64_t)want);
        CHECK(REG(FM_REG_B, m) == (uint64_t)(4 * ONE + m * 5 * ONE));
        CHECK(REG(FM_REG_C, m) == (uint64_t)(5 * ONE));
    }
    fm_line_free(l);
}

/* The tight loop (no flags) equals the general loop (forced by a Set outside the span). */
static void test_quiet_equals_general(void)
{
    unsigned long long s = 12345;
    for (int it = 0; it < 200; it++) {
        fm_line *a = line(0), *b = line(0);
        fm_cmd far = cmd(FM_SETDI, W - 1, 1, 1, 7, 0, 0);
        fm_line_exec(b, &far);
        for (int k = 0; k < 6; k++) {
            s = s * 6364136223846793005ULL + 1442695040888963407ULL;
            int x = (int)((s >> 33) % (W - 1)), dx = (int)((s >> 20) % 40), n = 1 + (int)((s >> 10) % 3);
            fm_cmd c = eval(x, dx, n, (int64_t)(s >> 28), (int64_t)(s >> 40) - (1 << 23), (int64_t)(s % 99991) - 50000);
            if (x + dx > W - 1) c.dx = W - 1 - x;
            fm_line_exec(a, &c);
            fm_line_exec(b, &c);
        }
        uint64_t ra[4 * W], rb[4 * W];
        fm_line_state(a, ra, NULL, NULL);
        fm_line_state(b, rb, NULL, NULL);
        for (int k = 0; k < 4; k++)     /* columns 0..W-2: B at W-1 holds b's Set */
            CHECK(!memcmp(ra + k * W, rb + k * W, (W - 1) * sizeof *ra));
        fm_line_free(a);
        fm_line_free(b);
    }
}

static void test_protect(void)
{
    fm_line *l = line(0);
    fm_cmd s = cmd(FM_SETDI, 15, 1, 1, 2 * ONE, 0, 0), e = eval(10, 10, 2, 0, ONE, 0);
    CHECK(fm_line_exec(l, &s) == FM_OK);
    state(l);
    CHECK(FLAG(FM_FLAG_PB, 15) && !FLAG(FM_FLAG_PB, 14) && REG(FM_REG_B, 15) == (uint64_t)(2 * ONE));
    fm_line_exec(l, &e);
    state(l);
    for (int c = 10; c < 20; c++)   /* dI = 1 up to 14, then 2 from the protected B */
        CHECK(REG(FM_REG_D, c) == (uint64_t)((c <= 15 ? c - 10 : 5 + 2 * (c - 15)) * ONE));
    CHECK(!FLAG(FM_FLAG_PB, 15));   /* the Eval dropped it */
    /* an order-1 Eval ignores pC; an order-3 one honours pB (d^2) and pC (d^3), not pA */
    fm_line_reset(l);
    fm_cmd sa = cmd(FM_SETI, 3, 1, 1, 100 * ONE, 0, 0), sc = cmd(FM_SETDDI, 3, 1, 1, ONE, 0, 0);
    fm_line_exec(l, &sa);
    fm_line_exec(l, &sc);
    fm_cmd e3 = {FM_EVAL, 0, 8, 4, {0, 0, 0, 0, 0, 0, 0, 0}};
    fm_line_exec(l, &e3);
    state(l);
    CHECK(REG(FM_REG_D, 3) == 0 && REG(FM_REG_C, 3) == (uint64_t)ONE && REG(FM_REG_A, 3) == 0);
    /* d^3 = 1 from 3 on: d^2 = 1 at 4, dI = 1 at 5, I = 1 at 6, 1 + 3 at 7 */
    CHECK(REG(FM_REG_D, 5) == 0 && REG(FM_REG_D, 6) == (uint64_t)ONE && REG(FM_REG_D, 7) == (uint64_t)(4 * ONE));
    CHECK(!FLAG(FM_FLAG_PA, 3) && !FLAG(FM_FLAG_PC, 3));
    fm_line_free(l);
}

static void test_periodic_dis_eval0(void)
{
    fm_line *l = line(0);
    fm_cmd sp = cmd(FM_SETPI, 4, 10, 1, 7 * ONE, 0, 0);
    fm_line_exec(l, &sp);
    state(l);
    for (int c = 0; c < W; c++) CHECK(FLAG(FM_FLAG_PA, c) == (c >= 4 && (c - 4) % 10 == 0));
    fm_cmd sp0 = cmd(FM_SETPDI, 2, 0, 1, ONE, 0, 0);       /* dX 0: period 4096, one PE */
    fm_line_exec(l, &sp0);
    state(l);
    CHECK(FLAG(FM_FLAG_PB, 2) && !FLAG(FM_FLAG_PB, 3));
    fm_line_reset(l);
    fm_cmd d = cmd(FM_DIS, 5, 3, 0, 0, 0, 0), e = eval(0, 10, 1, ONE, 0, 0);
    fm_line_exec(l, &d);
    fm_line_exec(l, &e);
    state(l);
    for (int c = 0; c < 10; c++) {
        CHECK(REG(FM_REG_D, c) == (c >= 5 && c < 8 ? 0 : (uint64_t)ONE));
        CHECK(!FLAG(FM_FLAG_DIS, c));
    }
    fm_cmd z = cmd(FM_EVAL0, 2, 2, 1, 300, 0, 0);
    fm_line_exec(l, &d);
    fm_cmd z2 = cmd(FM_EVAL0, 6, 2, 1, 9, 0, 0);
    fm_line_exec(l, &z);
    fm_line_exec(l, &z2);
    fm_line_exec(l, &e);
    state(l);
    CHECK(REG(FM_REG_D, 2) == (uint64_t)300 << DE_FRAC_BITS && FLAG(FM_FLAG_LOCK, 2));
    CHECK(REG(FM_REG_D, 6) == (uint64_t)ONE && !FLAG(FM_FLAG_LOCK, 6));  /* disabled */
    CHECK(!FLAG(FM_FLAG_DIS, 6));   /* the Eval0 ended the Dis of its span */
    CHECK(REG(FM_REG_D, 5) == 0 && !FLAG(FM_FLAG_DIS, 5));   /* dis up at 5 until the Eval */
    fm_line_free(l);
}

static void test_acc_mode(void)
{
    fm_line *l = line(0);
    fm_cmd on = cmd(FM_ACCMODE, 0, 0, 1, 1, 0, 0), e = eval(0, 8, 2, 2 * ONE, -ONE, 0);
    fm_line_exec(l, &on);
    fm_line_exec(l, &e);
    int am;
    fm_line_state(l, regs, flags, &am);
    CHECK(am == 1);
    for (int c = 0; c < 8; c++) CHECK(REG(FM_REG_D, c) == (c <= 2 ? (uint64_t)((2 - c) * ONE) : 0));
    CHECK(REG(FM_REG_A, 5) == ((uint64_t)(-3 * ONE) & DE_WORD_MASK));
    fm_line_free(l);
}

static void test_carry_bug(void)
{
    fm_line *l = line(1), *ok = line(0);
    const int64_t v0 = ONE - 1, v1 = ONE / 2 + 3;    /* fraction overflows at once */
    fm_cmd e = eval(0, 20, 2, v0, v1, 0);
    fm_line_exec(l, &e);
    fm_line_exec(l, &e);
    fm_line_exec(ok, &e);
    state(l);
    uint64_t d = 0, a = (uint64_t)v0;
    uint64_t dd[20];
    for (int c = 0; c < 20; c++) {
        dd[c] = de_add_word(0, a, 1);
        a = de_add_word(a, (uint64_t)v1, 1);
    }
    a = (uint64_t)v0;
    for (int c = 0; c < 20; c++) {
        d = de_add_word(dd[c], a, 1);
        CHECK(REG(FM_REG_D, c) == d);
        a = de_add_word(a, (uint64_t)v1, 1);
    }
    uint64_t good[4 * W];
    fm_line_state(ok, good, NULL, NULL);
    CHECK(REG(FM_REG_D, 19) != good[3 * W + 19] * 2);      /* the fault shows */
    fm_line_free(l);
    fm_line_free(ok);
}

static void test_bad_commands(void)
{
    fm_line *l = line(0), *x = NULL;
    fm_cmd bad[] = {cmd(FM_REFRESH, 0, 0, 0, 0, 0, 0), cmd(FM_EVAL, 0, 4096, 1, 0, 0, 0),
                    cmd(FM_EVAL, -1, 1, 1, 0, 0, 0), cmd(FM_EVAL, 0, 1, 9, 0, 0, 0),
                    cmd(FM_EVAL0, 0, 1, 1, 4096, 0, 0), cmd(FM_ACCMODE, 0, 0, 1, 2, 0, 0),
                    cmd(FM_SETI, 0, 1, 0, 0, 0, 0), cmd(99, 0, 1, 1, 0, 0, 0)};
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) CHECK(fm_line_exec(l, &bad[k]) == FM_EINVAL);
    CHECK(fm_line_exec(NULL, &bad[0]) == FM_EINVAL && fm_line_exec(l, NULL) == FM_EINVAL);
    CHECK(fm_line_new(0, 0, &x) == FM_EINVAL && fm_line_new(FM_MAX_WIDTH + 1, 0, &x) == FM_EINVAL);
    CHECK(fm_line_new(8, 0, NULL) == FM_EINVAL);
    fm_cmd wide = eval(4000, 4095, 1, ONE, 0, 0);   /* clipped to the array */
    CHECK(fm_line_exec(l, &wide) == FM_OK);
    CHECK(strcmp(fm_status_str(FM_EFORMAT), "malformed instruction stream") == 0);
    fm_line_free(l);
}

/* ---- streams -------------------------------------------------------------- */
static size_t put(uint8_t *p, size_t i, unsigned ident, uint64_t data)
{
    uint64_t w = ((uint64_t)ident << DE_WORD_BITS) | (data & DE_WORD_MASK);
    for (int k = 5; k >= 0; k--) { p[6 * i + k] = (uint8_t)w; w >>= 8; }
    return i + 1;
}
static uint64_t rng(unsigned x, unsigned dx) { return (x & 0xfff) | ((uint64_t)(dx & 0xfff) << 12); }

/* Eval1 (x, dx, I, dI) then Refresh: one line of the stream */
static size_t put_line(uint8_t *p, size_t i, int x, int dx, int64_t I, int64_t dI)
{
    i = put(p, i, DE_ID_ADDR_RANGE, rng((unsigned)x, (unsigned)dx));
    i = put(p, i, DE_ID_D_B, (uint64_t)dI);
    i = put(p, i, DE_ID_D_A_B, (uint64_t)I);
    i = put(p, i, DE_ID_ACC, 0);
    return put(p, i, DE_ID_REFRESH, 0);
}

static void test_decode(void)
{
    uint8_t p[6 * 64];
    size_t n = 0, pos = 0;
    fm_cmd c;
    fm_error err;
    n = put(p, n, DE_ID_ADDR_PERIODIC, rng(7, 3));     /* periodic: dX low, X high */
    n = put(p, n, DE_ID_SET_C, (uint64_t)-ONE);
    n = put(p, n, DE_ID_ADDR_RANGE, rng(1, 2));
    n = put(p, n, DE_ID_D_C, 3);
    n = put(p, n, DE_ID_D_B_C, 2);
    n = put(p, n, DE_ID_D_A_B_NP, 1);
    n = put(p, n, DE_ID_D_A_A_NP, 9);
    n = put(p, n, DE_ID_ACC, 0);
    n = put(p, n, DE_ID_ADDR_EVAL0, rng(4, 5) | (UINT64_C(77) << 24));
    n = put(p, n, DE_ID_ACCMODE_ON, 0);
    CHECK(fm_decode(p, n, &pos, &c, &err) == FM_OK && pos == 2);
    CHECK(c.op == FM_SETPDDI && c.x == 3 && c.dx == 7 && c.v[0] == (int64_t)((uint64_t)-ONE & DE_WORD_MASK));
    CHECK(fm_decode(p, n, &pos, &c, &err) == FM_OK && pos == 8);
    CHECK(c.op == FM_EVAL && c.nvals == 4 && c.v[0] == 9 && c.v[1] == 1 && c.v[2] == 2 && c.v[3] == 3);
    CHECK(fm_decode(p, n, &pos, &c, &err) == FM_OK && c.op == FM_EVAL0 && c.x == 4 && c.dx == 5 && c.v[0] == 77);
    CHECK(fm_decode(p, n, &pos, &c, &err) == FM_OK && c.op == FM_ACCMODE && c.v[0] == 1 && pos == n);
    CHECK(fm_decode(p, n, &pos, &c, &err) == FM_EINVAL);
    /* refusals, at the slot binfmt.deserialise names */
    struct { unsigned id[3]; uint64_t d[3]; int n; int64_t slot; } bad[] = {
        {{0x123}, {0}, 1, 0},                                        /* unknown identifier */
        {{DE_ID_NOP}, {1}, 1, 0},                                    /* NOP with data */
        {{DE_ID_ADDR_DIS}, {UINT64_C(1) << 24}, 1, 0},               /* block 2 of Dis */
        {{DE_ID_ADDR_RANGE}, {0}, 1, 0},                             /* end of stream */
        {{DE_ID_ADDR_PERIODIC, DE_ID_D_A}, {0, 0}, 2, 1},            /* not a Set */
        {{DE_ID_ADDR_RANGE, DE_ID_D_A, DE_ID_NOP}, {0, 0, 0}, 3, 2}, /* no ACC */
        {{DE_ID_ADDR_RANGE, DE_ID_D_A, DE_ID_ACC}, {0, 0, 5}, 3, 2}, /* ACC with data */
        {{DE_ID_ADDR_RANGE, DE_ID_D_B, DE_ID_ACC}, {0, 0, 0}, 3, 1}, /* not Table 7.2 */
        {{DE_ID_ADDR_RANGE, DE_ID_ACC}, {0, 0}, 2, 1},               /* no data slot */
        {{DE_ID_ACC}, {0}, 1, 0},                                    /* orphan ACC */
        {{DE_ID_SET_A}, {0}, 1, 0},                                  /* orphan Set */
    };
    for (size_t k = 0; k < sizeof bad / sizeof *bad; k++) {
        n = 0;
        for (int j = 0; j < bad[k].n; j++) n = put(p, n, bad[k].id[j], bad[k].d[j]);
        pos = 0;
        err.slot = -7;
        CHECK(fm_decode(p, n, &pos, &c, &err) == FM_EFORMAT);
        CHECK(err.slot == bad[k].slot);
        CHECK(strncmp(err.msg, "slot ", 5) == 0);
    }
}

static void test_render(void)
{
    uint8_t p[6 * 64];
    size_t n = 0, nl = 99, tr = 99;
    n = put_line(p, n, 0, 4, 10 * ONE, ONE);
    n = put_line(p, n, 2, 2, 20 * ONE, 0);
    n = put(p, n, DE_ID_NOP, 0);                       /* a trailing command: no line */
    uint16_t img[3 * 8 * 2];
    memset(img, 0xff, sizeof img);
    int32_t rows[2] = {2, 0};
    fm_error err;
    CHECK(fm_render(p, n, 8, 0, img, 8, 1, rows, 3, &nl, &tr, &err) == FM_OK);
    CHECK(nl == 2 && tr == 1);
    CHECK(img[16] == 10 && img[19] == 13 && img[20] == 0 && img[0] == 0 && img[2] == 20 && img[8] == 0xffff);
    /* too few rows, and a bad word: the image is left alone */
    memset(img, 0xff, sizeof img);
    CHECK(fm_render(p, n, 8, 0, img, 8, 1, NULL, 1, NULL, NULL, &err) == FM_ELIMIT);
    size_t m = put(p, n, DE_ID_ACC, 0);
    CHECK(fm_render(p, m, 8, 0, img, 8, 1, NULL, 8, NULL, NULL, &err) == FM_EFORMAT && err.slot == (int64_t)n);
    CHECK(img[0] == 0xffff && img[3 * 8 * 2 - 1] == 0xffff);
    CHECK(fm_render(p, n, 0, 0, img, 8, 1, NULL, 8, NULL, NULL, &err) == FM_EINVAL);
    CHECK(fm_render(NULL, 0, 8, 0, img, 8, 1, NULL, 8, &nl, &tr, &err) == FM_OK && nl == 0);
    /* three colours interleaved; the g stream only changes row 1 */
    fm_stream s[3] = {{p, n, NULL, 0}, {p, 5, rows + 1, 1}, {p, n, NULL, 0}};
    int32_t one = 1;
    s[1].rows = &one;
    memset(img, 0, sizeof img);
    CHECK(fm_render_rgb(s, 8, 2, 0, img, &err) == FM_OK);
    CHECK(img[0] == 10 && img[1] == 0 && img[2] == 10);
    CHECK(img[(8 + 0) * 3 + 1] == 10 && img[(8 + 2) * 3 + 0] == 20 && img[(8 + 2) * 3 + 1] == 12);
    one = 2;        /* outside the 2-row image */
    CHECK(fm_render_rgb(s, 8, 2, 0, img, &err) == FM_EINVAL && strncmp(err.msg, "colour g", 8) == 0);
    s[1].rows = NULL;
    s[2].nwords = m;
    CHECK(fm_render_rgb(s, 8, 2, 0, img, &err) == FM_EFORMAT && strncmp(err.msg, "colour b: slot", 14) == 0);
}

int main(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (!strcmp(argv[i], "--quick")) t_quick = 1;
    RUN(test_eval_orders);
    RUN(test_quiet_equals_general);
    RUN(test_protect);
    RUN(test_periodic_dis_eval0);
    RUN(test_acc_mode);
    RUN(test_carry_bug);
    RUN(test_bad_commands);
    RUN(test_decode);
    RUN(test_render);
    return t_report();
}
