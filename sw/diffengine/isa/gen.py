"""Generate the ISA tables of every language from spec/isa.toml and spec/video.toml.

    python -m diffengine.isa.gen            write the generated files
    python -m diffengine.isa.gen --check    regenerate in memory, diff, exit 1 on a difference
    python -m diffengine.isa.gen --out DIR  write under DIR instead of the repository
    python -m diffengine.isa.gen --spec-root DIR   read DIR/spec/*.toml instead

A spec file that is not valid TOML stops it with FILE:LINE:COL: and exit status 1.

Outputs (paths relative to the repository root, each with a do-not-edit header):
rtl/xproc/de_pkg.sv (SystemVerilog package de_pkg), sw/include/de_isa.h (C) and
sw/diffengine/isa/_tables.py (Python). The adder with its carry-bug model, the register
selects and the look-up table are emitted as functions in all three, from the same
numbers, so the RTL, the C y-processor model and the Python golden model cannot drift.
"""
from __future__ import annotations

import argparse
import difflib
import re
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
SPEC = ("spec/isa.toml", "spec/video.toml", "spec/regs.toml")
SV_OUT = "rtl/xproc/de_pkg.sv"
C_OUT = "sw/include/de_isa.h"
PY_OUT = "sw/diffengine/isa/_tables.py"
COMMAND = "python -m diffengine.isa.gen"


def read_toml(path: Path) -> dict:
    """One spec file; a syntax error or an unreadable file exits 1 naming FILE:LINE:COL."""
    shown = path.relative_to(ROOT) if path.is_relative_to(ROOT) else path
    try:
        with open(path, "rb") as f:
            return tomllib.load(f)
    except OSError as e:
        raise SystemExit(f"{shown}: cannot read ({e.strerror})") from None
    except tomllib.TOMLDecodeError as e:
        msg = str(e)
        line, col = getattr(e, "lineno", None), getattr(e, "colno", None)
        m = re.search(r"\s*\(at line (\d+), column (\d+)\)$", msg)
        if m:
            msg = msg[:m.start()]
            line, col = line or int(m.group(1)), col or int(m.group(2))
        elif msg.endswith("(at end of document)"):
            msg = msg[:-len("(at end of document)")].rstrip()
            text = path.read_bytes().decode("utf-8", "replace")
            line, col = text.count("\n") + 1, len(text.rsplit("\n", 1)[-1]) + 1
        where = f"{shown}:{line}:{col}" if line else f"{shown}"
        raise SystemExit(f"{where}: {msg}") from None


def load(root: Path = ROOT) -> dict:
    spec = read_toml(root / SPEC[0])
    spec["video"] = read_toml(root / SPEC[1])
    spec["regs"] = read_toml(root / SPEC[2])
    check(spec)
    return spec


def check(spec: dict) -> None:
    """Refuse a description the generated code could not represent."""
    w = spec["word"]
    fields = spec["id_field"]
    used = 0
    for f in fields:
        mask = ((1 << f["width"]) - 1) << f["lsb"]
        if used & mask:
            raise SystemExit(f"spec/isa.toml: identifier field {f['name']} overlaps another")
        used |= mask
    if used != (1 << w["id_bits"]) - 1:
        raise SystemExit("spec/isa.toml: the identifier fields do not cover id_bits exactly")
    lsbs = [f["lsb"] for f in fields]
    if lsbs != sorted(lsbs, reverse=True):
        raise SystemExit("spec/isa.toml: list the identifier fields MSB first")
    a = spec["adder"]
    if a["carry_from"] % w["block_bits"] or not a["carry_from"] < a["carry_to"] < w["block_bits"] * w["blocks"]:
        raise SystemExit("spec/isa.toml: adder.carry_from must be a block boundary below carry_to")
    if len(spec["lut"]["entries"]) > 1 << spec["lut"]["code_bits"]:
        raise SystemExit("spec/isa.toml: more look-up table entries than codes")


def camel(name: str) -> str:
    return "".join(p[:1].upper() + p[1:] for p in name.lower().split("_"))


