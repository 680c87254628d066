#!/usr/bin/env bash
# CTest entry of node_vcan.test (label `vcan`): runs the rostest when vcan0 exists, otherwise
# exits 77, which CTest reports as "not run" (SKIP_RETURN_CODE), never as passed.
#   run_vcan_rostest.sh RESULTS_BASE_DIR
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
results="${1:?usage: $0 RESULTS_BASE_DIR}"
if ! ip link show vcan0 >/dev/null 2>&1; then
  echo "vcan0 does not exist here: node_vcan.test not run (scripts/run_vcan_tests.sh runs it in a VM)"
  # Results of an earlier run (e.g. in the VM) describe that run, not this one.
  rm -f "$results/ranger_base/rostest-test_node_vcan.xml" "$results/ranger_base/rosunit-node_vcan.xml"
  exit 77
fi
export ROS_HOME="${ROS_HOME:-$(mktemp -d /tmp/ranger-vcan-roshome.XXXXXX)}" ROS_HOSTNAME=localhost
exec rostest --pkgdir="$here/../.." --package=ranger_base --results-filename test_node_vcan.xml \
  --results-base-dir "$results" "$here/node_vcan.test"
