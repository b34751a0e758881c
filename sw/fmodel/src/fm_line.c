/* fm_line.c - the state of every PE of a line and the commands on it (docs/isa.md §6),
 * a port of `_Line` of sw/diffengine/model/functional.py: an Eval walks its columns left
 * to right, substitutes the registers whose protect flag its order honours, writes the
 * registers, accumulates D unless locked, disabled or (Acc_mode) A < 0, and passes the
 * forward differences on; at its end the protect and dis flags of its span drop. */
#include <stdlib.h>
#include <string.h>
#include "fm_internal.h"
#include "de_isa.h"

const char *fm_status_str(fm_status s)
{
    switch (s) {
    case FM_OK: return "ok";
    case FM_EINVAL: return "invalid argument";
    case FM_ENOMEM: return "out of memory";
    case FM_EFORMAT: return "malformed instruction stream";
    case FM_ELIMIT: return "more lines than rows";
    }
    return "unknown status";
}

fm_status fm_line_new(int width, int carry_bug, fm_line **out)
{
    if (!out || width < 1 || width > FM_MAX_WIDTH) return FM_EINVAL;
    fm_line *l = calloc(1, sizeof *l);
    if (!l) return FM_ENOMEM;
    l->w = width;
    l->lo = width;
    l->bug = carry_bug != 0;
    l->reg = calloc(4 * (size_t)width, sizeof *l->reg);
    l->flag = calloc(5 * (size_t)width, 1);
    if (!l->reg || !l->flag) {
        fm_line_free(l);
        return FM_ENOMEM;
    }
    *out = l;
    return FM_OK;
}

void fm_line_free(fm_line *l)
{
    if (!l) return;
    free(l->reg);
    free(l->flag);
    free(l);
}

/* Only the columns touched since the last reset ([lo, hi)) need clearing. */
void fm_line_reset(fm_line *l)
{
    if (!l) return;
    if (l->hi > l->lo) {
        size_t n = (size_t)(l->hi - l->lo);
        for (int k = 0; k < 4; k++) memset(l->reg + (size_t)k * l->w + l->lo, 0, n * sizeof *l->reg);
        if (l->any_prot || l->any_gate)
            for (int k = 0; k < 5; k++) memset(l->flag + (size_t)k * l->w + l->lo, 0, n);
    }
    l->lo = l->w;
    l->hi = 0;
    l->any_prot = l->any_gate = 0;
    l->acc_mode = 0;
}

static void touch(fm_line *l, int a, int e)
{
    if (a < l->lo) l->lo = a;
    if (e > l->hi) l->hi = e;
}

static inline uint64_t add(const fm_line *l, uint64_t x, uint64_t y)
{
    return l->bug ? de_add_word(x, y, 1) : x + y;
}

/* End of every Eval in its active PEs: protect and dis flags drop. */
static void end_of_eval(fm_line *l, int a, int e)
{
    size_t n = (size_t)(e - a);
    if (l->any_prot) {
        memset(l->flag + (size_t)FM_FLAG_PA * l->w + a, 0, n);
        memset(l->flag + (size_t)FM_FLAG_PB * l->w + a, 0, n);
        memset(l->flag + (size_t)FM_FLAG_PC * l->w + a, 0, n);
    }
    if (l->any_gate) memset(l->flag + (size_t)FM_FLAG_DIS * l->w + a, 0, n);
}

/* Order <= 2 without flags, Acc_mode or carry bug: the common case, one tight loop. */
static void eval_quiet(fm_line *l, int a, int e, int p, const uint64_t *v)
{
    uint64_t *A = l->reg, *B = A + l->w, *C = B + l->w, *D = C + l->w;
    uint64_t v0 = v[0], v1 = p >= 1 ? v[1] : 0, v2 = p >= 2 ? v[2] : 0;
    if (p == 0) {
        for (int c = a; c < e; c++) { A[c] = v0; D[c] += v0; }
    } else if (p == 1) {
        for (int c = a; c < e; c++) { A[c] = v0; B[c] = v1; D[c] += v0; v0 += v1; }
    } else {
        for (int c = a; c < e; c++) {
            A[c] = v0; B[c] = v1; C[c] = v2; D[c] += v0;
            v0 += v1; v1 += v2;
        }
    }
}

