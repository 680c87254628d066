#!/usr/bin/env bash
# Proof that a program can reuse libranger_can with nothing copied: installs the library from the
# build tree BUILD into a scratch prefix, builds examples/ against it with find_package alone,
# and drives a square on the virtual chassis.
#   examples/build_and_run.sh BUILD WORKDIR
set -euo pipefail
build=$1
work=$2
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/prefix" >/dev/null
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
cmake -S "$here" -B "$work/build" "${generator[@]}" -DCMAKE_PREFIX_PATH="$work/prefix" \
  -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" >/dev/null
"$work/build/drive_square" sim 0.5
