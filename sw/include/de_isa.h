/* GENERATED FILE, DO NOT EDIT. Source: spec/isa.toml, spec/video.toml, spec/regs.toml.
 * Regenerate with `python -m diffengine.isa.gen` (or `make gen`); `make gen-check` diffs. */
/* de_isa.h - the x-processor instruction set for C and C++ (sw/hsr, sim/harness):
 * identifiers, field positions, the adder with its carry-bug model, the look-up
 * table, the video modes. docs/isa.md is the prose. */
#ifndef DE_ISA_H
#define DE_ISA_H

#include <stdint.h>

#define DE_ID_BITS 12
#define DE_BLOCK_BITS 12
#define DE_BLOCKS 3
#define DE_WORD_BITS 36
#define DE_FRAC_BITS 24
#define DE_ADDR_MAX 4095
#define DE_MAX_EVAL_ORDER 7
#define DE_RECORD_BITS 48
#define DE_ID_MASK ((1u << DE_ID_BITS) - 1u)
#define DE_BLOCK_MASK ((1u << DE_BLOCK_BITS) - 1u)
#define DE_WORD_MASK ((UINT64_C(1) << DE_WORD_BITS) - 1u)
#define DE_FRAC_MASK ((UINT64_C(1) << DE_FRAC_BITS) - 1u)

#define DE_ID_ADDR_LSB 11  /* address slot (X / dX in the data) */
#define DE_ID_ADDR_WIDTH 1
#define DE_ID_DATA_LSB 10  /* data slot (Eval value or Set) */
#define DE_ID_DATA_WIDTH 1
#define DE_ID_ACC_LSB 9  /* accumulate slot, D += A */
#define DE_ID_ACC_WIDTH 1
#define DE_ID_REFRESH_LSB 8  /* output the pixel, clear the PE */
#define DE_ID_REFRESH_WIDTH 1
#define DE_ID_DST_LSB 6  /* destination register code */
#define DE_ID_DST_WIDTH 2
#define DE_ID_SRC_LSB 4  /* source register code */
#define DE_ID_SRC_WIDTH 2
#define DE_ID_SET_LSB 3  /* data slot is a Set */
#define DE_ID_SET_WIDTH 1
#define DE_ID_PROT_LSB 2  /* Eval data slot honours DST's protect flag */
#define DE_ID_PROT_WIDTH 1
#define DE_ID_SUB_LSB 0  /* addressing sub-mode / Acc_mode */
#define DE_ID_SUB_WIDTH 2

#define DE_REG_NONE 0
#define DE_REG_A 1
#define DE_REG_B 2
#define DE_REG_C 3
#define DE_SUB_RANGE 0
#define DE_SUB_PERIODIC 1
#define DE_SUB_EVAL0 2
#define DE_SUB_DIS 3
#define DE_SUB_ACCMODE_ON 1
#define DE_SUB_ACCMODE_OFF 2
#define DE_TYPE_NONE 0
#define DE_TYPE_ADDRESS 1
#define DE_TYPE_INTENSITY 2

#define DE_ID_NOP 0x000u
#define DE_ID_REFRESH 0x100u
#define DE_ID_ACCMODE_ON 0x001u
#define DE_ID_ACCMODE_OFF 0x002u
#define DE_ID_ADDR_RANGE 0x800u
#define DE_ID_ADDR_PERIODIC 0x801u
#define DE_ID_ADDR_EVAL0 0x802u
#define DE_ID_ADDR_DIS 0x803u
#define DE_ID_ACC 0x200u
#define DE_ID_D_A 0x444u
#define DE_ID_D_B 0x484u
#define DE_ID_D_C 0x4c4u
#define DE_ID_D_B_C 0x4b4u
#define DE_ID_D_A_B 0x464u
#define DE_ID_D_A_B_NP 0x460u
#define DE_ID_D_A_A_NP 0x450u
#define DE_ID_SET_A 0x448u
#define DE_ID_SET_B 0x488u
#define DE_ID_SET_C 0x4c8u

