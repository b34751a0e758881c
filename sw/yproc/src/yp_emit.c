/* yp_emit.c - command lists, their serialisation (Table 7.2 as in
 * docs/isa.md section 2/3, byte for byte what diffengine's isa.serialise
 * produces), the .cmd text form, and a small x-processor model of the
 * commands yp emits (used for the expected frame and the tests). */
#define _POSIX_C_SOURCE 200809L   /* flockfile, putc_unlocked */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "yp_internal.h"
#include "de_isa.h"

#define M36 DE_WORD_MASK
/* The expected frame is the correct adder's (the product); the prototype's carry fault
 * is reproduced by the RTL's CarryBug=1 and the golden model, through the same
 * de_add_word generated from spec/isa.toml. */
#define YP_CARRY_BUG 0

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

/* ---- x-processor model (docs/isa.md section 6), per line ------------- */
void yp_simulate_line(const yp_cmdlist *l, int width, uint16_t *pix)
{
    uint64_t *D = calloc((size_t)width, sizeof(uint64_t)), *R = calloc(3 * (size_t)width, sizeof(uint64_t));
    unsigned char *fl = calloc((size_t)width, 1);   /* bit 0..2 protect A,B,C; 3 dis; 4 lock */
    if (!D || !R || !fl) { free(D); free(R); free(fl); memset(pix, 0, sizeof(uint16_t) * (size_t)width); return; }
    int accm = 0;
    for (int i = 0; i < l->n; i++) {
        const yp_cmd *c = &l->c[i];
        int a = c->x, e = c->x + c->dx;
        if (e > width) e = width;
        switch (c->op) {
        case YP_ACCMODE: accm = (int)c->v[0]; break;
        case YP_DIS: for (int p = a; p < e; p++) fl[p] |= 8; break;
        case YP_SETI: case YP_SETDI: case YP_SETDDI: {
            int r = c->op - YP_SETI;
            for (int p = a; p < e; p++) { R[3 * p + r] = (uint64_t)c->v[0]; fl[p] |= (unsigned char)(1 << r); }
            break;
        }
        case YP_EVAL0:
            for (int p = a; p < e; p++) {
                if (!(fl[p] & 0x18)) { D[p] = (uint64_t)c->v[0] << DE_FRAC_BITS; fl[p] |= 16; }
                fl[p] &= (unsigned char)~0x0f;
            }
            break;
        case YP_EVAL: {
            /* incoming values highest order first: in[0] = I, in[1] = dI, in[2] = ddI */
            uint64_t in[3] = {(uint64_t)c->v[0], (uint64_t)c->v[1], (uint64_t)c->v[2]};
            int ord = c->order;
            for (int p = a; p < e; p++) {
                uint64_t v[3];
                for (int r = ord; r >= 0; r--) v[r] = (fl[p] & (1 << r)) ? R[3 * p + r] : in[r];
                for (int r = 0; r <= ord; r++) R[3 * p + r] = v[r];
                uint64_t A = v[0] & M36;
                int neg = (int)((A >> (DE_WORD_BITS - 1)) & 1);
                if (!(fl[p] & 0x18) && !(accm && neg)) D[p] = de_add_word(D[p], A, YP_CARRY_BUG);
                fl[p] &= (unsigned char)~0x0f;
                for (int r = 0; r < ord; r++) in[r] = de_add_word(v[r], v[r + 1], YP_CARRY_BUG);
                in[ord] = v[ord];
            }
            break;
        }
        default: break;
        }
    }
    for (int p = 0; p < width; p++) pix[p] = (uint16_t)(((D[p] & M36) >> DE_FRAC_BITS) & DE_BLOCK_MASK);
    free(D); free(R); free(fl);
}

/* ---- serialisation -------------------------------------------------- */
static void put48(FILE *f, unsigned ident, uint64_t data)
{
    uint64_t w = ((uint64_t)(ident & DE_ID_MASK) << DE_WORD_BITS) | (data & M36);
    /* the caller holds f's lock (flockfile): a byte at a time without one fwrite
     * (and its lock) per 6-byte word, which cost the viewer ~5 ms a frame */
    for (int i = 0; i < DE_RECORD_BITS / 8; i++) putc_unlocked((int)(unsigned char)(w >> (DE_RECORD_BITS - 8 - 8 * i)), f);
}

static void put_cmd(FILE *f, const yp_cmd *c)
{
    uint64_t rng = (uint64_t)(c->x & DE_BLOCK_MASK) | ((uint64_t)(c->dx & DE_BLOCK_MASK) << DE_BLOCK_BITS);
    switch (c->op) {
    case YP_REFRESH: put48(f, DE_ID_REFRESH, 0); break;
    case YP_ACCMODE: put48(f, c->v[0] ? DE_ID_ACCMODE_ON : DE_ID_ACCMODE_OFF, 0); break;
    case YP_DIS: put48(f, DE_ID_ADDR_DIS, rng); break;
    case YP_EVAL0: put48(f, DE_ID_ADDR_EVAL0, rng | ((uint64_t)(c->v[0] & DE_BLOCK_MASK) << (2 * DE_BLOCK_BITS))); break;
    case YP_SETI: case YP_SETDI: case YP_SETDDI: {
        static const unsigned set_id[3] = {DE_ID_SET_A, DE_ID_SET_B, DE_ID_SET_C};
        put48(f, DE_ID_ADDR_RANGE, rng); put48(f, set_id[c->op - YP_SETI], (uint64_t)c->v[0]);
        break;
    }
    case YP_EVAL: {
        put48(f, DE_ID_ADDR_RANGE, rng);
        if (c->order == 0) put48(f, DE_ID_D_A, (uint64_t)c->v[0]);
        else if (c->order == 1) { put48(f, DE_ID_D_B, (uint64_t)c->v[1]); put48(f, DE_ID_D_A_B, (uint64_t)c->v[0]); }
        else { put48(f, DE_ID_D_C, (uint64_t)c->v[2]); put48(f, DE_ID_D_B_C, (uint64_t)c->v[1]); put48(f, DE_ID_D_A_B, (uint64_t)c->v[0]); }
        put48(f, DE_ID_ACC, 0);
        break;
    }
    default: break;
    }
}

hsr_status yp_write_de48(const yp_frame *fr, int colour, const char *path)
{
    FILE *f = fopen(path, "wb");
    if (!f) return HSR_EIO;
    static const unsigned char hdr[8] = {'D', 'E', '4', '8', 0, 1, 0, 0};
    fwrite(hdr, 1, 8, f);
    const yp_cmd refresh = {YP_REFRESH, 0, 0, 0, {0, 0, 0}};
    flockfile(f);
    for (int y = 0; y < fr->height; y++) {
        const yp_cmdlist *l = &fr->line[colour * fr->height + y];
        for (int i = 0; i < l->n; i++) put_cmd(f, &l->c[i]);
        put_cmd(f, &refresh);
    }
    funlockfile(f);
    return fclose(f) == 0 ? HSR_OK : HSR_EIO;
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
