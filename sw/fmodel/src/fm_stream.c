/* fm_stream.c - .de48 instruction words to commands (the inverse of isa.serialise, with
 * the refusals of diffengine.formats.binfmt.deserialise, slot for slot) and whole streams
 * of lines rendered into images. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "fm_internal.h"
#include "de_isa.h"

static void word(const uint8_t *p, unsigned *ident, uint64_t *data)
{
    uint64_t w = 0;
    for (int k = 0; k < 6; k++) w = (w << 8) | p[k];
    *ident = (unsigned)(w >> DE_WORD_BITS);
    *data = w & DE_WORD_MASK;
}

static const char *id_name(unsigned ident, char *buf, size_t n)
{
    for (unsigned k = 0; k < DE_LUT_ENTRIES; k++)
        if (de_lut_ident(k) == ident) return de_lut_name(k);
    snprintf(buf, n, "%#05x", ident);
    return buf;
}

static int is_intensity(unsigned ident)
{
    switch (ident) {
    case DE_ID_D_A: case DE_ID_D_B: case DE_ID_D_C: case DE_ID_D_B_C: case DE_ID_D_A_B:
    case DE_ID_D_A_B_NP: case DE_ID_D_A_A_NP: case DE_ID_SET_A: case DE_ID_SET_B:
    case DE_ID_SET_C:
        return 1;
    }
    return 0;
}

static int is_known(unsigned ident)
{
    switch (ident) {
    case DE_ID_NOP: case DE_ID_REFRESH: case DE_ID_ACCMODE_ON: case DE_ID_ACCMODE_OFF:
    case DE_ID_ADDR_RANGE: case DE_ID_ADDR_PERIODIC: case DE_ID_ADDR_EVAL0: case DE_ID_ADDR_DIS:
    case DE_ID_ACC:
        return 1;
    }
    return is_intensity(ident);
}

/* The data slots of an order-p Eval, highest difference first (isa.eval_data_ids). */
static unsigned eval_id(int p, int k)
{
    if (p == 0) return DE_ID_D_A;
    if (p == 1) return k == 0 ? DE_ID_D_B : DE_ID_D_A_B;
    if (p == 2) return k == 0 ? DE_ID_D_C : k == 1 ? DE_ID_D_B_C : DE_ID_D_A_B;
    return k == 0 ? DE_ID_D_C : k == 1 ? DE_ID_D_B_C : k == 2 ? DE_ID_D_A_B_NP : DE_ID_D_A_A_NP;
}

static fm_status fail(fm_error *err, size_t slot, const char *msg)
{
    if (err) {
        err->slot = (int64_t)slot;
        snprintf(err->msg, sizeof err->msg, "slot %zu: %s", slot, msg);
    }
    return FM_EFORMAT;
}