def ident_value(spec: dict, fields: dict) -> int:
    by_name = {f["name"]: f for f in spec["id_field"]}
    codes = {"dst": spec["reg_code"], "src": spec["reg_code"], "sub": spec["sub_code"]}
    v = 0
    for name, val in fields.items():
        f = by_name[name]
        if isinstance(val, str):
            val = codes[name][val]
        if not 0 <= val < 1 << f["width"]:
            raise SystemExit(f"spec/isa.toml: {name} = {val} does not fit {f['width']} bits")
        v |= val << f["lsb"]
    return v


def lut(spec: dict) -> list[tuple[str, int, str]]:
    return [(e["name"], ident_value(spec, e["fields"]), e["type"]) for e in spec["lut"]["entries"]]


def debug_lsbs(spec: dict) -> list[tuple[str, int, int]]:
    """(name, lsb, width) of each debug-vector field; the list is MSB first."""
    out, lsb = [], 0
    for name, width in reversed(spec["debug"]["fields"]):
        out.append((name, lsb, width))
        lsb += width
    return list(reversed(out))


CODE_GROUPS = (("REG", "reg_code"), ("SUB", "sub_code"), ("TYPE", "operand_type"))


def code_lines(spec: dict, fmt: str, groups) -> list[str]:
    """One line per code of the given spec tables, fmt taking {p} prefix, {k} name, {v}."""
    return [fmt.format(p=p, k=k.upper(), v=v) for p, g in groups for k, v in spec[g].items()]


def reg_map(spec: dict) -> list[tuple[str, int, int, str]]:
    """The host register map as (NAME, value, width in bits, comment), for every language."""
    r = spec["regs"]
    lm, ct = r["load_monitor"], r["controller"]
    out = [("REG_CHAN_LSB", r["address"]["channel_lsb"], 0, "address bits above it: the channel"),
           ("REG_INFO_CHAN", r["address"]["info_channel"], 2, "channel of the controller's registers"),
           ("LM_ID_MAGIC", lm["id_magic"], 8, "Load Monitor ID[31:24]"),
           ("CTRL_ID_MAGIC", ct["id_magic"], 8, "controller ID[31:24]")]
    out += [(f"LM_REG_{k.upper()}", v, 12, "Load Monitor register") for k, v in lm["reg"].items()]
    out += [("LM_HIST_BASE", lm["hist_base"], 12, "HIST[b] at LM_HIST_BASE + b"),
            ("LM_LINE_BASE", lm["line_base"], 12, "LINE[l] at LM_LINE_BASE + l")]
    out += [(f"CTRL_REG_{k.upper()}", v, 12, "controller register") for k, v in ct["reg"].items()]
    return out


def header(comment: str) -> str:
    return (f"{comment} GENERATED FILE, DO NOT EDIT. Source: {', '.join(SPEC)}.\n"
            f"{comment} Regenerate with `{COMMAND}` (or `make gen`); `make gen-check` diffs.\n")


# ---- SystemVerilog -------------------------------------------------------------------