#define DE_LUT_CODE_BITS 5
#define DE_LUT_ENTRIES 19

/* The prototype's 5 -> 12 look-up table; unused codes decode as NOP. */
static inline unsigned de_lut_ident(unsigned code)
{
    switch (code) {
    case 0: return DE_ID_NOP;
    case 1: return DE_ID_REFRESH;
    case 2: return DE_ID_ACCMODE_ON;
    case 3: return DE_ID_ACCMODE_OFF;
    case 4: return DE_ID_ADDR_RANGE;
    case 5: return DE_ID_ADDR_PERIODIC;
    case 6: return DE_ID_ADDR_EVAL0;
    case 7: return DE_ID_ADDR_DIS;
    case 8: return DE_ID_ACC;
    case 9: return DE_ID_D_A;
    case 10: return DE_ID_D_B;
    case 11: return DE_ID_D_C;
    case 12: return DE_ID_D_B_C;
    case 13: return DE_ID_D_A_B;
    case 14: return DE_ID_D_A_B_NP;
    case 15: return DE_ID_D_A_A_NP;
    case 16: return DE_ID_SET_A;
    case 17: return DE_ID_SET_B;
    case 18: return DE_ID_SET_C;
    default: return DE_ID_NOP;
    }
}

static inline const char *de_lut_name(unsigned code)
{
    switch (code) {
    case 0: return "NOP";
    case 1: return "REFRESH";
    case 2: return "ACCMODE_ON";
    case 3: return "ACCMODE_OFF";
    case 4: return "ADDR_RANGE";
    case 5: return "ADDR_PERIODIC";
    case 6: return "ADDR_EVAL0";
    case 7: return "ADDR_DIS";
    case 8: return "ACC";
    case 9: return "D_A";
    case 10: return "D_B";
    case 11: return "D_C";
    case 12: return "D_B_C";
    case 13: return "D_A_B";
    case 14: return "D_A_B_NP";
    case 15: return "D_A_A_NP";
    case 16: return "SET_A";
    case 17: return "SET_B";
    case 18: return "SET_C";
    default: return 0;
    }
}

/* The adder (isa.md section 7): with carry_bug the carry out of the fraction enters
 * the integer part at bit DE_ADD_CARRY_TO instead of DE_ADD_CARRY_FROM. */
#define DE_ADD_CARRY_FROM 24
#define DE_ADD_CARRY_TO 25
static inline uint64_t de_add_word(uint64_t x, uint64_t y, int carry_bug)
{
    if (!carry_bug) return (x + y) & DE_WORD_MASK;
    const uint64_t lm = (UINT64_C(1) << DE_ADD_CARRY_FROM) - 1u;
    uint64_t lo = (x & lm) + (y & lm);
    uint64_t hi = (x >> DE_ADD_CARRY_FROM) + (y >> DE_ADD_CARRY_FROM)
                  + ((lo >> DE_ADD_CARRY_FROM) << (DE_ADD_CARRY_TO - DE_ADD_CARRY_FROM));
    return ((hi << DE_ADD_CARRY_FROM) | (lo & lm)) & DE_WORD_MASK;
}

/* Video modes (spec/video.toml); index DE_VIDEO_MODE_TEST takes its geometry from
 * the caller. h/v: active, front porch, sync, back porch. */
