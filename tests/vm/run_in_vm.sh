#!/usr/bin/env bash
# Runs one shell command inside a throwaway qemu VM whose kernel has SocketCAN + vcan, for hosts
# whose own kernel has no CAN support (see docs and ../shared/reference on why and how).
#
#   tests/vm/run_in_vm.sh [--timeout SEC] [--cache-dir DIR] [--] "<command>"
#
# How: a tiny initramfs (static busybox + the kernel modules for virtio/9p/CAN/vcan/sch_plug of
# the installed Debian kernel) boots under qemu TCG, mounts the host's root filesystem over 9p
# (read-write, so results come back), creates vcan0 and vcan1, chroots into the host root and runs
# the command from the current directory with the current environment. The command's output is
# streamed here while it runs; its exit status becomes this script's exit status.
#
# Exit status: the command's, or 125 when the VM itself could not do its job (qemu or kernel
# missing, boot failure, timeout, no result) - always with a message saying which.
#
# Environment: RANGER_VM_KERNEL (path to a vmlinuz; default: newest /boot/vmlinuz-* with matching
# modules), RANGER_VM_TIMEOUT (seconds, default 1800), RANGER_VM_CACHE_DIR, RANGER_VM_MEMORY (MiB,
# default 2048), RANGER_VM_CPUS (default 2), RANGER_VM_VERBOSE=1 (show the kernel console).
set -euo pipefail

readonly HARNESS_FAILURE=125
die() {
  echo "run_in_vm: ERROR: $*" >&2
  exit "$HARNESS_FAILURE"
}

timeout_s="${RANGER_VM_TIMEOUT:-1800}"
cache_dir="${RANGER_VM_CACHE_DIR:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/ranger_can_vm}"
while [[ $# -gt 0 ]]; do
  case "$1" in
    --timeout) timeout_s="${2:?--timeout needs a value}"; shift 2 ;;
    --cache-dir) cache_dir="${2:?--cache-dir needs a value}"; shift 2 ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    --) shift; break ;;
    -*) die "unknown option '$1' (see --help)" ;;
    *) break ;;
  esac
