#!/usr/bin/env bash
# Verilator's FST writer needs the lz4 headers (Debian: liblz4-dev); GTKWave (fst2vcd) is
# handy for opening the dumps. Nothing to do when they are there; otherwise install them
# through scripts/ensure_system.sh (one lock for every apt-get of the project, so parallel
# callers cannot race). --headers: only the lz4 headers (what a trace build needs).
# Exit 1 only when the lz4 headers are still missing.
set -euo pipefail
need=()
[[ -f /usr/include/lz4.h ]] || need+=(liblz4-dev)
[[ ${1:-} == --headers ]] || command -v gtkwave >/dev/null || need+=(gtkwave)
[[ ${#need[@]} -eq 0 ]] && exit 0
"$(dirname "$0")/ensure_system.sh" "${need[@]}" && exit 0
[[ -f /usr/include/lz4.h ]] || exit 1
