#!/usr/bin/env bash
# Runs the CTest suites labelled `vcan` (real SocketCAN sockets on vcan0) of a build tree:
#   * natively, where this kernel has vcan and we are root (`modprobe vcan` is tried first);
#   * otherwise inside a throwaway qemu VM whose kernel has it (tests/vm/run_in_vm.sh);
#   * if neither is possible: fails with a message saying what is missing. It never skips.
#
#   scripts/run_vcan_tests.sh BUILD_DIR [JUNIT_FILE | --junit JUNIT_FILE] [--native | --vm]
#
# JUnit XML goes to JUNIT_FILE (default BUILD_DIR/vcan-junit.xml); the exit status is ctest's.
# RANGER_VCAN_MODE=native|vm|auto does what --native/--vm do.
set -euo pipefail

die() {
  echo "run_vcan_tests: ERROR: $*" >&2
  exit 1
}
say() { echo "run_vcan_tests: $*" >&2; }

repo_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build_dir=""
junit=""
mode="${RANGER_VCAN_MODE:-auto}"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --junit) junit="${2:?--junit needs a file}"; shift 2 ;;
    --native) mode=native; shift ;;
    --vm) mode=vm; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *)
      if [[ -z "$build_dir" ]]; then build_dir="$1"
      elif [[ -z "$junit" ]]; then junit="$1"
      else die "unexpected argument '$1' (see --help)"
      fi
      shift ;;
  esac
done
[[ -n "$build_dir" ]] || die "usage: $0 BUILD_DIR [JUNIT_FILE] [--native | --vm]"
[[ -f "$build_dir/CTestTestfile.cmake" ]] ||
  die "'$build_dir' is not a configured build tree (cmake -S . -B $build_dir && cmake --build $build_dir)"
build_dir="$(cd "$build_dir" && pwd)"
junit="${junit:-$build_dir/vcan-junit.xml}"
mkdir -p "$(dirname "$junit")"
junit="$(cd "$(dirname "$junit")" && pwd)/$(basename "$junit")"
command -v ctest >/dev/null || die "ctest not found: apt-get install -y cmake"

count="$(ctest --test-dir "$build_dir" -L vcan -N 2>/dev/null | sed -n 's/^Total Tests: *//p')"
[[ "${count:-0}" -gt 0 ]] ||
  die "no tests labelled vcan in $build_dir: build the test targets first (cmake --build $build_dir)"
say "$count vcan tests in $build_dir"

# Why vcan cannot be used natively, or nothing when it can (creating vcan0 if needed).
native_unavailable_reason() {
  [[ "$(id -u)" == 0 ]] || { echo "not root (the tests take vcan0 down and up)"; return; }
  command -v ip >/dev/null || { echo "'ip' not found (apt-get install -y iproute2)"; return; }
  modprobe vcan >/dev/null 2>&1 || true
  modprobe can-raw >/dev/null 2>&1 || true
  modprobe sch_plug >/dev/null 2>&1 || true
  if ! ip link show vcan0 >/dev/null 2>&1; then
    ip link add dev vcan0 type vcan >/dev/null 2>&1 ||
      { echo "this kernel cannot create vcan interfaces ('ip link add dev vcan0 type vcan' failed)"; return; }
  fi
  ip link set vcan0 up >/dev/null 2>&1 || { echo "cannot bring vcan0 up"; return; }
  local py
  py="$(command -v python3 || true)"
  if [[ -n "$py" ]] && ! "$py" -c 'import socket; socket.socket(socket.AF_CAN, socket.SOCK_RAW, socket.CAN_RAW)' 2>/dev/null; then
    echo "vcan0 exists but CAN_RAW sockets cannot be opened (modprobe can-raw)"
  fi
}

ctest_cmd=(ctest --test-dir "$build_dir" -L vcan --output-on-failure --no-tests=error
           --output-junit "$junit")
rm -f "$junit"
started=$(date +%s)
set +e
case "$mode" in
  native|auto)
    reason="$(native_unavailable_reason)"
    if [[ -z "$reason" ]]; then
      say "running natively on vcan0: ${ctest_cmd[*]}"
      "${ctest_cmd[@]}"
      status=$?
    elif [[ "$mode" == native ]]; then
      die "native run requested but vcan is unavailable: $reason"
    else
      say "vcan is not usable natively ($reason): running the vcan tests inside a VM"
      mode=vm
    fi
    ;;
  vm) ;;
  *) die "RANGER_VCAN_MODE must be native, vm or auto, not '$mode'" ;;
esac
if [[ "$mode" == vm ]]; then
  "$repo_root/tests/vm/run_in_vm.sh" --cache-dir "$build_dir/vm" --timeout "${RANGER_VM_TIMEOUT:-1800}" \
    "$(printf '%q ' "${ctest_cmd[@]}")"
  status=$?
  [[ "$status" != 125 ]] || die "the VM could not run the vcan tests (see above); they did NOT run"
fi
set -e

[[ -s "$junit" ]] || die "ctest wrote no JUnit report to $junit (status $status): the vcan tests did not run"
summary="$(tr '\n' ' ' < "$junit" | grep -o '<testsuite [^>]*' | grep -o -E '(tests|failures|disabled|skipped)="[0-9]+"' | tr '\n' ' ' || true)"
say "done in $(( $(date +%s) - started ))s, status $status; JUnit: $junit ($summary)"
exit "$status"