done
[[ $# -eq 1 ]] || die "expected exactly one command string, e.g. $0 \"ctest -L vcan\" (got $# arguments)"
command_string="$1"
[[ "$timeout_s" =~ ^[0-9]+$ && "$timeout_s" -gt 0 ]] || die "--timeout must be a positive number of seconds, got '$timeout_s'"

# ---- prerequisites, each with the package that provides it -----------------------------------
need() { command -v "$1" >/dev/null 2>&1 || die "'$1' not found: apt-get install -y $2"; }
need qemu-system-x86_64 qemu-system-x86
need cpio cpio
need gzip gzip
need modinfo kmod
need timeout coreutils
busybox_bin=""
for candidate in /bin/busybox /usr/bin/busybox; do
  if [[ -x "$candidate" ]] && ! ldd "$candidate" >/dev/null 2>&1; then busybox_bin="$candidate"; break; fi
done
[[ -n "$busybox_bin" ]] || die "no statically linked busybox found: apt-get install -y busybox-static"

# ---- the kernel: the newest installed one that ships vcan --------------------------------------
pick_kernel() {
  if [[ -n "${RANGER_VM_KERNEL:-}" ]]; then
    echo "$RANGER_VM_KERNEL"
    return
  fi
  local k
  for k in $(ls -1 /boot/vmlinuz-* 2>/dev/null | sort -rV); do
    local v="${k#/boot/vmlinuz-}"
    if [[ -n "$(find "/lib/modules/$v/kernel" -name 'vcan.ko*' -print -quit 2>/dev/null)" ]]; then
      echo "$k"
      return
    fi
  done
}
kernel="$(pick_kernel)"
[[ -n "$kernel" ]] || die "no kernel with the vcan module under /boot and /lib/modules: apt-get install -y linux-image-amd64"
[[ -e "$kernel" ]] || die "kernel image '$kernel' does not exist"
[[ -r "$kernel" ]] || die "kernel image '$kernel' is not readable by $(id -un) (try as root)"
kernel_version="${kernel##*/vmlinuz-}"
[[ -d "/lib/modules/$kernel_version" ]] || die "no /lib/modules/$kernel_version for kernel '$kernel'"

# ---- the initramfs (cached: rebuilt only when the kernel or this script changes) ---------------
# Modules wanted explicitly; their dependencies are added (deps first) from modinfo.
readonly WANTED_MODULES="virtio_pci 9pnet_virtio 9p can-raw vcan sch_plug"
module_file() {  # path of a module's .ko for the VM kernel (works without modules.dep too)
  local name="$1" f
  f="$(modinfo -k "$kernel_version" -F filename "$name" 2>/dev/null)" && [[ -f "$f" ]] && { echo "$f"; return; }
  for f in "$name" "${name//-/_}" "${name//_/-}"; do
    f="$(find "/lib/modules/$kernel_version/kernel" -name "$f.ko*" -print -quit 2>/dev/null)"
    [[ -n "$f" ]] && { echo "$f"; return; }
  done
  return 1
}
resolve_modules() {  # prints module names in load order, dependencies first, each once
  local -A seen=()
  local order=()
  visit() {
    local name="$1" file deps dep
    [[ -n "${seen[$name]:-}" ]] && return
    seen[$name]=1
    file="$(module_file "$name")" || die "module '$name' not found for kernel $kernel_version"
    deps="$(modinfo -F depends "$file")" || die "cannot read the dependencies of $file"
    for dep in ${deps//,/ }; do visit "$dep"; done
    order+=("$name")
  }
  local m
  for m in $WANTED_MODULES; do visit "$m"; done
  printf '%s\n' "${order[@]}"
}

# /init of the guest. Kept in this script so the cache key covers it.
read -r -d '' GUEST_INIT <<'INIT_EOF' || true
#!/bin/busybox sh
/bin/busybox --install -s /bin
export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev
say() { echo "ranger-vm: $*" > /dev/console; }
halt() { sync; poweroff -f; sleep 5; }
for m in $(cat /modules/order); do
  insmod "/modules/$m.ko" || { say "insmod $m failed"; halt; }
done
mkdir -p /host
mount -t 9p -o trans=virtio,version=9p2000.L,msize=512000 hostroot /host ||
  { say "cannot mount the host root over 9p"; halt; }
run_dir=$(sed -n 's/.*ranger\.run=\([^ ]*\).*/\1/p' /proc/cmdline)
[ -f "/host$run_dir/guest.sh" ] || { say "no /host$run_dir/guest.sh"; halt; }
hostname localhost
ip link set lo up
for dev in vcan0 vcan1; do
  { ip link add dev $dev type vcan && ip link set $dev up; } > "/host$run_dir/vcan-$dev.log" 2>&1 ||
    say "could not create $dev (see $run_dir/vcan-$dev.log)"
done
mount -t proc proc /host/proc
mount -t sysfs sysfs /host/sys
mount -o bind /dev /host/dev
mkdir -p /dev/pts /dev/shm
mount -t devpts devpts /host/dev/pts
mount -t tmpfs tmpfs /host/dev/shm
chroot /host /bin/bash "$run_dir/guest.sh"
say "guest finished"
halt
INIT_EOF

modules="$(resolve_modules)"
cache_key="$( { echo "$kernel_version"; echo "$modules"; echo "$GUEST_INIT"; } | sha256sum | cut -c1-16)"
mkdir -p "$cache_dir" || die "cannot create cache directory '$cache_dir'"
initramfs="$cache_dir/initramfs-$kernel_version-$cache_key.cpio.gz"
if [[ ! -s "$initramfs" ]]; then
  staging="$(mktemp -d "$cache_dir/staging.XXXXXX")"
  trap 'rm -rf "$staging"' EXIT
  mkdir -p "$staging"/{bin,dev,proc,sys,host,modules}
  cp "$busybox_bin" "$staging/bin/busybox"
  printf '%s\n' "$GUEST_INIT" > "$staging/init"
  chmod 755 "$staging/init"
  : > "$staging/modules/order"
  for m in $modules; do
    src="$(module_file "$m")"
    case "$src" in  # busybox insmod wants plain .ko files
      *.ko) cp "$src" "$staging/modules/$m.ko" ;;
      *.ko.xz) xz -dc "$src" > "$staging/modules/$m.ko" ;;
      *.ko.zst) zstd -dcq "$src" > "$staging/modules/$m.ko" ;;
      *.ko.gz) gzip -dc "$src" > "$staging/modules/$m.ko" ;;
      *) die "unexpected module file '$src'" ;;
    esac
    echo "$m" >> "$staging/modules/order"
  done
  (cd "$staging" && find . -print0 | cpio --null -o -H newc --quiet | gzip -1) > "$initramfs.tmp"
  mv "$initramfs.tmp" "$initramfs"
  rm -rf "$staging"
  trap - EXIT
  echo "run_in_vm: built $initramfs (modules: $(echo $modules))" >&2
fi