def gen_sv(spec: dict) -> str:
    w, a = spec["word"], spec["adder"]
    o = [header("//"), "`default_nettype none\n",
         "// Difference Engine x-processor: shared widths, identifier layout, the block-carry",
         "// adder, the instruction look-up table, the video modes and the debug-vector layout.",
         "// docs/isa.md is the prose of spec/isa.toml; docs/display-controller.md 3 that of",
         "// spec/video.toml.\n",
         "package de_pkg;\n",
         "  // A table package: not every block uses every entry, so Verilator's unused-parameter",
         "  // warning would only list the entries other blocks use.",
         "  /* verilator lint_off UNUSEDPARAM */\n",
         "  // ---- widths ----",
         f"  localparam int unsigned IdW    = {w['id_bits']};",
         f"  localparam int unsigned BlkW   = {w['block_bits']};",
         f"  localparam int unsigned NumBlk = {w['blocks']};",
         "  localparam int unsigned DataW  = BlkW * NumBlk;",
         f"  localparam int unsigned FracW  = {w['frac_bits']};",
         "  localparam int unsigned PixW   = DataW - FracW;  // pixel = the integer part",
         f"  localparam int unsigned AddrMax = {w['addr_max']};",
         "",
         "  // ---- identifier fields ----"]
    for f in spec["id_field"]:
        suffix = "Bit" if f["width"] == 1 else "Lsb"
        o.append(f"  localparam int unsigned Id{camel(f['name'])}{suffix} = {f['lsb']};  // {f['doc']}")
    o += ["", "  // The same layout as a packed struct (MSB first), so that the RTL can write id.dst.",
          "  typedef struct packed {"]
    for f in spec["id_field"]:
        typ = "logic      " if f["width"] == 1 else f"logic [{f['width'] - 1}:0]"
        o.append(f"    {typ} {f['name']};")
    o += ["  } id_t;", "",
          "  // ---- the array's chain from chip to chip (rtl/array/de_chip.sv) ----",
          "  // What a chip passes to the next: the bus (skewed blocks), the pixel chain and the",
          "  // chip's collision flag (MSB first). de_chip, its core and boundary registers and the",
          "  // fast array's pieces (sim/fast) all pass this one value; a chip does not use the",
          "  // coll of its input (the array ORs the chips' flags).",
          "  typedef struct packed {",
          "    logic [IdW-1:0]   id;",
          "    logic [DataW-1:0] data;",
          "    logic             pix_valid;",
          "    logic [PixW-1:0]  pix;",
          "    logic             coll;",
          "  } link_t;",
          "  // The configuration and observation chains: one serial bit each, chip to chip ...",
          "  typedef struct packed {",
          "    logic cfg;",
          "    logic obs;",
          "  } chain_t;",
          "  // ... and their controls, the same for every chip: shift the configuration, load",
          "  // and shift the observation words (7.4.5).",
          "  typedef struct packed {",
          "    logic cfg_mode;",
          "    logic obs_load;",
          "    logic obs_shift;",
          "  } chain_ctl_t;", "",
          "  // Register codes of the DST / SRC fields; RegNone reads as zero."]
    for k, v in spec["reg_code"].items():
        o.append(f"  localparam logic [1:0] Reg{camel(k)} = 2'd{v};")
    o.append("  // SUB field codes (with ADDR set; Acc_mode with no class bit set).")
    for k, v in spec["sub_code"].items():
        o.append(f"  localparam logic [1:0] Sub{camel(k)} = 2'd{v};")
    o += ["", "  // ---- identifiers of the look-up table ----"]
    for name, val, _ in lut(spec):
        o.append(f"  localparam logic [IdW-1:0] Id{camel(name)} = {w['id_bits']}'h{val:03X};")
    cw = spec["lut"]["code_bits"]
    o += ["", "  // Operand type: how the data mapper expands the 27-bit operand."]
    for k, v in spec["operand_type"].items():
        o.append(f"  localparam logic [1:0] Type{camel(k)} = 2'd{v};")
    o += [f"  localparam int unsigned LutCodeW = {cw};", "",
          "  // The prototype's 5 -> 12 look-up table; unused codes decode as Nop (cannot act).",
          "  function automatic logic [IdW-1:0] lut_ident(input logic [LutCodeW-1:0] code);",
          "    case (code)"]
    for i, (name, _, _) in enumerate(lut(spec)):
        o.append(f"      {cw}'d{i}: lut_ident = Id{camel(name)};")
    o += ["      default: lut_ident = IdNop;", "    endcase", "  endfunction", "",
          "  function automatic logic [1:0] lut_type(input logic [LutCodeW-1:0] code);",
          "    case (code)"]
    types = {"none": "TypeNone", "address": "TypeAddress", "intensity": "TypeIntensity"}
    # One case item per operand type, listing its codes.
    codes: dict[str, list[str]] = {}
    for i, (_, _, t) in enumerate(lut(spec)):
        codes.setdefault(t, []).append(f"{cw}'d{i}")
    for t, cs in codes.items():
        o.append(f"      {', '.join(cs)}:")
        o.append(f"        lut_type = {types[t]};")
    o += ["      default: lut_type = TypeNone;", "    endcase", "  endfunction", "",
          "  // ---- field selects ----",
          "  // Register read port: code RegNone reads as zero (\"adds 0\"); a word, and through",
          "  // it one block (de_pe) and a flag.",
          "  function automatic logic [DataW-1:0] reg_word(input logic [1:0] code,",
          "      input logic [DataW-1:0] a, input logic [DataW-1:0] b, input logic [DataW-1:0] c);",
          "    case (code)", "      RegA:    reg_word = a;", "      RegB:    reg_word = b;",
          "      RegC:    reg_word = c;", "      default: reg_word = '0;", "    endcase",
          "  endfunction"]
    for fn, w in (("reg_blk", "BlkW"), ("reg_flag", "1")):
        typ = "logic" if w == "1" else f"logic [{w}-1:0]"
        o += [f"  function automatic {typ} {fn}(input logic [1:0] code, input {typ} a,",
              f"                                input {typ} b, input {typ} c);",
              f"    {fn} = {w}'(reg_word(code, DataW'(a), DataW'(b), DataW'(c)));",
              "  endfunction"]
    o += ["  // One instruction as the y-processor and the controller store it: {identifier, data}.",
          "  localparam int unsigned RecW = IdW + DataW;",
          "  // Each reads one half of the record.",
          "  /* verilator lint_off UNUSEDSIGNAL */",
          "  function automatic logic [IdW-1:0] rec_id(input logic [RecW-1:0] r);",
          "    rec_id = r[RecW-1 -: IdW];",
          "  endfunction",
          "  function automatic logic [DataW-1:0] rec_data(input logic [RecW-1:0] r);",
          "    rec_data = r[DataW-1:0];",
          "  endfunction",
          "  /* verilator lint_on UNUSEDSIGNAL */",
          "  // A command starts with a slot that is neither DATA nor ACC (an address slot,",
          "  // Refresh, Acc_mode or Nop): the controller cuts the stream only there.",
          "  function automatic logic id_starts_cmd(input logic [IdW-1:0] id);",
          "    id_starts_cmd = !id[IdDataBit] && !id[IdAccBit];",
          "  endfunction",
          "  // Block i of a data word (block 0 = the low 12 bits; the pixel is block 2).",
          "  function automatic logic [BlkW-1:0] word_blk(input logic [DataW-1:0] w,",
          "                                               input int unsigned i);",
          "    word_blk = w[i*BlkW +: BlkW];",
          "  endfunction",
          "", "  // ---- the adder (isa.md section 7) ----",
          "  // With the prototype's carry fault the carry out of the fraction enters the integer",
          "  // part at bit AddCarryTo instead of AddCarryFrom: it adds 2 where 1 was meant.",
          f"  localparam int unsigned AddCarryFrom = {a['carry_from']};",
          f"  localparam int unsigned AddCarryTo   = {a['carry_to']};",
          "  localparam int unsigned AddCarryBlk  = AddCarryFrom / BlkW;  // block the fault enters",
          "",
          "  // The whole-word form (de_span_array): one carry chain when carry_bug is 0.",
          "  function automatic logic [DataW-1:0] add_word(input logic [DataW-1:0] x,",
          "                                                input logic [DataW-1:0] y,",
          "                                                input bit carry_bug);",
          "    logic [AddCarryFrom:0]       lo;",
          "    logic [DataW-AddCarryFrom-1:0] hi;",
          "    lo = {1'b0, x[AddCarryFrom-1:0]} + {1'b0, y[AddCarryFrom-1:0]};",
          "    hi = x[DataW-1:AddCarryFrom] + y[DataW-1:AddCarryFrom]",
          "       + ((DataW - AddCarryFrom)'(lo[AddCarryFrom]) << (AddCarryTo - AddCarryFrom));",
          "    // One carry chain without the fault: the fault's form puts two in series.",
          "    add_word = carry_bug ? {hi, lo[AddCarryFrom-1:0]} : x + y;",
          "  endfunction",
          "",
          "  // The block-carry form (de_pe): weight of a registered block carry as it enters",
          "  // block blk: bit 0, or with the fault bit AddCarryTo - AddCarryFrom of block",
          "  // AddCarryBlk.",
          "  function automatic logic [BlkW:0] blk_carry_in(input logic c, input int unsigned blk,",
          "                                                input bit carry_bug);",
          "    blk_carry_in = (BlkW + 1)'(c);",
          "    if (carry_bug && blk == AddCarryBlk) begin",
          "      blk_carry_in = (BlkW + 1)'(c) << (AddCarryTo - AddCarryFrom);",
          "    end",
          "  endfunction",
          "",
          "  // ---- video modes (spec/video.toml) ----",
          "  typedef struct packed {",
          "    logic [11:0] h_act, h_fp, h_sync, h_bp;",
          "    logic [11:0] v_act, v_fp, v_sync, v_bp;",
          "    logic        h_pol, v_pol;  // 1 = active-high sync pulse",
          "  } video_mode_t;",
          f"  localparam logic [1:0] VideoModeTest = 2'd{spec['video']['test']['index']};",
          "  // The test mode's default geometry (the tops' TestMode parameter).",
          "  localparam video_mode_t VideoTestDefault = "
          + sv_mode(spec["video"]["test"]).replace("\n" + " " * 25, "\n" + " " * 44) + ";",
          "",
          "  // The fixed modes by index; the test mode (and any other index) returns mode 0,",
          "  // its geometry comes from de_video_timing's parameters.",
          "  function automatic video_mode_t video_mode(input logic [1:0] m);",
          "    case (m)"]
    modes = spec["video"]["mode"]
    default = next(m for m in modes if m["index"] == 0)
    for m in modes:
        o += [f"      // {m['doc']}", f"      2'd{m['index']}: video_mode = {sv_mode(m)};"]
    o += [f"      default: video_mode = {sv_mode(default)};", "    endcase", "  endfunction", "",
          "  // ---- de_pe's debug vector dbg_o (MSB first in spec/isa.toml) ----"]
    fields = debug_lsbs(spec)
    for name, lsb, _ in fields:
        o.append(f"  localparam int unsigned Dbg{camel(name)}Lsb = {lsb};")
    o.append(f"  localparam int unsigned DbgW = {sum(wd for _, _, wd in fields)};")
    o += ["", "  // ---- host register map (spec/regs.toml) ----"]
    for name, val, width, doc in reg_map(spec):
        typ = "int unsigned" if width == 0 else f"logic [{width - 1}:0]"
        lit = str(val) if width == 0 else f"{width}'h{val:0{(width + 3) // 4}X}"
        o.append(f"  localparam {typ} {camel(name)} = {lit};  // {doc}")
    o += ["",
          "  // Elaboration-time check that id_t and the bit positions above agree (used by de_pe).",
          "  function automatic bit id_layout_ok();",
          "    id_t t;",
          "    bit  ok;",
          "    ok = ($bits(t) == IdW);"]
    for f in spec["id_field"]:
        suffix = "Bit" if f["width"] == 1 else "Lsb"
        val = "1'b1" if f["width"] == 1 else f"{f['width']}'d1"
        o.append(f"    t = '0; t.{f['name']} = {val}; ok &= (IdW'(t) == IdW'(1) << Id{camel(f['name'])}{suffix});")
    o += ["    id_layout_ok = ok;", "  endfunction", "", "  /* verilator lint_on UNUSEDPARAM */", "",
          "endpackage", "", "`default_nettype wire", ""]
    return "\n".join(o)


