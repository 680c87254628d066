#!/usr/bin/env bash
# Brings up the USB-to-CAN adapter for the RANGER (manual 3.4): loads gs_usb and sets the
# interface up at 500 kbit/s. Run once after the adapter is plugged in / powered:
#   rosrun ranger_bringup bringup_can2usb.bash [INTERFACE] [BITRATE]     (default can0 500000)
# Needs root for modprobe and ip; uses sudo when not root.
# Exit codes: 0 up, 1 no adapter / no interface / failed, 2 usage error.
set -euo pipefail

iface=${1-can0}
bitrate=${2-500000}
sysfs_net=${RANGER_SYSFS_NET:-/sys/class/net}  # tests point this at a fake tree

fail() {
  echo "bringup_can2usb: $*" >&2
  exit 1
}

case "$bitrate" in
  '' | *[!0-9]*)
    echo "bringup_can2usb: bitrate must be a number of bit/s, got '$bitrate'" >&2
    exit 2
    ;;
esac
if [ "$#" -gt 2 ] || [[ ! "$iface" =~ ^[A-Za-z0-9_.-]{1,15}$ ]]; then
  echo "usage: bringup_can2usb.bash [INTERFACE] [BITRATE]   (default: can0 500000)" >&2
  exit 2
fi

sudo=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || fail "not root and sudo is not installed: run this as root"
  sudo=(sudo)
fi
command -v ip >/dev/null || fail "'ip' not found: install iproute2"

# The adapter (CANable / candleLight, as shipped with the RANGER) uses the gs_usb driver.
if [ ! -d "$sysfs_net/$iface" ]; then
  command -v modprobe >/dev/null || fail "'modprobe' not found: install kmod"
  if ! "${sudo[@]}" modprobe gs_usb; then
    fail "cannot load the gs_usb kernel module: this kernel has no CAN USB support (on a VM" \
      "or a container, use the virtual chassis instead:" \
      "roslaunch ranger_bringup ranger_minimal.launch sim:=true)"
  fi
  # The interface appears a moment after the driver binds to the adapter.
  for _ in 1 2 3 4 5 6 7 8 9 10; do
    [ -d "$sysfs_net/$iface" ] && break
    sleep 0.2
  done
fi
if [ ! -d "$sysfs_net/$iface" ]; then
  present=()
  for dev in "$sysfs_net"/*; do
    [ "$(cat "$dev/type" 2>/dev/null)" = 280 ] && present+=("$(basename "$dev")")
  done
  hint="no CAN interface is present"
  [ ${#present[@]} -gt 0 ] && hint="CAN interfaces present: ${present[*]}"
  fail "no CAN interface '$iface': is the USB-to-CAN adapter plugged in (see lsusb, dmesg)?" \
    "($hint)"
fi
if [ "$(cat "$sysfs_net/$iface/type" 2>/dev/null)" != 280 ]; then
  fail "'$iface' is not a CAN interface"
fi

# Setting the bitrate needs the interface down; it may already be up from an earlier run.
"${sudo[@]}" ip link set "$iface" down
"${sudo[@]}" ip link set "$iface" type can bitrate "$bitrate" ||
  fail "could not set bitrate $bitrate on $iface"
"${sudo[@]}" ip link set "$iface" up || fail "could not bring $iface up"
echo "bringup_can2usb: $iface is up at $bitrate bit/s. Check the chassis with: candump $iface"
