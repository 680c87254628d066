#!/usr/bin/env bash
# Builds libranger_can, its unit tests and the system suites in tests/ twice — with AddressSanitizer
# + UndefinedBehaviorSanitizer (build/asan) and with ThreadSanitizer (build/tsan) — and runs every
# CTest case that needs no kernel CAN support (label != vcan) in each. Any sanitizer report fails
# the run: the process halts at the first report (halt_on_error, -fno-sanitize-recover=all), and
# reports are also written to files so that one raised in a child process (the CLI, the virtual
# chassis) fails the run even when the test that spawned it ignored its exit status.
#
# Usage: scripts/test_sanitizers.sh [address|thread]...     (default: address thread)
# Environment: RANGER_JOBS (default 2), CXX (default: the system compiler), RANGER_RESULTS
#   (directory for JUnit reports asan.xml / tsan.xml; default build/test-results).
# With RANGER_SANITIZE_VCAN=1 the `vcan` suites of the ASan build also run, natively or in the
# qemu VM (scripts/run_vcan_tests.sh).
set -uo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
kinds=("$@")
[ ${#kinds[@]} -gt 0 ] || kinds=(address thread)
jobs=${RANGER_JOBS:-2}
results=${RANGER_RESULTS:-$root/build/test-results}
generator=()
command -v ninja >/dev/null && generator=(-G Ninja)
mkdir -p build "$results" && touch build/COLCON_IGNORE

# Flags shared by both builds. -O1 keeps the runs quick while stack traces stay exact; asserts
# stay on (no NDEBUG).
common_flags="-O1 -g -fno-omit-frame-pointer"

failed=()
for kind in "${kinds[@]}"; do
  case $kind in
    address)
      dir=build/asan
      flags="-fsanitize=address,undefined -fno-sanitize-recover=all"
      ;;
    thread)
      dir=build/tsan
      flags="-fsanitize=thread"
      ;;
    *) echo "test_sanitizers.sh: unknown sanitizer '$kind' (expected address or thread)" >&2; exit 2 ;;
  esac
  name=$(basename "$dir")
  echo "== $name: configure + build ($dir)"
  start=$SECONDS
  # RANGER_SANITIZE instruments libranger_can's directory; the system suites in tests/ are a
  # sibling directory, so the same flags also go in CMAKE_CXX_FLAGS to instrument them too.
  if ! cmake -S . -B "$dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Debug \
    -DRANGER_SANITIZE="$kind" -DRANGER_BUILD_BENCHMARKS=OFF -DRANGER_BUILD_TESTS=ON \
    -DCMAKE_CXX_FLAGS="$common_flags $flags" \
    -DCMAKE_EXE_LINKER_FLAGS="$flags" -DCMAKE_SHARED_LINKER_FLAGS="$flags" >/dev/null ||
    ! cmake --build "$dir" -j "$jobs"; then
    echo "== $name: BUILD FAILED"
    failed+=("$name")
    continue
  fi
  echo "== $name: built in $((SECONDS - start)) s"

  reports=$root/$dir/sanitizer-reports
  rm -rf "$reports" && mkdir -p "$reports"
  # log_path: every instrumented process writes its reports to $reports/<name>.<pid>.
  export ASAN_OPTIONS="halt_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1:strict_init_order=1:log_path=$reports/asan"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1:log_path=$reports/ubsan"
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:log_path=$reports/tsan"

  echo "== $name: ctest (label != vcan)"
  start=$SECONDS
  ctest --test-dir "$dir" -LE vcan --output-on-failure -j "$jobs" --timeout 300 \
    --output-junit "$results/$name.xml"
  rc=$?
  if [ "${RANGER_SANITIZE_VCAN:-0}" = 1 ] && [ "$kind" = address ] &&
    [ -x scripts/run_vcan_tests.sh ]; then
    echo "== $name: vcan suites"
    scripts/run_vcan_tests.sh "$dir" --junit "$results/$name-vcan.xml" || rc=1
  fi
  echo "== $name: tests ran in $((SECONDS - start)) s"

  shopt -s nullglob
  files=("$reports"/*)
  shopt -u nullglob
  if [ ${#files[@]} -gt 0 ]; then
    echo "== $name: ${#files[@]} SANITIZER REPORT(S):"
    for f in "${files[@]}"; do
      echo "---- $f"
      head -n 60 "$f"
    done
    rc=1
  fi
  unset ASAN_OPTIONS UBSAN_OPTIONS TSAN_OPTIONS
  if [ $rc -ne 0 ]; then
    echo "== $name: FAILED"
    failed+=("$name")
  else
    echo "== $name: ok, no sanitizer reports"
  fi
done

if [ ${#failed[@]} -gt 0 ]; then
  echo "test_sanitizers.sh: failed: ${failed[*]}"
  exit 1
fi
echo "test_sanitizers.sh: all clean (${kinds[*]})"