fm_status fm_decode(const uint8_t *words, size_t n, size_t *pos, fm_cmd *c, fm_error *err)
{
    if (!words || !pos || !c || *pos >= n) return FM_EINVAL;
    size_t i = *pos;
    unsigned ident, nid;
    uint64_t data, nd;
    char msg[128], b1[16], b2[16];
    word(words + 6 * i, &ident, &data);
    memset(c, 0, sizeof *c);
    if (!is_known(ident)) {
        snprintf(msg, sizeof msg, "unknown identifier %#05x", ident);
        return fail(err, i, msg);
    }
    const int64_t bl0 = (int64_t)(data & DE_BLOCK_MASK), bl1 = (int64_t)((data >> 12) & DE_BLOCK_MASK);
    const int64_t bl2 = (int64_t)(data >> 24);
    switch (ident) {
    case DE_ID_NOP: case DE_ID_REFRESH: case DE_ID_ACCMODE_ON: case DE_ID_ACCMODE_OFF:
        if (data) {
            snprintf(msg, sizeof msg, "%s carries nonzero data", id_name(ident, b1, sizeof b1));
            return fail(err, i, msg);
        }
        c->op = ident == DE_ID_NOP ? FM_NOP : ident == DE_ID_REFRESH ? FM_REFRESH : FM_ACCMODE;
        if (c->op == FM_ACCMODE) { c->nvals = 1; c->v[0] = ident == DE_ID_ACCMODE_ON; }
        *pos = i + 1;
        return FM_OK;
    case DE_ID_ADDR_EVAL0:
        c->op = FM_EVAL0; c->x = (int32_t)bl0; c->dx = (int32_t)bl1; c->nvals = 1; c->v[0] = bl2;
        *pos = i + 1;
        return FM_OK;
    case DE_ID_ADDR_DIS:
        if (bl2) return fail(err, i, "ADDR_DIS carries a nonzero block 2");
        c->op = FM_DIS; c->x = (int32_t)bl0; c->dx = (int32_t)bl1;
        *pos = i + 1;
        return FM_OK;
    case DE_ID_ADDR_RANGE: case DE_ID_ADDR_PERIODIC: {
        const int periodic = ident == DE_ID_ADDR_PERIODIC;
        if (bl2) {
            snprintf(msg, sizeof msg, "%s carries a nonzero block 2", id_name(ident, b1, sizeof b1));
            return fail(err, i, msg);
        }
        c->x = (int32_t)(periodic ? bl1 : bl0);
        c->dx = (int32_t)(periodic ? bl0 : bl1);
        if (i + 1 >= n) {
            snprintf(msg, sizeof msg, "%s at the end of the stream: its data slots are missing",
                     id_name(ident, b1, sizeof b1));
            return fail(err, i, msg);
        }
        word(words + 6 * (i + 1), &nid, &nd);
        if (nid == DE_ID_SET_A || nid == DE_ID_SET_B || nid == DE_ID_SET_C) {
            int r = nid == DE_ID_SET_A ? 0 : nid == DE_ID_SET_B ? 1 : 2;
            c->op = (periodic ? FM_SETPI : FM_SETI) + r;
            c->nvals = 1;
            c->v[0] = (int64_t)nd;
            *pos = i + 2;
            return FM_OK;
        }
        if (periodic) {
            snprintf(msg, sizeof msg, "%s after ADDR_PERIODIC: only SET_A/B/C may follow",
                     id_name(nid, b1, sizeof b1));
            return fail(err, i + 1, msg);
        }
        size_t j = i + 1;
        for (;;) {
            if (j >= n || j - i > DE_MAX_EVAL_ORDER + 1) break;
            word(words + 6 * j, &nid, &nd);
            if (nid == DE_ID_ACC || !is_intensity(nid)) break;
            j++;
        }
        if (j < n) word(words + 6 * j, &nid, &nd);
        if (j >= n || nid != DE_ID_ACC) {
            snprintf(msg, sizeof msg, "Eval data slots not closed by ACC (found %s)",
                     j < n ? id_name(nid, b2, sizeof b2) : "end of stream");
            return fail(err, j < n ? j : n - 1, msg);
        }
        if (nd) return fail(err, j, "ACC carries nonzero data");
        const size_t m = j - i - 1;     /* data slots */
        int ok = m >= 1 && m <= FM_MAX_VALUES;
        for (size_t k = 0; ok && k < m; k++) {
            word(words + 6 * (i + 1 + k), &nid, &nd);
            ok = nid == eval_id((int)m - 1, (int)k);
        }
        if (!ok) return fail(err, i + 1, "Eval data slots are not a Table 7.2 sequence");
        c->op = FM_EVAL;
        c->nvals = (int32_t)m;
        for (size_t k = 0; k < m; k++) {        /* highest difference first in the stream */
            word(words + 6 * (i + 1 + k), &nid, &nd);
            c->v[m - 1 - k] = (int64_t)nd;
        }
        *pos = j + 1;
        return FM_OK;
    }
    default:
        snprintf(msg, sizeof msg, "%s without a preceding address slot", id_name(ident, b1, sizeof b1));
        return fail(err, i, msg);
    }
}

