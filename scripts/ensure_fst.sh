#!/usr/bin/env bash
# Verilator's FST writer needs the lz4 headers (Debian: liblz4-dev); GTKWave is handy for
# opening the dumps. Install them once if missing (root on these machines; otherwise say
# what to install).
set -euo pipefail
need=()
[[ -f /usr/include/lz4.h ]] || need+=(liblz4-dev)
command -v gtkwave >/dev/null || need+=(gtkwave)
[[ ${#need[@]} -eq 0 ]] && exit 0
if [[ $(id -u) -eq 0 ]]; then
  echo "waves: installing ${need[*]} (Debian packages, once)" >&2
  apt-get update -qq && apt-get install -y -qq "${need[@]}" >/dev/null
else
  echo "waves: please install: ${need[*]} (sudo apt-get install ${need[*]})" >&2
  [[ -f /usr/include/lz4.h ]] || exit 1
fi