def sv_mode(m: dict) -> str:
    """A video_mode_t value as a concatenation (yosys's own parser has no '{...}), one line
    per direction (h, v, polarities)."""
    h = ", ".join(f"12'd{x}" for x in m["h"])
    v = ", ".join(f"12'd{x}" for x in m["v"])
    pad = " " * 25  # under the first value after "      2'dN: video_mode = {"
    return f"{{{h},\n{pad}{v},\n{pad}1'b{int(m['hpol'])}, 1'b{int(m['vpol'])}}}"


# ---- C -------------------------------------------------------------------------------

def gen_c(spec: dict) -> str:
    w, a = spec["word"], spec["adder"]
    o = [header("/*").replace("\n/*", "\n *").rstrip("\n") + " */",
         "/* de_isa.h - the x-processor instruction set for C and C++ (sw/hsr, sim/harness):",
         " * identifiers, field positions, the adder with its carry-bug model, the look-up",
         " * table, the video modes. docs/isa.md is the prose. */",
         "#ifndef DE_ISA_H", "#define DE_ISA_H", "", "#include <stdint.h>", "",
         f"#define DE_ID_BITS {w['id_bits']}",
         f"#define DE_BLOCK_BITS {w['block_bits']}",
         f"#define DE_BLOCKS {w['blocks']}",
         f"#define DE_WORD_BITS {w['block_bits'] * w['blocks']}",
         f"#define DE_FRAC_BITS {w['frac_bits']}",
         f"#define DE_ADDR_MAX {w['addr_max']}",
         f"#define DE_MAX_EVAL_ORDER {w['max_eval_order']}",
         f"#define DE_RECORD_BITS {w['record_bits']}",
         "#define DE_ID_MASK ((1u << DE_ID_BITS) - 1u)",
         "#define DE_BLOCK_MASK ((1u << DE_BLOCK_BITS) - 1u)",
         "#define DE_WORD_MASK ((UINT64_C(1) << DE_WORD_BITS) - 1u)",
         "#define DE_FRAC_MASK ((UINT64_C(1) << DE_FRAC_BITS) - 1u)", ""]
    for f in spec["id_field"]:
        o.append(f"#define DE_ID_{f['name'].upper()}_LSB {f['lsb']}  /* {f['doc']} */")
        o.append(f"#define DE_ID_{f['name'].upper()}_WIDTH {f['width']}")
    o += [""] + code_lines(spec, "#define DE_{p}_{k} {v}", CODE_GROUPS) + [""]
    for name, val, _ in lut(spec):
        o.append(f"#define DE_ID_{name} 0x{val:03x}u")
    cw = spec["lut"]["code_bits"]
    o += ["", f"#define DE_LUT_CODE_BITS {cw}", f"#define DE_LUT_ENTRIES {len(lut(spec))}", "",
          "/* The prototype's 5 -> 12 look-up table; unused codes decode as NOP. */",
          "static inline unsigned de_lut_ident(unsigned code)", "{", "    switch (code) {"]
    for i, (name, _, _) in enumerate(lut(spec)):
        o.append(f"    case {i}: return DE_ID_{name};")
    o += ["    default: return DE_ID_NOP;", "    }", "}", "",
          "static inline const char *de_lut_name(unsigned code)", "{", "    switch (code) {"]
    for i, (name, _, _) in enumerate(lut(spec)):
        o.append(f"    case {i}: return \"{name}\";")
    o += ["    default: return 0;", "    }", "}", "",
          "/* The adder (isa.md section 7): with carry_bug the carry out of the fraction enters",
          " * the integer part at bit DE_ADD_CARRY_TO instead of DE_ADD_CARRY_FROM. */",
          f"#define DE_ADD_CARRY_FROM {a['carry_from']}",
          f"#define DE_ADD_CARRY_TO {a['carry_to']}",
          "static inline uint64_t de_add_word(uint64_t x, uint64_t y, int carry_bug)", "{",
          "    if (!carry_bug) return (x + y) & DE_WORD_MASK;",
          "    const uint64_t lm = (UINT64_C(1) << DE_ADD_CARRY_FROM) - 1u;",
          "    uint64_t lo = (x & lm) + (y & lm);",
          "    uint64_t hi = (x >> DE_ADD_CARRY_FROM) + (y >> DE_ADD_CARRY_FROM)",
          "                  + ((lo >> DE_ADD_CARRY_FROM) << (DE_ADD_CARRY_TO - DE_ADD_CARRY_FROM));",
          "    return ((hi << DE_ADD_CARRY_FROM) | (lo & lm)) & DE_WORD_MASK;", "}", "",
          "/* Video modes (spec/video.toml); index DE_VIDEO_MODE_TEST takes its geometry from",
          " * the caller. h/v: active, front porch, sync, back porch. */",
          "typedef struct { const char *name; int h[4], v[4]; int hpol, vpol; } de_video_mode;",
          f"#define DE_VIDEO_MODE_TEST {spec['video']['test']['index']}",
          f"#define DE_VIDEO_MODES {len(spec['video']['mode'])}",
          "static inline const de_video_mode *de_video_mode_get(int m)", "{",
          "    static const de_video_mode modes[DE_VIDEO_MODES] = {"]
    for m in spec["video"]["mode"]:
        h, v = ", ".join(map(str, m["h"])), ", ".join(map(str, m["v"]))
        o.append(f"        {{\"{m['name']}\", {{{h}}}, {{{v}}}, {int(m['hpol'])}, {int(m['vpol'])}}},  /* {m['doc']} */")
    o += ["    };", "    return m >= 0 && m < DE_VIDEO_MODES ? &modes[m] : 0;", "}",
          "static inline int de_video_htotal(const de_video_mode *m)",
          "{", "    return m->h[0] + m->h[1] + m->h[2] + m->h[3];", "}",
          "static inline int de_video_vtotal(const de_video_mode *m)",
          "{", "    return m->v[0] + m->v[1] + m->v[2] + m->v[3];", "}", "",
          "/* de_pe's debug vector dbg_o: lsb of each field. */"]
    for name, lsb, width in debug_lsbs(spec):
        o.append(f"#define DE_DBG_{name.upper()}_LSB {lsb}")
    o += [f"#define DE_DBG_BITS {sum(wd for _, _, wd in debug_lsbs(spec))}", "",
          "/* The host register map (spec/regs.toml). */"]
    o += [f"#define DE_{name} 0x{val:03x}u  /* {doc} */" for name, val, _, doc in reg_map(spec)]
    o += ["", "#endif", ""]
    return "\n".join(o)


