#!/usr/bin/env bash
# One-time set-up of a computer for the RANGER's USB-to-CAN adapter (manual 3.4): loads gs_usb at
# every boot, installs can-utils (candump, cansend) when missing, then brings the interface up
# with bringup_can2usb.bash.
#   rosrun ranger_bringup setup_can2usb.bash [INTERFACE] [BITRATE]     (default can0 500000)
set -euo pipefail

here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
modules_load_dir=${RANGER_MODULES_LOAD_DIR:-/etc/modules-load.d}  # tests use a temporary dir

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  if ! command -v sudo >/dev/null; then
    echo "setup_can2usb: not root and no sudo: run as root" >&2
    exit 1
  fi
  sudo=(sudo)
fi

if [ ! -f "$modules_load_dir/gs_usb.conf" ]; then
  echo "setup_can2usb: loading gs_usb at boot ($modules_load_dir/gs_usb.conf)"
  echo gs_usb | "${sudo[@]}" tee "$modules_load_dir/gs_usb.conf" >/dev/null
fi
if ! command -v candump >/dev/null; then
  echo "setup_can2usb: installing can-utils"
  "${sudo[@]}" apt-get install -y can-utils
fi
exec "$here/bringup_can2usb.bash" "$@"
