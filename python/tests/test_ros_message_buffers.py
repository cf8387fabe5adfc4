"""The node's glibc thresholds (vasco_gpu.ros.message_buffers): buffers of a large message's size,
allocated and freed in turn as a node's messages are, page-fault fresh memory every time under
glibc's defaults and not once the thresholds are raised. No ROS needed."""

from __future__ import annotations

import platform
import subprocess
import sys

import pytest

GLIBC_ONLY = pytest.mark.skipif(platform.system() != "Linux" or platform.libc_ver()[0] != "glibc",
                                reason="glibc's malloc only")

# Two buffers of 1.5 MB (a map's serialised copies) made and freed 50 times, after a warm-up;
# prints the minor page faults of the 50 rounds.
CHURN = """
import resource, sys
if sys.argv[1] == "kept":
    from vasco_gpu.ros.message_buffers import keep_message_buffers
    assert keep_message_buffers()
def faults():
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt
def message():
    a = bytearray(1_500_000)
    b = bytearray(1_500_000)
    del b, a
for _ in range(3):
    message()
before = faults()
for _ in range(50):
    message()
print(faults() - before)
"""


def faults(mode: str) -> int:
    out = subprocess.run([sys.executable, "-c", CHURN, mode], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return int(out.stdout)


@GLIBC_ONLY
def test_kept_buffers_fault_in_no_fresh_pages_per_message():
    default, kept = faults("default"), faults("kept")
    # 50 rounds of 2 x 367 pages of 4 KiB when every buffer is fresh: glibc's defaults trim the
    # freed 3 MB off the heap's top each round (the reason for the module)
    assert default >= 50 * 2 * 300, default
    assert kept <= default // 20, (kept, default)


# 400 buffers of 100 KB on the heap (under the raised mmap threshold), every other one freed: 20 MB
# of holes between chunks in use, which free() cannot give back (none is at the heap's top);
# prints the resident kB before and after give_back_free_memory.
HOLES = """
import sys
from vasco_gpu.ros.message_buffers import give_back_free_memory, keep_message_buffers
assert keep_message_buffers()
def rss_kb():
    return int(next(l for l in open("/proc/self/status") if l.startswith("VmRSS:")).split()[1])
held = [bytearray(b"x" * 100_000) for _ in range(400)]
del held[::2]
before = rss_kb()
assert give_back_free_memory()
print(before, rss_kb())
"""


@GLIBC_ONLY
def test_free_memory_between_buffers_goes_back_to_the_system():
    out = subprocess.run([sys.executable, "-c", HOLES], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    before, after = (int(v) for v in out.stdout.split())
    # 200 holes of 100 KB (24 whole pages each): about 19 MB; half of it is a margin for the
    # interpreter's own churn
    assert before - after >= 10_000, (before, after)