typedef struct { const char *name; int h[4], v[4]; int hpol, vpol; } de_video_mode;
#define DE_VIDEO_MODE_TEST 3
#define DE_VIDEO_MODES 3
static inline const de_video_mode *de_video_mode_get(int m)
{
    static const de_video_mode modes[DE_VIDEO_MODES] = {
        {"640x480", {640, 16, 96, 48}, {480, 10, 2, 33}, 0, 0},  /* 640x480@60 (VESA DMT, 25.175 MHz, 800x525) */
        {"640x485", {640, 8, 24, 11}, {485, 11, 2, 27}, 0, 0},  /* 640x485 low resolution of section 7.4.5 (21.5 MHz, 683x525, 59.96 Hz) */
        {"1280x1024", {1280, 48, 112, 248}, {1024, 1, 3, 38}, 1, 1},  /* 1280x1024@60 (VESA DMT, 108 MHz, 1688x1066) */
    };
    return m >= 0 && m < DE_VIDEO_MODES ? &modes[m] : 0;
}
static inline int de_video_htotal(const de_video_mode *m)
{
    return m->h[0] + m->h[1] + m->h[2] + m->h[3];
}
static inline int de_video_vtotal(const de_video_mode *m)
{
    return m->v[0] + m->v[1] + m->v[2] + m->v[3];
}

/* de_pe's debug vector dbg_o: lsb of each field. */
#define DE_DBG_A_LSB 200
#define DE_DBG_B_LSB 164
#define DE_DBG_C_LSB 128
#define DE_DBG_D_LSB 92
#define DE_DBG_PA_LSB 91
#define DE_DBG_PB_LSB 90
#define DE_DBG_PC_LSB 89
#define DE_DBG_DIS_LSB 88
#define DE_DBG_LOCK_LSB 87
#define DE_DBG_ACC_MODE_LSB 86
#define DE_DBG_ACT_LSB 85
#define DE_DBG_ID1_LSB 73
#define DE_DBG_ID2_LSB 61
#define DE_DBG_OUT_LSB 25
#define DE_DBG_XZ1_LSB 24
#define DE_DBG_ACT1_LSB 23
#define DE_DBG_PROT1_LSB 22
#define DE_DBG_C1_LSB 21
#define DE_DBG_ACT2_LSB 20
#define DE_DBG_PROT2_LSB 19
#define DE_DBG_C2_LSB 18
#define DE_DBG_E0WR2_LSB 17
#define DE_DBG_ACCEN2_LSB 16
#define DE_DBG_ACCC2_LSB 15
#define DE_DBG_ACCEN3_LSB 14
#define DE_DBG_ACCC3_LSB 13
#define DE_DBG_PIX_VALID_LSB 12
#define DE_DBG_PIX_LSB 0
#define DE_DBG_BITS 236

/* The host register map (spec/regs.toml). */
#define DE_REG_CHAN_LSB 0x00cu  /* address bits above it: the channel */
#define DE_REG_INFO_CHAN 0x003u  /* channel of the controller's registers */
#define DE_LM_ID_MAGIC 0x0deu  /* Load Monitor ID[31:24] */
#define DE_CTRL_ID_MAGIC 0x0dcu  /* controller ID[31:24] */
#define DE_LM_REG_ID 0x000u  /* Load Monitor register */
#define DE_LM_REG_FRAMES 0x001u  /* Load Monitor register */
#define DE_LM_REG_ISSUED 0x002u  /* Load Monitor register */
#define DE_LM_REG_FREE 0x003u  /* Load Monitor register */
#define DE_LM_REG_LATE 0x004u  /* Load Monitor register */
#define DE_LM_REG_DROP 0x005u  /* Load Monitor register */
#define DE_LM_REG_MAX_ISSUED 0x006u  /* Load Monitor register */
#define DE_LM_REG_LAST_LINE 0x007u  /* Load Monitor register */
#define DE_LM_REG_LAST_REC 0x008u  /* Load Monitor register */
#define DE_LM_REG_TOTAL_DROP 0x009u  /* Load Monitor register */
#define DE_LM_REG_TOTAL_LATE 0x00au  /* Load Monitor register */
#define DE_LM_HIST_BASE 0x040u  /* HIST[b] at LM_HIST_BASE + b */
#define DE_LM_LINE_BASE 0x400u  /* LINE[l] at LM_LINE_BASE + l */
#define DE_CTRL_REG_ID 0x000u  /* controller register */
#define DE_CTRL_REG_ALIGN_ERR 0x001u  /* controller register */

#endif
