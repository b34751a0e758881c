#!/usr/bin/env bash
# The Debian packages that `make demo` and `make test` need, installed once and under one
# lock before any parallel work starts (the Makefile runs this first). The per-tool
# scripts (ensure_fst.sh, ensure_clang.sh) and tests that need a system tool call it with
# their own package names, so that no two callers ever run apt-get at the same time.
set -euo pipefail

usage() {
  cat <<'EOF'
usage: scripts/ensure_system.sh [--check] [--list] [PACKAGE[?] ...]

Installs the Debian packages that `make demo` and `make test` need, or only the PACKAGEs
named (a trailing ? marks a package optional: installed when the archive has it, skipped
otherwise). When every package is installed (dpkg-query) it does nothing. Otherwise,
under one lock file shared by every caller (DE_SYSTEM_LOCK, default
/run/lock/diffengine-apt.lock), it checks again, runs `apt-get update` only when the
package lists are missing or lack a package (or an install fails on stale lists), then
`apt-get -o DPkg::Lock::Timeout=300 install -y --no-install-recommends ...`.

Needs root, or sudo without a password (or sudo on a terminal). Otherwise it names the
missing packages and the command to run, and exits 1 (DE_SYSTEM_CHECK=warn: exit 0
after saying so).

  --check   only report what is missing; exit 1 if a required package is
  --list    print the default package list and exit
  -h, --help
EOF
}

# What `make demo` and `make test` use from Debian (ccache is optional: the sim Makefiles
# compile through it when it is there).
DEFAULT=(
  build-essential   # gcc, g++, make: sw/hsr, the Verilated models
  python3-venv      # .venv (scripts/setup.sh)
  python3-dev       # libpython for cocotb's embedded Python
  iverilog          # tb/postsynth (netlists in Icarus)
  liblz4-dev        # Verilator FST traces (scripts/ensure_fst.sh)
  zlib1g-dev        # Verilator FST traces
  gtkwave           # fst2vcd in the trace tests, GTKWave for make waves
  chromium          # tb/sim_regress/test_inspect.py, the viewer's browser tests (headless)
  chromium-driver   # Selenium's chromedriver for the viewer's browser tests (docs/viewer.md)
  'ccache?'         # faster Verilator rebuilds
)

check=0
args=()
while (($#)); do
  case $1 in
    -h|--help) usage; exit 0 ;;
    --check) check=1 ;;
    --list) printf '%s\n' "${DEFAULT[@]}"; exit 0 ;;
    -*) echo "ensure_system: unknown option $1 (see --help)" >&2; exit 2 ;;
    *) args+=("$1") ;;
  esac
  shift