/* Order 2 with protect flags raised in the line, no Dis/Eval0, Acc_mode or carry bug (the
 * common case of real frames: a SetddI per curvature change): eval_general for p = 2,
 * unrolled. */
static void eval_prot2(fm_line *l, int a, int e, const uint64_t *v)
{
    const size_t w = (size_t)l->w;
    uint64_t *A = l->reg, *B = A + w, *C = B + w, *D = C + w;
    const uint8_t *pa = l->flag, *pb = pa + w, *pc = pb + w;
    uint64_t v0 = v[0], v1 = v[1], v2 = v[2];
    for (int c = a; c < e; c++) {
        if (pa[c] | pb[c] | pc[c]) {
            if (pa[c]) v0 = A[c] & DE_WORD_MASK;
            if (pb[c]) v1 = B[c] & DE_WORD_MASK;
            if (pc[c]) v2 = C[c] & DE_WORD_MASK;
        }
        A[c] = v0; B[c] = v1; C[c] = v2; D[c] += v0;
        v0 += v1; v1 += v2;
    }
}

/* Any order, flags, Acc_mode, carry bug: column by column, as `_eval_columns`. */
static void eval_general(fm_line *l, int a, int e, int p, const uint64_t *vin)
{
    const size_t w = (size_t)l->w;
    uint64_t *D = l->reg + 3 * w;
    const uint8_t *lock = l->flag + FM_FLAG_LOCK * w, *dis = l->flag + FM_FLAG_DIS * w;
    /* difference level -> register whose protect flag it honours, and the register that
     * holds each level afterwards (docs/isa.md §6: A is scratch for p >= 3) */
    int plev[3], preg[3], np = 0, wlev[3], wreg[3], nw = 0;
    if (p <= 2) {
        for (int j = 0; j <= p; j++) {
            plev[np] = j; preg[np++] = j;
            wlev[nw] = j; wreg[nw++] = j;
        }
    } else {
        plev[0] = p - 1; preg[0] = 1; plev[1] = p; preg[1] = 2; np = 2;
        wlev[0] = 0; wreg[0] = 0; wlev[1] = p - 1; wreg[1] = 1; wlev[2] = p; wreg[2] = 2; nw = 3;
    }
    uint64_t v[FM_MAX_VALUES];
    memcpy(v, vin, (size_t)(p + 1) * sizeof *v);
    const int gate = l->any_gate, acc = l->acc_mode, prot = l->any_prot;
    const uint64_t sign = UINT64_C(1) << (DE_WORD_BITS - 1);
    for (int c = a; c < e; c++) {
        if (prot)
            for (int k = 0; k < np; k++)
                if (l->flag[(size_t)preg[k] * w + c])
                    v[plev[k]] = l->reg[(size_t)preg[k] * w + c] & DE_WORD_MASK;
        for (int k = 0; k < nw; k++) l->reg[(size_t)wreg[k] * w + c] = v[wlev[k]];
        if (!(gate && (lock[c] || dis[c])) && !(acc && (v[0] & sign)))
            D[c] = add(l, D[c], v[0]);
        for (int j = 0; j < p; j++) v[j] = add(l, v[j], v[j + 1]);
    }
}

static int clip(const fm_line *l, int x) { return x < l->w ? x : l->w; }

static fm_status check(const fm_cmd *c)
{
    if (c->x < 0 || c->x > DE_ADDR_MAX || c->dx < 0 || c->dx > DE_ADDR_MAX) return FM_EINVAL;
    switch (c->op) {
    case FM_NOP:
        return FM_OK;
    case FM_EVAL:
        return c->nvals >= 1 && c->nvals <= FM_MAX_VALUES ? FM_OK : FM_EINVAL;
    case FM_EVAL0:
        return c->nvals == 1 && c->v[0] >= 0 && c->v[0] <= (int64_t)DE_BLOCK_MASK ? FM_OK : FM_EINVAL;
    case FM_ACCMODE:
        return c->nvals == 1 && (c->v[0] == 0 || c->v[0] == 1) ? FM_OK : FM_EINVAL;
    case FM_SETI: case FM_SETDI: case FM_SETDDI: case FM_SETPI: case FM_SETPDI: case FM_SETPDDI:
        return c->nvals == 1 ? FM_OK : FM_EINVAL;
    case FM_DIS:
        return FM_OK;
    default:            /* FM_REFRESH ends a line: the caller's job (fm_render) */
        return FM_EINVAL;
    }
}

