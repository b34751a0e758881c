#!/usr/bin/env bash
# Lint every RTL file: Verilator -Wall per top module, then verible. Waivers live in the
# RTL next to the line they cover, each with its reason.
set -euo pipefail
cd "$(dirname "$0")/.."
pkg=rtl/xproc/de_pkg.sv
fail=0
lint_top() {  # top-module, files...
  local top=$1; shift
  if ! out=$(verilator --lint-only -Wall --top-module "$top" "$@" 2>&1); then
    echo "$out" | grep -v '^ ' ; fail=1
  fi
}
lint_top de_array $pkg rtl/xproc/de_pe.sv rtl/proto/de_skew.sv rtl/proto/de_deskew.sv \
  rtl/array/de_chip.sv rtl/array/de_array.sv
lint_top de_data_mapper $pkg rtl/proto/de_instr_lut.sv rtl/proto/de_data_mapper.sv
array=($pkg rtl/xproc/de_pe.sv rtl/proto/de_skew.sv rtl/proto/de_deskew.sv
       rtl/array/de_chip.sv rtl/array/de_array.sv)
for f in rtl/ctrl/*.sv; do
  top=$(basename "$f" .sv)
  if grep -q "de_array" "$f"; then
    # The arrays inside at 2 chips: de_array is linted at its product size (72) above, and
    # the controller's own code does not depend on the count; at 3 x 72 chips this one
    # call took over a minute of make test.
    lint_top "$top" -GNumChips=2 "${array[@]}" rtl/ctrl/*.sv
  else
    lint_top "$top" $pkg $(ls rtl/ctrl/*.sv | grep -v display_controller)
  fi
done
# board top: the whole design; the other board blocks stand alone
ctrl=($(ls rtl/ctrl/*.sv))
lint_top de_board_core "${array[@]}" rtl/proto/de_instr_lut.sv rtl/proto/de_data_mapper.sv \
  "${ctrl[@]}" rtl/board/*.sv
for f in rtl/board/*.sv; do
  case $f in
    */de_board_core.sv) ;;
    */de_fs_player.sv) lint_top de_fs_player $pkg rtl/proto/de_instr_lut.sv rtl/proto/de_data_mapper.sv "$f" ;;
    *) lint_top "$(basename "$f" .sv)" "$f" ;;
  esac
done
# virtual array: de_vpe.sv is generated from de_pe.sv (rtl/varray/gen_vpe.py)
python3 rtl/varray/gen_vpe.py build/varray/de_vpe.sv >/dev/null
lint_top de_varray $pkg build/varray/de_vpe.sv rtl/varray/de_varray.sv
lint_top de_span_array $pkg rtl/varray/de_span_array.sv
lint_top de_span_video $pkg rtl/varray/de_span_array.sv rtl/varray/de_afifo.sv rtl/varray/de_skid.sv \
  rtl/varray/de_span_video.sv
# sim/fast: the fast array's pieces and its DPI shell (simulation wiring around the same
# RTL, docs/simulation.md section 7). The tail and the shell hold no PE, so de_pkg's
# instruction-field constants are unused there.
chip=($pkg rtl/xproc/de_pe.sv rtl/proto/de_skew.sv rtl/proto/de_deskew.sv rtl/array/de_chip.sv)
lint_top de_fast_head "${chip[@]}" sim/fast/de_fast_head.sv
lint_top de_fast_unit "${chip[@]}" sim/fast/de_fast_unit.sv
lint_top de_fast_tail -Wno-UNUSEDPARAM "${chip[@]}" sim/fast/de_fast_tail.sv
lint_top de_array -Wno-UNUSEDPARAM "${chip[@]}" sim/fast/de_array.sv
if ! verible-verilog-lint $(find rtl sim/fast -name '*.sv' | sort); then fail=1; fi
[[ $fail -eq 0 ]] && echo "lint: clean ($(find rtl sim/fast -name '*.sv' | wc -l) files)"
exit $fail
