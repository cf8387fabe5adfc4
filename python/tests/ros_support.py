"""What the ROS 2 tests share: the environment every ROS process here runs in (Fast DDS over
shared memory only, a domain of this test run's own), the node started as a process, the
skip (or, in CI, failure) when ROS 2 is not installed, the node's UDP sockets.

The network rule: FASTDDS_BUILTIN_TRANSPORTS=SHM keeps Fast DDS off UDP (its default transport
sends multicast discovery out of the network interface; ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
alone still opens sockets on it), and ROS_DOMAIN_ID keeps this run apart from any other.
ROS_AUTOMATIC_DISCOVERY_RANGE is removed: set (LOCALHOST included), it makes rmw_fastrtps add a
UDP transport next to shared memory (test_ros_node.py's socket test caught exactly that)."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
import time

# Set before rclpy creates a participant in this process, and passed to every child.
ROS_ENV = {"FASTDDS_BUILTIN_TRANSPORTS": "SHM", "ROS_DOMAIN_ID": str(100 + os.getpid() % 50),
           "RMW_IMPLEMENTATION": "rmw_fastrtps_cpp",
           "RCUTILS_LOGGING_BUFFERED_STREAM": "0", "PYTHONUNBUFFERED": "1"}
os.environ.update(ROS_ENV)
os.environ.pop("ROS_AUTOMATIC_DISCOVERY_RANGE", None)
os.environ.pop("ROS_STATIC_PEERS", None)


def import_or_skip(module: str):
    """pytest.importorskip with the install hint; with VASCO_REQUIRE_ROS_TESTS=1 (CI) a missing
    module fails the test run instead of skipping it."""
    import pytest

    how = "the ROS 2 extra is not installed: pip install '.[ros]' ./ros (Jazzy: ROS_DISTRO=jazzy pip install '.[ros-jazzy]' ./ros)"
    if os.environ.get("VASCO_REQUIRE_ROS_TESTS") == "1":
        try:
            return __import__(module)
        except ImportError as e:
            pytest.fail(f"VASCO_REQUIRE_ROS_TESTS=1 and {module} does not import ({e}): {how}", pytrace=False)
    return pytest.importorskip(module, reason=how)


class NodeProcess:
    """``python -m vasco_gpu.ros`` with ROS parameters; its output collected line by line."""

    def __init__(self, params: dict, cwd=None, env=None, command=None):
        """command: another program to run the same way (a benchmark's stand-in for the node)."""
        args = command or [sys.executable, "-m", "vasco_gpu.ros", "--ros-args"]
        for k, v in params.items():
            args += ["-p", f"{k}:={_ros_value(v)}"]
        self.proc = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                     env={**os.environ, **ROS_ENV, **(env or {})}, cwd=cwd)
        self.lines: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    @property
    def output(self) -> str:
        return "\n".join(self.lines)

    def wait_for(self, text: str, timeout: float = 30.0) -> str:
        """The first output line containing text; AssertionError with the output on timeout or exit."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            hit = next((ln for ln in list(self.lines) if text in ln), None)
            if hit is not None:
                return hit
            if self.proc.poll() is not None:
                self._reader.join(2)
                hit = next((ln for ln in self.lines if text in ln), None)
                if hit is not None:
                    return hit
                raise AssertionError(f"node exited {self.proc.returncode} before {text!r}:\n{self.output}")
            time.sleep(0.02)
        raise AssertionError(f"no {text!r} within {timeout} s:\n{self.output}")

    def interrupt(self, timeout: float = 10.0) -> tuple[int, float]:
        """SIGINT; (exit status, seconds until it exited)."""
        start = time.monotonic()
        self.proc.send_signal(signal.SIGINT)
        rc = self.proc.wait(timeout)
        took = time.monotonic() - start
        self._reader.join(2)
        return rc, took

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(10)

    def cpu_seconds(self) -> float:
        """The process's CPU time so far (user + system, /proc)."""
        fields = open(f"/proc/{self.proc.pid}/stat").read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")

    def cpu_share(self, action) -> float:
        """The process's CPU time over wall time while action() runs (1.0: one core)."""
        c0, t0 = self.cpu_seconds(), time.monotonic()
        action()
        return (self.cpu_seconds() - c0) / (time.monotonic() - t0)


def _ros_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (list, tuple)):
        return "[" + ",".join(_ros_value(x) for x in v) + "]"
    if isinstance(v, str):
        return f"'{v}'" if v else "''"
    return repr(v)


def udp_sockets(pid: int) -> list[str]:
    """The local addresses ("ip:port") of the UDP sockets process pid holds open."""
    inodes = set()
    for fd in os.listdir(f"/proc/{pid}/fd"):
        try:
            target = os.readlink(f"/proc/{pid}/fd/{fd}")
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    found = []
    for table, width in (("udp", 8), ("udp6", 32)):
        try:
            rows = open(f"/proc/{pid}/net/{table}").read().splitlines()[1:]
        except OSError:
            continue
        for row in rows:
            cols = row.split()
            if cols[9] in inodes:
                addr, port = cols[1].split(":")
                found.append(f"{_ip(addr, width)}:{int(port, 16)}")
    return found


def _ip(hexaddr: str, width: int) -> str:
    raw = bytes.fromhex(hexaddr)
    if width == 8:
        return ".".join(str(b) for b in raw[::-1])
    words = [raw[i:i + 4][::-1] for i in range(0, 16, 4)]
    return ":".join(b.hex() for b in words)


def is_loopback(addr: str) -> bool:
    """127.0.0.0/8 or ::1 (0.0.0.0 and :: bind every interface: not loopback)."""
    ip = addr.rsplit(":", 1)[0]
    return ip.startswith("127.") or ip == "00000000:00000000:00000000:00000001"
