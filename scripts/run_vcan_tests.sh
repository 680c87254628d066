#!/usr/bin/env bash
# Runs the CTest suites labelled `vcan` (real SocketCAN sockets on vcan0) of one or more build
# trees:
#   * natively, where this kernel has vcan and we are root (`modprobe vcan` is tried first);
#   * otherwise inside a throwaway qemu VM whose kernel has it (tests/vm/run_in_vm.sh), booted
#     once for every build tree given;
#   * if neither is possible: fails with a message saying what is missing. It never skips.
#
#   scripts/run_vcan_tests.sh BUILD_DIR [JUNIT_FILE | --junit JUNIT_FILE] [--native | --vm]
#                             [--and BUILD_DIR JUNIT_FILE]...
#
# JUnit XML goes to JUNIT_FILE (default BUILD_DIR/vcan-junit.xml); each further `--and` tree's to
# its own file, its suites run after the first's in the same VM (scripts/test.sh's vcan and
# ros_vcan stages: one boot). The exit status is ctest's (the first non-zero one of the trees).
# Each tree's wall time is printed ("run_vcan_tests: BUILD_DIR: ... in N s").
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
more=()  # further BUILD_DIR JUNIT pairs (--and)
mode="${RANGER_VCAN_MODE:-auto}"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --junit) junit="${2:?--junit needs a file}"; shift 2 ;;
    --and) more+=("${2:?--and needs BUILD_DIR JUNIT_FILE}" "${3:?--and needs BUILD_DIR JUNIT_FILE}"); shift 3 ;;
    --native) mode=native; shift ;;
    --vm) mode=vm; shift ;;
    -h|--help) sed -n '2,17p' "$0"; exit 0 ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *)
      if [[ -z "$build_dir" ]]; then build_dir="$1"
      elif [[ -z "$junit" ]]; then junit="$1"
      else die "unexpected argument '$1' (see --help)"
      fi
      shift ;;
  esac
done
[[ -n "$build_dir" ]] || die "usage: $0 BUILD_DIR [JUNIT_FILE] [--native | --vm] [--and BUILD_DIR JUNIT_FILE]..."
command -v ctest >/dev/null || die "ctest not found: apt-get install -y cmake"
builds=()
junits=()
add_tree() {  # build_dir junit
  local dir=$1 out=$2
  [[ -f "$dir/CTestTestfile.cmake" ]] ||
    die "'$dir' is not a configured build tree (cmake -S . -B $dir && cmake --build $dir)"
  dir="$(cd "$dir" && pwd)"
  out="${out:-$dir/vcan-junit.xml}"
  mkdir -p "$(dirname "$out")"
  out="$(cd "$(dirname "$out")" && pwd)/$(basename "$out")"
  local count
  count="$(ctest --test-dir "$dir" -L vcan -N 2>/dev/null | sed -n 's/^Total Tests: *//p')"
  [[ "${count:-0}" -gt 0 ]] ||
    die "no tests labelled vcan in $dir: build the test targets first (cmake --build $dir)"
  say "$count vcan tests in $dir"
  builds+=("$dir")
  junits+=("$out")
}
add_tree "$build_dir" "$junit"
for ((i = 0; i < ${#more[@]}; i += 2)); do add_tree "${more[$i]}" "${more[$((i + 1))]}"; done

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

# One shell command that runs every tree's suites in turn, each tree's status and wall time in
# $status_dir (written from inside the VM too: the host's root is its root).
status_dir="${builds[0]}/vcan-status"
rm -rf "$status_dir" && mkdir -p "$status_dir"
run_all=""
for i in "${!builds[@]}"; do
  rm -f "${junits[$i]}"
  cmd=(ctest --test-dir "${builds[$i]}" -L vcan --output-on-failure --no-tests=error
       --output-junit "${junits[$i]}")
  run_all+="s=\$(date +%s); $(printf '%q ' "${cmd[@]}"); echo \$? \$((\$(date +%s) - s)) > $(printf '%q' "$status_dir/$i"); "
done
run_all+="exit 0"
started=$(date +%s)
set +e
case "$mode" in
  native|auto)
    reason="$(native_unavailable_reason)"
    if [[ -z "$reason" ]]; then
      say "running natively on vcan0: ${builds[*]}"
      bash -c "$run_all"
    elif [[ "$mode" == native ]]; then
      die "native run requested but vcan is unavailable: $reason"
    else
      say "vcan is not usable natively ($reason): running the vcan tests inside a VM (one boot for ${#builds[@]} build tree(s))"
      mode=vm
    fi
    ;;
  vm) ;;
  *) die "RANGER_VCAN_MODE must be native, vm or auto, not '$mode'" ;;
esac
if [[ "$mode" == vm ]]; then
  "$repo_root/tests/vm/run_in_vm.sh" --cache-dir "${builds[0]}/vm" --timeout "${RANGER_VM_TIMEOUT:-1800}" \
    "$run_all"
  vm_status=$?
  [[ "$vm_status" != 125 ]] || die "the VM could not run the vcan tests (see above); they did NOT run"
fi
set -e

status=0
for i in "${!builds[@]}"; do
  tree_status=1 seconds="?"
  read -r tree_status seconds 2>/dev/null < "$status_dir/$i" || true
  [[ -s "${junits[$i]}" ]] ||
    die "ctest wrote no JUnit report to ${junits[$i]} (status $tree_status): the vcan tests of ${builds[$i]} did not run"
  summary="$(tr '\n' ' ' < "${junits[$i]}" | grep -o '<testsuite [^>]*' | grep -o -E '(tests|failures|disabled|skipped)="[0-9]+"' | tr '\n' ' ' || true)"
  say "${builds[$i]}: status $tree_status in ${seconds} s; JUnit: ${junits[$i]} ($summary)"
  [[ "$status" != 0 || "$tree_status" == 0 ]] || status=$tree_status
done
say "done in $(( $(date +%s) - started ))s, status $status"
exit "$status"
