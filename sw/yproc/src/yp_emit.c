/* yp_emit.c - command lists, their serialisation (Table 7.2 as in
 * docs/isa.md section 2/3, byte for byte what diffengine's isa.serialise
 * produces), the .cmd text form, and the pixels a line's commands give
 * (yp_simulate_line: the serialised words through sw/fmodel, the functional
 * model of the array; yproc keeps no model of the x-processor of its own). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"
#include "de_isa.h"
#include "fmodel.h"

#define M36 DE_WORD_MASK
/* The expected frame is the correct adder's (the product); the prototype's carry fault
 * is reproduced by the RTL's CarryBug=1, the golden model and sw/fmodel (its carry_bug
 * argument), through the same de_add_word generated from spec/isa.toml. */
#define YP_CARRY_BUG 0
/* bytes of one instruction word (a .de48 slot) */
#define YP_WORD_BYTES (DE_RECORD_BITS / 8)
/* the most slots one command takes: an Eval of order 2 (address, 3 values, ACC) */
#define YP_MAX_CMD_SLOTS 5

int yp_cmd_slots(const yp_cmd *c)
{
    switch (c->op) {
    case YP_EVAL: return c->order + 3;
    case YP_SETI: case YP_SETDI: case YP_SETDDI: return 2;
    default: return 1;
    }
}

hsr_status yp_cmdlist_push(yp_cmdlist *l, yp_cmd c)
{
    if (l->n == l->cap) {
        int nc = l->cap ? 2 * l->cap : 16;
        yp_cmd *p = realloc(l->c, sizeof(yp_cmd) * (size_t)nc);
        if (!p) return HSR_ENOMEM;
        l->c = p; l->cap = nc;
    }
    l->c[l->n++] = c;
    l->slots += yp_cmd_slots(&c);
    return HSR_OK;
}

void yp_cmdlist_free(yp_cmdlist *l)
{
    free(l->c);
    l->c = NULL; l->n = l->cap = l->slots = 0;
}

void yp_options_default(yp_options *o)
{
    memset(o, 0, sizeof *o);   /* line_lod NULL, no_degrade 0 */
    o->capacity = 798; o->aa = 1; o->shading = YP_PHONG; o->tol = 1.0;
}

int yp_mode_capacity(const char *mode, int *width, int *height)
{
    for (int i = 0; i < DE_VIDEO_MODES; i++) {
        const de_video_mode *m = de_video_mode_get(i);
        if (!strcmp(mode, m->name)) {
            if (width) *width = m->h[0];
            if (height) *height = m->v[0];
            /* HTotal - 2: the window has HTotal - 1 slots, and the end-of-line
             * marker must reach the buffer's head inside it (docs/pipeline.md 1.1) */
            return de_video_htotal(m) - 2;
        }
    }
    return 0;
}

hsr_status yp_frame_new(int width, int height, yp_frame **out)
{
    if (!out || width < 1 || height < 1 || width > 4096) return HSR_EINVAL;
    yp_frame *f = calloc(1, sizeof *f);
    if (!f) return HSR_ENOMEM;
    f->width = width; f->height = height;
    f->line = calloc(3 * (size_t)height, sizeof(yp_cmdlist));
    f->st = calloc((size_t)height, sizeof(yp_line_stats));
    f->ideal = calloc(3 * (size_t)height * (size_t)width, sizeof(double));
    if (!f->line || !f->st || !f->ideal) { yp_frame_free(f); return HSR_ENOMEM; }
    *out = f;
    return HSR_OK;
}

void yp_frame_free(yp_frame *f)
{
    if (!f) return;
    if (f->line) for (int i = 0; i < 3 * f->height; i++) yp_cmdlist_free(&f->line[i]);
    free(f->line); free(f->st); free(f->ideal); free(f);
}

/* ---- serialisation -------------------------------------------------- */
/* one 48-bit instruction word at o (big-endian: identifier in bits 47..36, data in
 * 35..0); returns the end */
static uint8_t *put48(uint8_t *o, unsigned ident, uint64_t data)
{
    uint64_t w = ((uint64_t)(ident & DE_ID_MASK) << DE_WORD_BITS) | (data & M36);
    for (int i = 0; i < YP_WORD_BYTES; i++) o[i] = (uint8_t)(w >> (DE_RECORD_BITS - 8 - 8 * i));
    return o + YP_WORD_BYTES;
}

/* the words of one command (at most YP_MAX_CMD_SLOTS, yp_cmd_slots of them; none for
 * an unknown op) at o; returns the end */