# ---- the run directory: on the host filesystem, so the guest writes results straight back -----
run_dir="$(mktemp -d "${TMPDIR:-/tmp}/ranger_vm_run.XXXXXX")"
[[ "$run_dir" =~ ^[A-Za-z0-9/._-]+$ ]] || die "run directory '$run_dir' has characters the kernel command line cannot carry; set TMPDIR"
keep_run_dir="${RANGER_VM_KEEP_RUN_DIR:-0}"
cleanup() { [[ "$keep_run_dir" == 1 ]] || rm -rf "$run_dir"; }
trap cleanup EXIT
mkdir -p "$run_dir/home"
printf '%s\n' "$command_string" > "$run_dir/command.sh"
# The caller's environment, minus what belongs to this host session only.
export -p | grep -v -E '^declare -x (HOSTNAME|PWD|OLDPWD|SHLVL|TERM|DISPLAY|XAUTHORITY|SSH_[A-Z_]*|DBUS_[A-Z_]*|XDG_RUNTIME_DIR|SHELLOPTS|BASHOPTS|BASH_[A-Z_]*)=' > "$run_dir/env.sh" || true
printf '%s\n' "$PWD" > "$run_dir/cwd"
cat > "$run_dir/guest.sh" <<GUEST_EOF
#!/bin/bash
# Generated by run_in_vm.sh: runs inside the VM, chrooted into the host root.
run="$run_dir"
(
  . "\$run/env.sh"
  export HOME="\$run/home" TERM=dumb ROS_HOSTNAME=localhost ROS_MASTER_URI=http://localhost:11311
  cwd="\$(cat "\$run/cwd")"
  cd -- "\$cwd" || { echo "run_in_vm: cannot cd to '\$cwd' inside the VM"; exit 125; }
  exec /bin/bash "\$run/command.sh"
) > "\$run/output.log" 2>&1 < /dev/null
echo \$? > "\$run/exit_code.tmp"
mv "\$run/exit_code.tmp" "\$run/exit_code"
sync
GUEST_EOF
: > "$run_dir/output.log"

echo "run_in_vm: kernel $kernel_version, qemu TCG, timeout ${timeout_s}s, command: $command_string" >&2
started=$(date +%s)
set +e
timeout --kill-after=15 "$timeout_s" qemu-system-x86_64 \
  -accel tcg -cpu max -m "${RANGER_VM_MEMORY:-2048}" -smp "${RANGER_VM_CPUS:-2}" \
  -nographic -no-reboot -monitor none -serial stdio -nodefaults \
  -kernel "$kernel" -initrd "$initramfs" \
  -append "console=ttyS0 panic=-1 loglevel=3 ranger.run=$run_dir" \
  -virtfs "local,path=/,mount_tag=hostroot,security_model=none,multidevs=remap" \
  < /dev/null > "$run_dir/console.log" 2>&1 &
qemu_pid=$!
# Interrupted (Ctrl-C, CI cancel): take the VM down with us.
trap 'kill "$qemu_pid" 2>/dev/null; wait "$qemu_pid" 2>/dev/null; die "interrupted; the VM was stopped"' INT TERM HUP
# Stream the command's output while the VM runs (the guest writes it straight to our filesystem).
tail -n +1 -F --pid="$qemu_pid" "$run_dir/output.log" 2>/dev/null &
tail_pid=$!
wait "$qemu_pid"
qemu_status=$?
wait "$tail_pid" 2>/dev/null
set -e
elapsed=$(( $(date +%s) - started ))

if [[ "${RANGER_VM_VERBOSE:-0}" == 1 ]]; then
  echo "---- VM console ----" >&2
  cat "$run_dir/console.log" >&2
fi
if [[ ! -f "$run_dir/exit_code" ]]; then
  if [[ "$qemu_status" == 124 || "$qemu_status" == 137 ]]; then
    echo "run_in_vm: ERROR: the VM did not finish within ${timeout_s}s and was killed" >&2
  else
    echo "run_in_vm: ERROR: the VM stopped (qemu status $qemu_status) without writing a result" >&2
  fi
  echo "---- last lines of the VM console ($run_dir/console.log) ----" >&2
  tail -n 40 "$run_dir/console.log" >&2
  keep_run_dir=1
  die "no result from the VM; run directory kept at $run_dir"
fi
status="$(cat "$run_dir/exit_code")"
[[ "$status" =~ ^[0-9]+$ ]] || die "unreadable exit code '$status' in $run_dir/exit_code"
echo "run_in_vm: command exited with status $status (VM run took ${elapsed}s)" >&2
exit "$status"