fm_status fm_line_exec(fm_line *l, const fm_cmd *c)
{
    if (!l || !c) return FM_EINVAL;
    fm_status st = check(c);
    if (st != FM_OK) return st;
    const size_t w = (size_t)l->w;
    const int a = clip(l, c->x), e = clip(l, c->x + c->dx);
    switch (c->op) {
    case FM_EVAL: {
        if (e <= a) return FM_OK;
        int p = c->nvals - 1;
        uint64_t v[FM_MAX_VALUES];
        for (int j = 0; j <= p; j++) v[j] = (uint64_t)c->v[j] & DE_WORD_MASK;
        touch(l, a, e);
        const int plain = !l->any_gate && !l->acc_mode && !l->bug;
        if (p <= 2 && plain && !l->any_prot)
            eval_quiet(l, a, e, p, v);
        else if (p == 2 && plain)
            eval_prot2(l, a, e, v);
        else
            eval_general(l, a, e, p, v);
        end_of_eval(l, a, e);
        return FM_OK;
    }
    case FM_EVAL0: {
        if (e <= a) return FM_OK;
        uint64_t *D = l->reg + 3 * w;
        uint8_t *lock = l->flag + FM_FLAG_LOCK * w;
        const uint8_t *dis = l->flag + FM_FLAG_DIS * w;
        const uint64_t val = (uint64_t)c->v[0] << DE_FRAC_BITS;
        touch(l, a, e);
        for (int col = a; col < e; col++)
            if (!lock[col] && !dis[col]) { D[col] = val; lock[col] = 1; }
        l->any_gate = 1;
        end_of_eval(l, a, e);
        return FM_OK;
    }
    case FM_SETI: case FM_SETDI: case FM_SETDDI:
    case FM_SETPI: case FM_SETPDI: case FM_SETPDDI: {
        int r = (c->op - FM_SETI) % 3;      /* A, B, C */
        int periodic = c->op >= FM_SETPI;
        int step = periodic ? (c->dx ? c->dx : 4096) : 1;   /* countdown reloads dX-1 mod 4096 */
        int end = periodic ? l->w : e;
        if (a >= end) return FM_OK;
        uint64_t val = (uint64_t)c->v[0] & DE_WORD_MASK;
        uint64_t *reg = l->reg + (size_t)r * w;
        uint8_t *pf = l->flag + (size_t)r * w;
        touch(l, a, end);
        for (int col = a; col < end; col += step) { reg[col] = val; pf[col] = 1; }
        l->any_prot = 1;
        return FM_OK;
    }
    case FM_DIS:
        if (e > a) {
            touch(l, a, e);
            memset(l->flag + FM_FLAG_DIS * w + a, 1, (size_t)(e - a));
            l->any_gate = 1;
        }
        return FM_OK;
    case FM_ACCMODE:
        l->acc_mode = c->v[0] != 0;
        return FM_OK;
    default:
        return FM_OK;   /* FM_NOP */
    }
}

void fm_line_state(const fm_line *l, uint64_t *regs, uint8_t *flags, int *acc_mode)
{
    if (!l) return;
    const size_t n = 4 * (size_t)l->w;
    if (regs)
        for (size_t i = 0; i < n; i++) regs[i] = l->reg[i] & DE_WORD_MASK;
    if (flags) memcpy(flags, l->flag, 5 * (size_t)l->w);
    if (acc_mode) *acc_mode = l->acc_mode;
}

void fm_line_pixels(const fm_line *l, uint16_t *px)
{
    if (!l || !px) return;
    fm_line_row(l, px, 1);
}

void fm_line_row(const fm_line *l, uint16_t *px, ptrdiff_t stride)
{
    const uint64_t *D = l->reg + 3 * (size_t)l->w;
    for (int c = 0; c < l->w; c++)
        px[c * stride] = (uint16_t)((D[c] >> DE_FRAC_BITS) & DE_BLOCK_MASK);
}