/* Pass 1: decode everything, count lines and trailing commands. */
static fm_status scan(const uint8_t *words, size_t n, size_t *lines, size_t *trailing, fm_error *err)
{
    size_t pos = 0, nl = 0, tr = 0;
    fm_cmd c;
    while (pos < n) {
        fm_status st = fm_decode(words, n, &pos, &c, err);
        if (st != FM_OK) return st;
        if (c.op == FM_REFRESH) { nl++; tr = 0; }
        else tr++;
    }
    *lines = nl;
    *trailing = tr;
    return FM_OK;
}

fm_status fm_render(const uint8_t *words, size_t nwords, int width, int carry_bug,
                    uint16_t *img, ptrdiff_t row_stride, ptrdiff_t col_stride,
                    const int32_t *rows, size_t nrows, size_t *lines, size_t *trailing,
                    fm_error *err)
{
    if (err) { err->slot = -1; err->msg[0] = 0; }
    if ((!words && nwords) || !img || width < 1 || width > FM_MAX_WIDTH) return FM_EINVAL;
    size_t nl = 0, tr = 0;
    fm_status st = nwords ? scan(words, nwords, &nl, &tr, err) : FM_OK;
    if (st != FM_OK) return st;
    if (nl > nrows) {
        if (err) snprintf(err->msg, sizeof err->msg, "%zu lines, only %zu rows for them", nl, nrows);
        return FM_ELIMIT;
    }
    if (rows)
        for (size_t k = 0; k < nl; k++)
            if (rows[k] < 0) {
                if (err) snprintf(err->msg, sizeof err->msg, "row %d of line %zu is negative", rows[k], k);
                return FM_EINVAL;
            }
    fm_line *l = NULL;
    if ((st = fm_line_new(width, carry_bug, &l)) != FM_OK) return st;
    size_t pos = 0, k = 0;
    fm_cmd c;
    while (k < nl) {        /* pass 2: the stream is known good */
        fm_decode(words, nwords, &pos, &c, NULL);
        if (c.op == FM_REFRESH) {
            ptrdiff_t row = rows ? rows[k] : (ptrdiff_t)k;
            fm_line_row(l, img + row * row_stride, col_stride);
            fm_line_reset(l);
            k++;
        } else {
            fm_line_exec(l, &c);    /* decoded operands are in range: cannot fail */
        }
    }
    fm_line_free(l);
    if (lines) *lines = nl;
    if (trailing) *trailing = tr;
    return FM_OK;
}

fm_status fm_render_rgb(const fm_stream s[3], int width, int height, int carry_bug,
                        uint16_t *img, fm_error *err)
{
    static const char *name[3] = {"r", "g", "b"};
    if (err) { err->slot = -1; err->msg[0] = 0; }
    if (!s || !img || height < 0) return FM_EINVAL;
    for (int ch = 0; ch < 3; ch++) {    /* check all three before writing a pixel */
        size_t nl = 0, tr = 0;
        fm_status st = FM_OK;
        if (!s[ch].words && s[ch].nwords) st = FM_EINVAL;
        else if (s[ch].nwords) st = scan(s[ch].words, s[ch].nwords, &nl, &tr, err);
        if (st == FM_OK && nl > (s[ch].rows ? s[ch].nrows : (size_t)height)) st = FM_ELIMIT;
        for (size_t k = 0; st == FM_OK && s[ch].rows && k < nl; k++)
            if (s[ch].rows[k] < 0 || s[ch].rows[k] >= height) st = FM_EINVAL;
        if (st != FM_OK) {
            if (err) {
                char m[sizeof err->msg];
                snprintf(m, sizeof m, "%s", err->msg[0] ? err->msg
                         : st == FM_ELIMIT ? "more lines than rows" : "bad stream or row");
                snprintf(err->msg, sizeof err->msg, "colour %s: %.140s", name[ch], m);
            }
            return st;
        }
    }
    for (int ch = 0; ch < 3; ch++) {
        fm_status st = fm_render(s[ch].words, s[ch].nwords, width, carry_bug, img + ch,
                                 (ptrdiff_t)width * 3, 3, s[ch].rows,
                                 s[ch].rows ? s[ch].nrows : (size_t)height, NULL, NULL, err);
        if (st != FM_OK) return st;
    }
    return FM_OK;
}
