#!/usr/bin/env bash
# libFuzzer needs clang and its sanitizer/fuzzer runtime (Debian 12: clang and
# libclang-rt-<version>-dev, which plain `clang` does not pull in). Check that a fuzzer
# binary really links; if not and we are root, install what is missing, once; otherwise
# say what to install. Exit 0 only when `clang -fsanitize=fuzzer` works.
set -euo pipefail
links() {
  command -v clang >/dev/null || return 1
  local d; d=$(mktemp -d)
  printf '#include <stddef.h>\n#include <stdint.h>\nint LLVMFuzzerTestOneInput(const uint8_t *d, size_t n) { (void)d; (void)n; return 0; }\n' > "$d/t.c"
  clang -fsanitize=fuzzer,address,undefined "$d/t.c" -o "$d/t" >/dev/null 2>&1
  local rc=$?; rm -rf "$d"; return $rc
}
links && exit 0
if [[ $(id -u) -ne 0 ]]; then
  echo "fuzz: please install clang and its runtime (sudo apt-get install clang libclang-rt-dev)" >&2
  exit 1
fi
echo "fuzz: installing clang and its fuzzer runtime (Debian packages, once)" >&2
apt-get update -qq
command -v clang >/dev/null || apt-get install -y -qq clang >/dev/null
ver=$(clang --version | sed -n 's/.*clang version \([0-9]*\).*/\1/p' | head -1)
apt-get install -y -qq "libclang-rt-${ver}-dev" >/dev/null 2>&1 || true
links || { echo "fuzz: clang installed but -fsanitize=fuzzer still does not link" >&2; exit 1; }
