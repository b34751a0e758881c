#!/usr/bin/env bash
# libFuzzer needs clang (Debian: clang). Install it once if missing and we are root;
# otherwise say what to install.
set -euo pipefail
command -v clang >/dev/null && exit 0
if [[ $(id -u) -eq 0 ]]; then
  echo "fuzz: installing clang (Debian package, once)" >&2
  apt-get update -qq && apt-get install -y -qq clang >/dev/null
else
  echo "fuzz: please install clang (sudo apt-get install clang)" >&2
  exit 1
fi
