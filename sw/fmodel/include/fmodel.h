/* fmodel.h - the functional model of the x-processor array in C: what every PE computes
 * for a command stream (docs/isa.md §5-§7), a command at a time, column by column, and
 * fast enough for an interactive view (a 640x480 colour frame in milliseconds). The one
 * public header of sw/fmodel.
 *
 * It is a port of the numpy golden model (sw/diffengine/model/functional.py, `_Line`),
 * which stays the readable reference: sw/tests/test_fmodel.py runs both on every command
 * and compares every register and flag of every PE after each one, and compares whole
 * frames (random streams with printed seeds, the shipped scenes). The carry-bug adder of
 * §7.7 is supported (de_add_word of de_isa.h).
 *
 * Arithmetic: registers are 36-bit words. Without the carry bug they are kept modulo 2^64
 * (2^36 divides 2^64, so every sum is exact modulo 2^36) and masked where they are read;
 * with it every add goes through the faulty adder.
 *
 * Input streams are .de48 instruction words (6 bytes, big-endian: identifier in bits
 * 47..36, data in 35..0; the body of a .de48 file, without its 8-byte header), decoded to
 * commands exactly as diffengine.formats.binfmt.deserialise does, with the same refusals
 * (the error names the slot). Status codes, never aborts; no global state; thread-safe
 * for distinct fm_line objects and images. */
#ifndef FMODEL_H
#define FMODEL_H

#include <stddef.h>
#include <stdint.h>

typedef enum fm_status {
    FM_OK = 0,
    FM_EINVAL,      /* NULL pointer, bad width, bad operand, Refresh given to fm_line_exec */
    FM_ENOMEM,      /* allocation failed */
    FM_EFORMAT,     /* malformed instruction stream (fm_error says at which slot) */
    FM_ELIMIT       /* more lines in a stream than rows given for them */
} fm_status;

const char *fm_status_str(fm_status s);

#define FM_MAX_WIDTH 4104       /* columns of a line (4096 + 8, as the numpy model) */
#define FM_MAX_VALUES 8         /* an Eval of order 7 has 8 values */

/* The commands of Table 7.1. */
typedef enum fm_op {
    FM_NOP = 0, FM_REFRESH, FM_EVAL0, FM_EVAL, FM_SETI, FM_SETDI, FM_SETDDI,
    FM_SETPI, FM_SETPDI, FM_SETPDDI, FM_DIS, FM_ACCMODE
} fm_op;

/* One command. x, dx in 0..4095. v: for FM_EVAL (I, dI, ..., d^pI), nvals = p + 1 in
 * 1..8, taken modulo 2^36 (signed 12.24 or 36-bit patterns alike); Set*: v[0]; FM_EVAL0:
 * v[0] the 12-bit intensity 0..4095; FM_ACCMODE: v[0] 0 or 1. */
typedef struct fm_cmd {
    int32_t op, x, dx, nvals;
    int64_t v[FM_MAX_VALUES];
} fm_cmd;

/* Where a stream was refused: the instruction slot (0 = first word) and why. */
typedef struct fm_error {
    int64_t slot;
    char msg[160];
} fm_error;

/* ---- one line: the state of every PE ------------------------------------ */
typedef struct fm_line fm_line;

/* A line of `width` columns (1..FM_MAX_WIDTH), reset; carry_bug selects the §7.7 adder. */
fm_status fm_line_new(int width, int carry_bug, fm_line **out);
void fm_line_free(fm_line *l);
void fm_line_reset(fm_line *l);     /* what a Refresh leaves: every register and flag 0 */
/* Execute one command on every PE (FM_EINVAL for a Refresh or a bad operand; the line is
 * unchanged then). */
fm_status fm_line_exec(fm_line *l, const fm_cmd *c);
/* The state of every PE: regs[k * width + col] for k = A, B, C, D (36-bit words),
 * flags[k * width + col] for k = pA, pB, pC, dis, lock (0/1); *acc_mode. Any output may
 * be NULL. */
enum { FM_REG_A, FM_REG_B, FM_REG_C, FM_REG_D };
enum { FM_FLAG_PA, FM_FLAG_PB, FM_FLAG_PC, FM_FLAG_DIS, FM_FLAG_LOCK };
void fm_line_state(const fm_line *l, uint64_t *regs, uint8_t *flags, int *acc_mode);
/* The pixels a Refresh would output: (D >> 24) & 0xfff of each column. */
void fm_line_pixels(const fm_line *l, uint16_t *px);

/* ---- instruction streams -------------------------------------------------- */
/* Decode the command that starts at slot *pos of `words` (nwords 6-byte words) and advance
 * *pos past it. FM_EFORMAT with err->slot set on a malformed stream. */
fm_status fm_decode(const uint8_t *words, size_t nwords, size_t *pos, fm_cmd *c,
                    fm_error *err);

/* Render a stream of lines (each closed by its Refresh) into an image of uint16 pixels:
 * line k goes to row rows[k] (row k when rows is NULL), pixel (row, col) at
 * img[row * row_stride + col * col_stride], cols 0..width-1. nrows is how many rows the
 * stream may fill (FM_ELIMIT when it holds more lines). The whole stream is decoded and
 * checked before the first pixel is written, so a refused stream leaves img unchanged.
 * *lines (may be NULL): lines rendered; *trailing (may be NULL): commands after the last
 * Refresh, which form no line and are not shown. */
fm_status fm_render(const uint8_t *words, size_t nwords, int width, int carry_bug,
                    uint16_t *img, ptrdiff_t row_stride, ptrdiff_t col_stride,
                    const int32_t *rows, size_t nrows, size_t *lines, size_t *trailing,
                    fm_error *err);

/* One colour's stream for fm_render_rgb: words/nwords, and rows/nrows as for fm_render. */
typedef struct fm_stream {
    const uint8_t *words;
    size_t nwords;
    const int32_t *rows;
    size_t nrows;
} fm_stream;

/* The three colours r, g, b into an interleaved image img[(row * width + col) * 3 + c]
 * of `height` rows: a whole frame (rows NULL, nrows = height) or the changed lines of an
 * incremental frame (rows = their row numbers). Every stream is checked before any pixel
 * is written; err->msg names the colour. */
fm_status fm_render_rgb(const fm_stream s[3], int width, int height, int carry_bug,
                        uint16_t *img, fm_error *err);

#endif
