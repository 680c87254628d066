#!/usr/bin/env bash
# The cost of a thread's wake-ups in the vendor-bench VM, against `ranger_can sim vcan0` (the
# feedback flowing as in the bench): scripts/wake_floor.cpp in each mode, 15 s each.
#   scripts/wake_floor.sh            builds it (g++) and runs it in the qemu VM
# Needs install/ (scripts/build.sh) for the simulator.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "${1:-}" != --guest ]; then
  mkdir -p build
  g++ -O2 -std=c++17 -o build/wake_floor scripts/wake_floor.cpp
  exec tests/vm/run_in_vm.sh --timeout 600 -- "bash scripts/wake_floor.sh --guest"
fi
install/ranger_can/bin/ranger_can sim vcan0 --no-stdin >/dev/null 2>&1 &
sim=$!
trap 'kill $sim 2>/dev/null' EXIT
sleep 2
for mode in idle clock send sendrecv work; do build/wake_floor "$mode" 15; done