static uint8_t *put_cmd(uint8_t *o, const yp_cmd *c)
{
    uint64_t rng = (uint64_t)(c->x & DE_BLOCK_MASK) | ((uint64_t)(c->dx & DE_BLOCK_MASK) << DE_BLOCK_BITS);
    switch (c->op) {
    case YP_REFRESH: return put48(o, DE_ID_REFRESH, 0);
    case YP_ACCMODE: return put48(o, c->v[0] ? DE_ID_ACCMODE_ON : DE_ID_ACCMODE_OFF, 0);
    case YP_DIS: return put48(o, DE_ID_ADDR_DIS, rng);
    case YP_EVAL0: return put48(o, DE_ID_ADDR_EVAL0, rng | ((uint64_t)(c->v[0] & DE_BLOCK_MASK) << (2 * DE_BLOCK_BITS)));
    case YP_SETI: case YP_SETDI: case YP_SETDDI: {
        static const unsigned set_id[3] = {DE_ID_SET_A, DE_ID_SET_B, DE_ID_SET_C};
        o = put48(o, DE_ID_ADDR_RANGE, rng);
        return put48(o, set_id[c->op - YP_SETI], (uint64_t)c->v[0]);
    }
    case YP_EVAL:
        o = put48(o, DE_ID_ADDR_RANGE, rng);
        if (c->order == 0) o = put48(o, DE_ID_D_A, (uint64_t)c->v[0]);
        else if (c->order == 1) { o = put48(o, DE_ID_D_B, (uint64_t)c->v[1]); o = put48(o, DE_ID_D_A_B, (uint64_t)c->v[0]); }
        else { o = put48(o, DE_ID_D_C, (uint64_t)c->v[2]); o = put48(o, DE_ID_D_B_C, (uint64_t)c->v[1]); o = put48(o, DE_ID_D_A_B, (uint64_t)c->v[0]); }
        return put48(o, DE_ID_ACC, 0);
    default: return o;
    }
}

/* The words of line l followed by its Refresh into *buf (grown as needed, *cap bytes);
 * returns the words written, 0 if out of memory. */
static size_t line_words(const yp_cmdlist *l, uint8_t **buf, size_t *cap)
{
    size_t need = ((size_t)l->n * YP_MAX_CMD_SLOTS + 1) * YP_WORD_BYTES;
    if (need > *cap) {
        uint8_t *p = realloc(*buf, need);
        if (!p) return 0;
        *buf = p; *cap = need;
    }
    uint8_t *o = *buf;
    for (int i = 0; i < l->n; i++) o = put_cmd(o, &l->c[i]);
    o = put48(o, DE_ID_REFRESH, 0);
    return (size_t)(o - *buf) / YP_WORD_BYTES;
}

/* ---- the pixels of a line: sw/fmodel ----------------------------------- */
hsr_status yp_simulate_line(const yp_cmdlist *l, int width, uint16_t *pix)
{
    if (!pix || width < 1) return HSR_EINVAL;
    hsr_status st = HSR_EINVAL;
    uint8_t *w = NULL;
    size_t cap = 0, n = 0, lines = 0;
    if (l && width <= FM_MAX_WIDTH) {
        st = HSR_ENOMEM;
        if ((n = line_words(l, &w, &cap)) > 0) {
            /* one row: the list's words and its Refresh; a Refresh inside the list would
             * make a second line (FM_ELIMIT): a list is one line */
            fm_status fs = fm_render(w, n, width, YP_CARRY_BUG, pix, 0, 1, NULL, 1, &lines, NULL, NULL);
            st = fs == FM_OK && lines == 1 ? HSR_OK : fs == FM_ENOMEM ? HSR_ENOMEM : HSR_EINVAL;
        }
    }
    free(w);
    /* what the old model did when out of memory: a black line, never stale pixels */
    if (st != HSR_OK) memset(pix, 0, sizeof(uint16_t) * (size_t)width);
    return st;
}

hsr_status yp_write_de48(const yp_frame *fr, int colour, const char *path)
{
    FILE *f = fopen(path, "wb");
    if (!f) return HSR_EIO;
    static const unsigned char hdr[8] = {'D', 'E', '4', '8', 0, 1, 0, 0};
    hsr_status st = fwrite(hdr, 1, sizeof hdr, f) == sizeof hdr ? HSR_OK : HSR_EIO;
    /* a line at a time: one fwrite per line, not a lock per word (~5 ms a frame for
     * the viewer when it was one per word) */
    uint8_t *buf = NULL;
    size_t cap = 0;
    for (int y = 0; y < fr->height && st == HSR_OK; y++) {
        size_t n = line_words(&fr->line[colour * fr->height + y], &buf, &cap);
        if (!n) st = HSR_ENOMEM;
        else if (fwrite(buf, YP_WORD_BYTES, n, f) != n) st = HSR_EIO;
    }
    free(buf);
    if (fclose(f) != 0 && st == HSR_OK) st = HSR_EIO;
    return st;
}

static void fixed(char *buf, size_t n, int64_t v)
{
    uint64_t w = (uint64_t)v & M36;
    snprintf(buf, n, "0x%03x.%06x", (unsigned)(w >> DE_FRAC_BITS), (unsigned)(w & DE_FRAC_MASK));
}