# ---- Python --------------------------------------------------------------------------

def gen_py(spec: dict) -> str:
    w, a = spec["word"], spec["adder"]
    o = [header("#").rstrip("\n"),
         '"""The ISA tables of spec/isa.toml and spec/video.toml (imported by diffengine.isa)."""',
         "from __future__ import annotations", "",
         f"ID_BITS = {w['id_bits']}",
         f"BLOCK_BITS = {w['block_bits']}",
         f"BLOCKS = {w['blocks']}",
         "WORD_BITS = BLOCK_BITS * BLOCKS",
         f"FRAC_BITS = {w['frac_bits']}",
         f"ADDR_MAX = {w['addr_max']}",
         f"MAX_EVAL_ORDER = {w['max_eval_order']}",
         f"RECORD_BITS = {w['record_bits']}",
         "ID_MASK = (1 << ID_BITS) - 1",
         "BLOCK_MASK = (1 << BLOCK_BITS) - 1",
         "WORD_MASK = (1 << WORD_BITS) - 1",
         "FRAC_MASK = (1 << FRAC_BITS) - 1",
         "", "# Identifier fields: name -> (lsb, width)."]
    o.append("ID_FIELDS = {")
    for f in spec["id_field"]:
        o.append(f"    \"{f['name']}\": ({f['lsb']}, {f['width']}),  # {f['doc']}")
    o.append("}")
    for f in spec["id_field"]:
        if f["width"] == 1:
            o.append(f"ID_{f['name'].upper()} = 1 << {f['lsb']}")
        else:
            o.append(f"{f['name'].upper()}_SHIFT = {f['lsb']}")
            o.append(f"{f['name'].upper()}_MASK = 0x{(1 << f['width']) - 1:x}")
    o += [""] + code_lines(spec, "{p}_{k} = {v}", CODE_GROUPS[:2]) + [""]
    o.append('TYPE_NONE, TYPE_ADDR, TYPE_INT = "none", "address", "intensity"')
    o.append("OPERAND_TYPE_CODE = {" + ", ".join(
        f"\"{k}\": {v}" for k, v in spec["operand_type"].items()) + "}")
    o.append("")
    for name, val, _ in lut(spec):
        o.append(f"{name} = 0x{val:03x}")
    tname = {"none": "TYPE_NONE", "address": "TYPE_ADDR", "intensity": "TYPE_INT"}
    o += ["", f"LUT_CODE_BITS = {spec['lut']['code_bits']}",
          "# The instruction look-up table of the prototype (7.6.2): 5-bit code -> identifier.",
          "LUT: list[tuple[str, int, str]] = ["]
    for name, _, t in lut(spec):
        o.append(f"    (\"{name}\", {name}, {tname[t]}),")
    o += ["]", "", "# The host register map (spec/regs.toml)."]
    o += [f"{name} = 0x{val:03x}  # {doc}" for name, val, _, doc in reg_map(spec)]
    o += ["",
          f"ADD_CARRY_FROM = {a['carry_from']}",
          f"ADD_CARRY_TO = {a['carry_to']}", "", "",
          "def add_word(x: int, y: int, carry_bug: bool = False) -> int:",
          '    """The adder (isa.md section 7); with carry_bug the carry out of the fraction',
          '    enters the integer part at ADD_CARRY_TO instead of ADD_CARRY_FROM."""',
          "    if not carry_bug:", "        return (x + y) & WORD_MASK",
          "    lm = (1 << ADD_CARRY_FROM) - 1",
          "    lo = (x & lm) + (y & lm)",
          "    hi = (x >> ADD_CARRY_FROM) + (y >> ADD_CARRY_FROM) + ((lo >> ADD_CARRY_FROM) << (ADD_CARRY_TO - ADD_CARRY_FROM))",
          "    return ((hi << ADD_CARRY_FROM) | (lo & lm)) & WORD_MASK", "", "",
          "# Video modes (spec/video.toml): index -> (name, (hact, hfp, hsync, hbp),",
          "# (vact, vfp, vsync, vbp), hpol, vpol); index VIDEO_MODE_TEST is given by the caller.",
          f"VIDEO_MODE_TEST = {spec['video']['test']['index']}",
          "VIDEO_MODES = {"]
    for m in spec["video"]["mode"]:
        o.append(f"    {m['index']}: (\"{m['name']}\", {tuple(m['h'])}, {tuple(m['v'])}, {m['hpol']}, {m['vpol']}),")
    o += ["}", "", "# de_pe's debug vector dbg_o, MSB first: (name, width).",
          "DBG_FIELDS: list[tuple[str, int]] = ["]
    for name, width in spec["debug"]["fields"]:
        o.append(f"    (\"{name}\", {width}),")
    o += ["]", ""]
    return "\n".join(o)


def outputs(spec: dict) -> dict[str, str]:
    return {SV_OUT: gen_sv(spec), C_OUT: gen_c(spec), PY_OUT: gen_py(spec)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog=COMMAND, description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="diff against the checked-in files; exit 1 on a difference")
    ap.add_argument("--out", type=Path, default=ROOT, help="root to write under (default: the repository)")
    ap.add_argument("--spec-root", type=Path, default=ROOT,
                    help="root whose spec/*.toml are read (default: the repository)")
    a = ap.parse_args(argv)
    files = outputs(load(a.spec_root.resolve()))
    bad = 0
    for rel, text in files.items():
        path = a.out / rel
        if a.check:
            old = path.read_text() if path.exists() else ""
            if old != text:
                bad += 1
                sys.stdout.writelines(difflib.unified_diff(
                    old.splitlines(True), text.splitlines(True), f"a/{rel}", f"b/{rel} (generated)"))
        else:
            path.parent.mkdir(parents=True, exist_ok=True)
            if not path.exists() or path.read_text() != text:
                path.write_text(text)
                print(f"wrote {rel}")
    if bad:
        print(f"{bad} generated file(s) differ from {', '.join(SPEC)}: run `{COMMAND}`", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