done
named=("${args[@]}")
((${#args[@]})) || args=("${DEFAULT[@]}")
req=() opt=()
for p in "${args[@]}"; do
  if [[ $p == *'?' ]]; then opt+=("${p%'?'}"); else req+=("$p"); fi
done

# The packages among "$@" that dpkg does not list as installed, one a line.
missing_of() {
  local -A ok=()
  local name st p
  while read -r name st; do
    [[ $st == installed ]] && ok[$name]=1
  done < <(dpkg-query -W -f='${Package} ${db:Status-Status}\n' "$@" 2>/dev/null || true)
  for p; do [[ -n ${ok[$p]:-} ]] || echo "$p"; done
}

# The packages among "$@" that the package lists can install, one a line.
candidates_of() {
  apt-cache policy "$@" 2>/dev/null | awk '
    /^[^ ]/ { p = $1; sub(/:$/, "", p) }
    $1 == "Candidate:" && $2 != "(none)" { print p }'
}

is_in() { local x=$1; shift; local y; for y; do [[ $x == "$y" ]] && return 0; done; return 1; }

mapfile -t miss < <(missing_of "${req[@]}" "${opt[@]}")
((${#miss[@]} == 0)) && exit 0                      # the usual case: nothing to do, no lock
miss_req=()
for p in "${miss[@]}"; do is_in "$p" "${req[@]}" && miss_req+=("$p"); done

if ((check)); then
  echo "ensure_system: not installed: ${miss[*]}" >&2
  ((${#miss_req[@]} == 0))
  exit
fi

if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null && { sudo -n true 2>/dev/null || [[ -t 0 ]]; }; then
    exec sudo -- env DE_SYSTEM_LOCK="${DE_SYSTEM_LOCK:-}" "$0" "${named[@]}"
  fi
  if ((${#miss_req[@]} == 0)); then
    echo "ensure_system: optional, not installed: ${miss[*]} (not root, no sudo)" >&2
    exit 0
  fi
  echo "ensure_system: missing Debian packages: ${miss[*]}" >&2
  echo "ensure_system: not root and no sudo here; as root run:" >&2
  echo "  apt-get install -y --no-install-recommends ${miss[*]}" >&2
  echo "  (or: sudo $0${named[*]:+$(printf ' %q' "${named[@]}")})" >&2
  [[ ${DE_SYSTEM_CHECK:-} == warn ]] && exit 0
  exit 1
fi

# One caller at a time from here on; the others wait, then find the packages installed.
lockdir=/run/lock
[[ -d $lockdir && -w $lockdir ]] || lockdir=/tmp
lock=${DE_SYSTEM_LOCK:-$lockdir/diffengine-apt.lock}
if [[ -w $lock || ! -e $lock ]]; then exec 9>>"$lock"; chmod 666 "$lock" 2>/dev/null || true
else exec 9<"$lock"; fi
if ! flock -w 900 9; then
  echo "ensure_system: waited 900 s for $lock (another install still running?)" >&2
  exit 1
fi
mapfile -t miss < <(missing_of "${req[@]}" "${opt[@]}")
((${#miss[@]} == 0)) && exit 0                      # another caller installed them meanwhile

log=$(mktemp)
trap 'rm -f "$log"' EXIT
apt_() {
  DEBIAN_FRONTEND=noninteractive apt-get -o DPkg::Lock::Timeout=300 "$@" >>"$log" 2>&1
}
fail() {
  echo "ensure_system: $1" >&2
  tail -n 20 "$log" | sed 's/^/  /' >&2
  exit 1
}

updated=0
mapfile -t cand < <(candidates_of "${miss[@]}")
if ! compgen -G '/var/lib/apt/lists/*_Packages*' >/dev/null || ((${#cand[@]} < ${#miss[@]})); then
  echo "ensure_system: apt-get update (package lists missing or lacking ${miss[*]})" >&2
  apt_ update -qq || fail "apt-get update failed"
  updated=1
  mapfile -t cand < <(candidates_of "${miss[@]}")
fi
inst=() absent=()
for p in "${miss[@]}"; do
  if is_in "$p" "${cand[@]}"; then inst+=("$p")
  elif is_in "$p" "${req[@]}"; then absent+=("$p")
  else echo "ensure_system: optional $p is not in the archive, skipped" >&2; fi
done
((${#absent[@]} == 0)) || fail "not in the package lists: ${absent[*]}"
((${#inst[@]})) || exit 0

echo "ensure_system: installing ${inst[*]} (Debian packages, once)" >&2
if ! apt_ install -y -qq --no-install-recommends "${inst[@]}"; then
  ((updated == 0)) || fail "apt-get install ${inst[*]} failed"
  echo "ensure_system: install failed; apt-get update and once more" >&2
  apt_ update -qq || fail "apt-get update failed"
  apt_ install -y -qq --no-install-recommends "${inst[@]}" \
    || fail "apt-get install ${inst[*]} failed"
fi
mapfile -t left < <(missing_of "${inst[@]}")
((${#left[@]} == 0)) || fail "still not installed after apt-get: ${left[*]}"
echo "ensure_system: installed ${inst[*]}" >&2
