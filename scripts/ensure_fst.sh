#!/usr/bin/env bash
# Verilator's FST writer needs the lz4 headers (Debian: liblz4-dev); GTKWave is handy for
# opening the dumps. Install them once if missing (root on these machines; otherwise say
# what to install). --headers: only the lz4 headers (what a trace build needs).
set -euo pipefail
need=()
[[ -f /usr/include/lz4.h ]] || need+=(liblz4-dev)
[[ ${1:-} == --headers ]] || command -v gtkwave >/dev/null || need+=(gtkwave)
[[ ${#need[@]} -eq 0 ]] && exit 0
if [[ $(id -u) -eq 0 ]]; then
  echo "fst: installing ${need[*]} (Debian packages, once)" >&2
  apt-get update -qq && apt-get install -y -qq "${need[@]}" >/dev/null
else
  echo "fst: please install: ${need[*]} (sudo apt-get install ${need[*]})" >&2
  [[ -f /usr/include/lz4.h ]] || exit 1
fi
