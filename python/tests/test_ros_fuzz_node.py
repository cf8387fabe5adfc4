"""fuzz/fuzz_node.py for a few seconds: the ROS 2 node in-process fed good, hostile and mutated
messages, parameter changes, service calls and its timers; no exception may escape, memory stays
bounded, and a good scan is still mapped after every case. A finding fails the test with the
fuzzer's report (the exception, the node's frame, the reproducer under the test's tmp_path)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import ros_support

ros_support.import_or_skip("rclpy")
ros_support.import_or_skip("tf2_msgs")

FUZZER = Path(__file__).resolve().parents[2] / "fuzz" / "fuzz_node.py"
SECONDS = 10


def test_the_node_fuzzer_finds_nothing_in_a_short_run(tmp_path):
    run = subprocess.run([sys.executable, str(FUZZER), "--seconds", str(SECONDS), "--seed", "1",
                          "--artifact-dir", str(tmp_path), "--shrink-seconds", "20"],
                         capture_output=True, text=True, timeout=SECONDS + 240,
                         env={**os.environ, **ros_support.ROS_ENV})
    report = run.stdout + run.stderr
    assert run.returncode == 0, report[-8000:]
    summary = [line for line in run.stdout.splitlines() if line.startswith("fuzz_node: ok:")]
    assert summary, report[-8000:]
    cases, operations = (int(summary[0].split()[k]) for k in (2, 4))
    assert cases >= 3 and operations >= 100, summary[0]  # it fuzzed, not just started


def test_the_fuzzer_reports_an_exception_with_a_reproducer(tmp_path):
    """A case whose only operation is a service that does not exist makes the fuzzer's own lookup
    raise: the fuzzer must report it as a finding, write the reproducer and exit 1 (the route every
    finding in the node takes)."""
    case = tmp_path / "case.json"
    case.write_text('{"case_seed": 0, "start": {"backend": "cpu_double", "threads": 1}, '
                    '"ops": [["service", "no_such_service", false]]}')
    run = subprocess.run([sys.executable, str(FUZZER), "--replay", str(case)], capture_output=True, text=True,
                         timeout=120, env={**os.environ, **ros_support.ROS_ENV})
    assert run.returncode == 1, run.stdout + run.stderr
    assert "reproduced at operation 0: exception: StopIteration" in run.stdout, run.stdout + run.stderr
