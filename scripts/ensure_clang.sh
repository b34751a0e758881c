#!/usr/bin/env bash
# libFuzzer needs clang and its sanitizer/fuzzer runtime (Debian 12: clang and
# libclang-rt-<version>-dev, which plain `clang` does not pull in). Check that a fuzzer
# binary really links; if not, install what is missing through scripts/ensure_system.sh
# (one lock for every apt-get of the project; root or sudo, else it says what to install).
# Exit 0 only when `clang -fsanitize=fuzzer` works.
set -euo pipefail
links() {
  command -v clang >/dev/null || return 1
  local d; d=$(mktemp -d)
  printf '#include <stddef.h>\n#include <stdint.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n' > "$d/t.c"
  local rc=0
  clang -fsanitize=fuzzer,address,undefined "$d/t.c" -o "$d/t" >/dev/null 2>&1 || rc=$?
  rm -rf "$d"; return $rc
}
links && exit 0
sys="$(dirname "$0")/ensure_system.sh"
"$sys" clang || { echo "fuzz: clang is needed (apt-get install clang libclang-rt-dev)" >&2; exit 1; }
ver=$(clang --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -1)
# optional: older Debian releases ship the runtime inside libclang-common-<version>-dev
"$sys" "libclang-rt-${ver}-dev?" || true
links || { echo "fuzz: clang installed but -fsanitize=fuzzer still does not link" >&2; exit 1; }
