"""bringup_can2usb.bash / setup_can2usb.bash against stand-ins for modprobe, ip and sudo and a
fake /sys/class/net: the commands they run, and the clear errors when the adapter is missing."""

import os
import stat
import subprocess

import pytest

SCRIPTS = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "scripts")
BRINGUP = os.path.join(SCRIPTS, "bringup_can2usb.bash")
SETUP = os.path.join(SCRIPTS, "setup_can2usb.bash")
ARPHRD_CAN = "280"


def write_exe(path, text):
    path.write_text("#!/bin/bash\n" + text)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)


@pytest.fixture
def fake(tmp_path):
    """bin/ with logging stand-ins, net/ as /sys/class/net. MODPROBE_CREATES=<iface> makes the
    fake modprobe 'bind' an adapter; MODPROBE_FAILS=1 makes it fail."""
    bin_dir, net = tmp_path / "bin", tmp_path / "net"
    bin_dir.mkdir()
    net.mkdir()
    log = tmp_path / "calls.log"
    write_exe(bin_dir / "sudo", 'echo "sudo $*" >> "$CALLS"; exec "$@"\n')
    write_exe(bin_dir / "ip", 'echo "ip $*" >> "$CALLS"\n')
    write_exe(bin_dir / "candump", "exit 0\n")
    write_exe(bin_dir / "modprobe", '''echo "modprobe $*" >> "$CALLS"
[ -n "${MODPROBE_FAILS:-}" ] && { echo "modprobe: FATAL: Module gs_usb not found" >&2; exit 1; }
if [ -n "${MODPROBE_CREATES:-}" ]; then
  mkdir -p "$RANGER_SYSFS_NET/$MODPROBE_CREATES"
  echo 280 > "$RANGER_SYSFS_NET/$MODPROBE_CREATES/type"
fi
exit 0
''')
    write_exe(bin_dir / "sleep", "exit 0\n")  # the wait for the interface, without waiting

    class Fake:
        def add_interface(self, name, kind=ARPHRD_CAN):
            (net / name).mkdir()
            (net / name / "type").write_text(kind + "\n")

        def run(self, script, *args, **env):
            environment = dict(os.environ, PATH=f"{bin_dir}:/usr/bin:/bin", CALLS=str(log),
                               RANGER_SYSFS_NET=str(net), **env)
            result = subprocess.run(["/bin/bash", script, *args], capture_output=True, text=True,
                                    env=environment, timeout=60)
            calls = log.read_text().splitlines() if log.exists() else []
            return result, [c for c in calls if not c.startswith("sudo ")]

    return Fake()


UP_CAN0 = ["ip link set can0 down", "ip link set can0 type can bitrate 500000",
           "ip link set can0 up"]


def test_present_interface_is_set_to_500k_and_up(fake):
    fake.add_interface("can0")
    result, calls = fake.run(BRINGUP)
    assert result.returncode == 0, result.stderr
    assert calls == UP_CAN0
    assert "can0 is up at 500000 bit/s" in result.stdout


def test_missing_interface_loads_gs_usb_first(fake):
    result, calls = fake.run(BRINGUP, MODPROBE_CREATES="can0")
    assert result.returncode == 0, result.stderr
    assert calls == ["modprobe gs_usb"] + UP_CAN0


def test_no_adapter_is_a_clear_error(fake):
    fake.add_interface("can1")
    result, calls = fake.run(BRINGUP)
    assert result.returncode == 1
    assert "no CAN interface 'can0'" in result.stderr
    assert "plugged in" in result.stderr
    assert "can1" in result.stderr  # names the CAN interfaces that do exist
    assert not [c for c in calls if c.startswith("ip ")]


def test_kernel_without_gs_usb_is_a_clear_error(fake):
    result, calls = fake.run(BRINGUP, MODPROBE_FAILS="1")
    assert result.returncode == 1
    assert "cannot load the gs_usb kernel module" in result.stderr
    assert "sim:=true" in result.stderr
    assert calls == ["modprobe gs_usb"]


def test_interface_and_bitrate_arguments(fake):
    fake.add_interface("can1")
    result, calls = fake.run(BRINGUP, "can1", "250000")
    assert result.returncode == 0, result.stderr
    assert calls == ["ip link set can1 down", "ip link set can1 type can bitrate 250000",
                     "ip link set can1 up"]


def test_a_non_can_interface_is_refused(fake):
    fake.add_interface("can0", kind="1")  # Ethernet
    result, calls = fake.run(BRINGUP)
    assert result.returncode == 1 and "not a CAN interface" in result.stderr
    assert calls == []


@pytest.mark.parametrize("args", [("can0", "fast"), ("can0", ""), ("bad name",),
                                  ("can0", "500000", "extra")])
def test_usage_errors(fake, args):
    result, calls = fake.run(BRINGUP, *args)
    assert result.returncode == 2 and result.stderr
    assert calls == []


def test_setup_loads_gs_usb_at_boot_then_brings_up(fake, tmp_path):
    fake.add_interface("can0")
    modules = tmp_path / "modules-load.d"
    modules.mkdir()
    result, calls = fake.run(SETUP, RANGER_MODULES_LOAD_DIR=str(modules))
    assert result.returncode == 0, result.stderr
    assert (modules / "gs_usb.conf").read_text() == "gs_usb\n"
    assert calls == UP_CAN0
