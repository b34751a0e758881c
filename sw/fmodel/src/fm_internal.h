/* fm_internal.h - what the sources of sw/fmodel share (not public). */
#ifndef FM_INTERNAL_H
#define FM_INTERNAL_H
#include "fmodel.h"

struct fm_line {
    int w, bug;
    uint64_t *reg;      /* A, B, C, D: 4 x w, kept modulo 2^64 (masked on reading) */
    uint8_t *flag;      /* pA, pB, pC, dis, lock: 5 x w */
    int lo, hi;         /* columns touched since the last reset: [lo, hi) */
    int any_prot;       /* a Set has run in this line: Evals must look at protect flags */
    int any_gate;       /* a Dis/Eval0 has run: an ACC may be suppressed */
    int acc_mode;
};

/* D's pixels into px[c * stride], c = 0..w-1. */
void fm_line_row(const fm_line *l, uint16_t *px, ptrdiff_t stride);
#endif