void yp_format_cmd(const yp_cmd *c, char *buf, size_t n)
{
    char a[3][24];
    switch (c->op) {
    case YP_REFRESH: snprintf(buf, n, "Refresh;"); break;
    case YP_ACCMODE: snprintf(buf, n, "Acc_mode (%d);", c->v[0] ? 1 : 0); break;
    case YP_DIS: snprintf(buf, n, "Dis (%u, %u);", c->x, c->dx); break;
    case YP_EVAL0: snprintf(buf, n, "Eval0 (%u, %u, %u);", c->x, c->dx, (unsigned)c->v[0]); break;
    case YP_SETI: case YP_SETDI: case YP_SETDDI: {
        static const char *nm[3] = {"SetI", "SetdI", "SetddI"};
        fixed(a[0], sizeof a[0], c->v[0]);
        if (c->dx == 1) snprintf(buf, n, "%s (%u, %s);", nm[c->op - YP_SETI], c->x, a[0]);
        else snprintf(buf, n, "%s (%u, %u, %s);", nm[c->op - YP_SETI], c->x, c->dx, a[0]);
        break;
    }
    case YP_EVAL:
        for (int i = 0; i <= c->order; i++) fixed(a[i], sizeof a[i], c->v[i]);
        if (c->order == 0) snprintf(buf, n, "Eval1 (%u, %u, %s);", c->x, c->dx, a[0]);
        else if (c->order == 1) snprintf(buf, n, "Eval2 (%u, %u, %s, %s);", c->x, c->dx, a[0], a[1]);
        else snprintf(buf, n, "Eval3 (%u, %u, %s, %s, %s);", c->x, c->dx, a[0], a[1], a[2]);
        break;
    default: snprintf(buf, n, "Nop;"); break;
    }
}

hsr_status yp_write_cmd(const yp_frame *fr, int colour, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) return HSR_EIO;
    fprintf(f, "# yproc: %s stream, %d lines of %d pixels (docs/yproc.md)\n", colour == 0 ? "red" : colour == 1 ? "green" : "blue",
            fr->height, fr->width);
    char buf[160];
    for (int y = 0; y < fr->height; y++) {
        const yp_cmdlist *l = &fr->line[colour * fr->height + y];
        fprintf(f, "# line %d\n", y);
        for (int i = 0; i < l->n; i++) { yp_format_cmd(&l->c[i], buf, sizeof buf); fprintf(f, "%s\n", buf); }
        fprintf(f, "Refresh;\n");
    }
    return fclose(f) == 0 ? HSR_OK : HSR_EIO;
}

static int cmd_eq(const yp_cmd *p, const yp_cmd *q)
{
    return p->op == q->op && p->order == q->order && p->x == q->x && p->dx == q->dx
           && p->v[0] == q->v[0] && p->v[1] == q->v[1] && p->v[2] == q->v[2];
}

int yp_cmdlist_changed_slots(const yp_cmdlist *a, const yp_cmdlist *b) { return yp_cmdlist_changed(a, b, NULL); }

int yp_cmdlist_changed(const yp_cmdlist *a, const yp_cmdlist *b, int *cmds)
{
    /* LCS by dynamic programming over the commands after the common head and tail
     * (a line changes in a few places; the table is small or absent) */
    int h = 0, na = a->n, nb = b->n;
    while (h < na && h < nb && cmd_eq(&a->c[h], &b->c[h])) h++;
    while (na > h && nb > h && cmd_eq(&a->c[na - 1], &b->c[nb - 1])) { na--; nb--; }
    int m = na - h, n = nb - h, changed = 0, nc = 0;
    if (cmds) *cmds = 0;
    if (m == 0 || n == 0) {
        for (int j = h; j < nb; j++) changed += yp_cmd_slots(&b->c[j]);
        if (cmds) *cmds = nb - h;
        return changed;
    }
    int *t = calloc((size_t)(m + 1) * (size_t)(n + 1), sizeof(int));
    if (!t) { for (int j = h; j < nb; j++) changed += yp_cmd_slots(&b->c[j]); if (cmds) *cmds = nb - h; return changed; }
#define T(i, j) t[(size_t)(i) * (size_t)(n + 1) + (size_t)(j)]
    for (int i = m - 1; i >= 0; i--)
        for (int j = n - 1; j >= 0; j--)
            T(i, j) = cmd_eq(&a->c[h + i], &b->c[h + j]) ? T(i + 1, j + 1) + 1
                      : T(i + 1, j) > T(i, j + 1) ? T(i + 1, j) : T(i, j + 1);
    /* walk the table: commands of b not on the common subsequence are changed */
    for (int i = 0, j = 0; j < n;) {
        if (i < m && cmd_eq(&a->c[h + i], &b->c[h + j])) { i++; j++; }
        else if (i < m && T(i + 1, j) >= T(i, j + 1)) i++;
        else { changed += yp_cmd_slots(&b->c[h + j]); nc++; j++; }
    }
#undef T
    free(t);
    if (cmds) *cmds = nc;
    return changed;
}
