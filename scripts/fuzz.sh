#!/usr/bin/env bash
# Builds every libFuzzer target (libranger_can/fuzz/fuzz_*.cpp) with clang, ASan and UBSan in
# build/fuzz and runs each for a bounded time, starting from the committed seed corpus
# (libranger_can/fuzz/corpus/<target>/). Fails when any target finds a crash, a sanitizer report,
# a timeout or an out-of-memory, and prints the reproducer's path and the command to replay it.
#
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]
#   SECONDS  total time budget, split evenly across the targets (default 60: 15 s each for four
#            targets, the CI setting). Each target gets at least 5 s.
#   TARGET   run only these targets (e.g. fuzz_decode); default: all.
# Environment: RANGER_JOBS (build parallelism, default 2), RANGER_FUZZ_ARGS (extra libFuzzer
#   flags, e.g. "-jobs=2 -workers=2"). Running longer: see docs/HARDENING.md.
#
# New inputs that reach new coverage are kept in build/fuzz/corpus/<target>/ (not committed, so
# the repository's seed corpus stays small); crashes go to build/fuzz/artifacts/<target>/.
set -uo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=build_flags.sh
source scripts/build_flags.sh
root=$(pwd)
total=${1:-60}
shift || true
jobs=${RANGER_JOBS:-2}
build=$root/build/fuzz
seeds=$root/libranger_can/fuzz/corpus

if ! [[ $total =~ ^[0-9]+$ ]] || [ "$total" -lt 1 ]; then
  echo "fuzz.sh: SECONDS must be a positive integer, got '$total'" >&2
  exit 2
fi
if ! command -v clang++ >/dev/null; then
  echo "fuzz.sh: clang++ not found (scripts/setup.sh test installs clang and libclang-rt-14-dev)" >&2
  exit 1
fi

targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  for src in libranger_can/fuzz/fuzz_*.cpp; do
    [ -e "$src" ] && targets+=("$(basename "$src" .cpp)")
  done
fi
if [ ${#targets[@]} -eq 0 ]; then
  echo "fuzz.sh: no fuzz targets in libranger_can/fuzz/" >&2
  exit 1
fi

mkdir -p build && touch build/COLCON_IGNORE
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
echo "== fuzz: build ${targets[*]} (clang, ASan+UBSan, $build)"
start=$SECONDS
# libranger_can on its own (not the repository root): the fuzzers need neither the unit tests
# nor the system suites.
CC=clang CXX=clang++ cmake -S libranger_can -B "$build" "${generator[@]}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$ranger_relwithdebinfo_flags" \
  -DRANGER_BUILD_FUZZERS=ON -DRANGER_BUILD_TESTS=OFF \
  -DRANGER_BUILD_BENCHMARKS=OFF >/dev/null || { echo "fuzz.sh: configure failed" >&2; exit 1; }
cmake --build "$build" -j "$jobs" --target "${targets[@]}" ||
  { echo "fuzz.sh: build failed" >&2; exit 1; }
echo "== fuzz: built in $((SECONDS - start)) s"

per_target=$((total / ${#targets[@]}))
[ "$per_target" -ge 5 ] || per_target=5
# Each libFuzzer run: halt at the first report, 10 s per input is a hang, 2 GB is an OOM.
export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"

failed=()
for t in "${targets[@]}"; do
  corpus=$build/corpus/$t
  artifacts=$build/artifacts/$t/
  rm -rf "$artifacts"
  mkdir -p "$corpus" "$artifacts" "$seeds/$t"
  dict=()
  [ -f "libranger_can/fuzz/$t.dict" ] && dict=(-dict="libranger_can/fuzz/$t.dict")
  echo
  echo "== fuzz: $t for $per_target s (seeds: libranger_can/fuzz/corpus/$t)"
  log=$build/$t.log
  # The first corpus directory receives new inputs; the seed directory is only read.
  # shellcheck disable=SC2086
  "$build/fuzzers/$t" "$corpus" "$seeds/$t" "${dict[@]}" -max_total_time="$per_target" \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
    -artifact_prefix="$artifacts" ${RANGER_FUZZ_ARGS:-} >"$log" 2>&1
  rc=$?
  # The summary: the last status line and libFuzzer's final statistics.
  grep -E '^#[0-9]+[[:space:]]+(DONE|pulse)' "$log" | tail -n 1
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|new_units_added|peak_rss_mb)' "$log"
  if [ $rc -ne 0 ]; then
    failed+=("$t")
    echo "== fuzz: $t FAILED (exit $rc); the report:"
    grep -nE 'ERROR: |SUMMARY: |runtime error|property violated|Test unit written to|deadly signal|timeout' "$log" |
      head -n 20
    echo "   full log: $log"
    for a in "$artifacts"*; do
      [ -f "$a" ] || continue
      echo "   reproducer: $a"
      echo "   replay:     $build/fuzzers/$t $a"
    done
  else
    echo "== fuzz: $t ok"
  fi
done

echo
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz.sh: crashes found in: ${failed[*]} (reproducers under $build/artifacts/)"
  exit 1
fi
echo "fuzz.sh: ${#targets[@]} targets, $per_target s each, no crash"
