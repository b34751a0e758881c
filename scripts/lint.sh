#!/usr/bin/env bash
# Lint every RTL file: Verilator -Wall per top module, then verible. Waivers live in the
# RTL next to the line they cover, each with its reason.
set -euo pipefail
cd "$(dirname "$0")/.."
# File lists: the FuseSoC cores' (rtl/*/*.core, sim/fast/de_fast.core; scripts/filelist.py,
# cached in build/cores/), relative to the checkout so the messages keep their paths.
py=.venv/bin/python; [[ -x $py ]] || py=python3
files() { "$py" scripts/filelist.py --relative "$@"; }
fail=0
lint_top() {  # top-module, files...
  local top=$1; shift
  if ! out=$(verilator --lint-only -Wall --top-module "$top" "$@" 2>&1); then
    echo "$out" | grep -v '^ ' ; fail=1
  fi
}
lint_top de_array $(files array lint)
lint_top de_data_mapper $(files input lint)
ctrl=($(files display_core))
for f in "${ctrl[@]}"; do
  lint_top "$(basename "$f" .sv)" "${ctrl[@]}"
done
# The arrays inside at 2 chips: de_array is linted at its product size (72) above, and the
# controller's own code does not depend on the count; at 3 x 72 chips this one call took
# over a minute of make test.
lint_top display_controller -GNumChips=2 $(files display_controller lint)
# board top: the whole design; the other board blocks stand alone
lint_top de_board_core $(files board lint)
for f in rtl/board/*.sv; do
  case $f in
    */de_board_core.sv) ;;
    */de_frame_player.sv) lint_top de_frame_player $(files input) "$f" ;;
    */de_sdram_frames.sv) lint_top de_sdram_frames $(files board frames) ;;
    */de_uart_pkg.sv|*/de_sdram_pkg.sv) ;;   # linted with their users
    */de_sdram_ctrl.sv) lint_top de_sdram_ctrl $(files sdram_ctrl) ;;
    */de_uart_link.sv) lint_top de_uart_link $(files board uart) ;;
    *) lint_top "$(basename "$f" .sv)" "$f" ;;
  esac
done
lint_top de_async_fifo $(files prim lint)
lint_top de_delay $(files prim lint)
lint_top de_span_array $(files span_array lint)
lint_top de_span_video $(files span_video lint)
# sim/fast: the fast array's pieces and its DPI shell (simulation wiring around the same
# RTL, docs/simulation.md section 7). The tail and the shell hold no PE, so de_pkg's
# instruction-field constants are unused there.
lint_top de_fast_head $(files fast head)
lint_top de_fast_unit $(files fast unit)
lint_top de_fast_tail -Wno-UNUSEDPARAM $(files fast tail)
lint_top de_array -Wno-UNUSEDPARAM $(files fast shell)
if ! verible-verilog-lint $(find rtl sim/fast -name '*.sv' | sort); then fail=1; fi
[[ $fail -eq 0 ]] && echo "lint: clean ($(find rtl sim/fast -name '*.sv' | wc -l) files)"
exit $fail
