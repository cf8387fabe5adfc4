"""What checks each fenced block of README.md and of every Markdown file under docs/, keyed
by the document (its path in the source tree: "README.md", "docs/cli.md") and then by
readme_blocks.Block.key, and the fixtures that make the files the blocks' commands name
(standard library only).

Every block of every document must have an entry here, and every entry a block: a new or
changed block (or a new document with blocks) fails the docs test until this table says
how it is checked, and an entry whose block or document is gone fails as stale.

Kinds of check:
  run          each command of a shell block runs with bash in a scratch directory that the
               block's fixture prepared, the build's tools first on PATH; it must exit with
               `status` (by command prefix; default 0), and `outputs` must exist afterwards.
               Commands starting with a prefix in `skip` are not run (the reason says why);
               `python=True`: the block needs the Python package's console scripts, so
               python/tests/test_readme.py runs it and the docs test skips it.
  make-target  each `make [VAR=VALUE...] X` line: `make -n -C SOURCE [VAR=VALUE...] X` (a dry
               run) must succeed, its output naming `mentions[X]`; the targets themselves are
               never run here.
  compile      a C or C++ fragment, put into `harness` (its #include lines first), must
               compile against the source tree's headers (syntax only).
  covered-by   another test checks what the block says: each (file, strings) of `files`
               must exist and contain every string.
  synopsis     a usage block of `tool`: every option in it must be in `tool --help`; the
               `examples` commands (the synopsis filled in) run as in `run`.
  output       a sample of a tool's output: `command` runs (fixture first; $VASCO_SOURCE and
               $VASCO_BUILD name the source tree and the build directory); with
               `output_file` that file must equal the block, else one line of the
               command's stderr must match the block's line with numbers and the
               alternatives of `alternatives` generalised.
  layout       the Layout tree: every directory and file it names must exist.
  python       a Python block: python/tests/test_readme.py runs it as written, as a script
               would (fixture first, `outputs` must exist afterwards); skipped by the docs test.
  quoted       a benchmark's output quoted from a results file: the block's lines must be a
               run of consecutive lines of `quote_of` (a file of bench/results/, made by one
               bench/run_all.sh run under a header naming its date, machine and commit), or
               with `picked` lines of it in its order (its header lines and the rows
               wanted); the document must link the file (readme_quotes.py).
  skip         not checked: `reason` says why.
"""

from __future__ import annotations

import gzip
import math
import shutil
import subprocess
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Dict, List, Optional, Sequence, Tuple

PY_RUNS_IT = "Python block: python/tests/test_readme.py runs it"
PY_SCRIPT_RUNS_IT = "Python console script: python/tests/test_readme.py runs it"


@dataclass
class Check:
    kind: str
    reason: str = ""
    fixture: str = ""
    status: Dict[str, int] = field(default_factory=dict)
    outputs: Sequence[str] = ()
    skip: Dict[str, str] = field(default_factory=dict)
    python: bool = False
    mentions: Dict[str, Sequence[str]] = field(default_factory=dict)
    harness: str = ""
    files: Sequence[Tuple[str, Sequence[str]]] = ()
    tool: str = ""
    examples: Sequence[str] = ()
    command: str = ""
    output_file: str = ""
    alternatives: Sequence[Tuple[str, str]] = ()
    needs: Sequence[str] = ()  # Python modules a python check needs (skipped without them)
    quote_of: str = ""  # quoted: the results file the block comes from
    picked: bool = False  # quoted: lines of it in its order, not one run of them


def quoted(results_file: str, picked: bool = False) -> Check:
    """A block quoted, line for line, from a saved benchmark run (bench/results/...): a run
    of its lines, or with picked its header and the rows wanted, in its order."""
    return Check("quoted", quote_of=results_file, picked=picked)


def picked(results_file: str) -> Check:
    return quoted(results_file, picked=True)


# Pages of benchmark figures: no Markdown table typed by hand (readme_quotes.py).
NO_HAND_TABLES = ("docs/performance.md",)

# A document's summary section: its figures with a decimal point must be in the results
# files the document quotes or the section links (readme_quotes.py).
SUMMARIES = {"docs/performance.md": "What to expect"}


# ---------------------------------------------------------------------------------------
# Compile harnesses: the fragment's #include lines go to @INCLUDES@, the rest to @BODY@.

C_HARNESS = r"""
#include <stdio.h>
#include <stdlib.h>
@INCLUDES@
static void die(const char *why) { fprintf(stderr, "%s\n", why); exit(1); }
void readme_snippet(size_t n, const double *poses, const int *beam_counts, const float *ranges,
                    const double *first_angles, const double *angle_steps, const double *new_poses);
void readme_snippet(size_t n, const double *poses, const int *beam_counts, const float *ranges,
                    const double *first_angles, const double *angle_steps, const double *new_poses) {
@BODY@
}
"""

CXX_HARNESS = r"""
#include <vector>
@INCLUDES@
std::vector<vasco::Pose> optimizer_poses();
void readme_snippet(const vasco::ScanBatch &scans, int x0, int y0);
void readme_snippet(const vasco::ScanBatch &scans, int x0, int y0) {
@BODY@
  (void)map;
  (void)patch;
}
"""

# ---------------------------------------------------------------------------------------
# Fixtures: fixture(scratch, source, bin) makes the files a block's commands name.


def laser_lines(log: Path) -> List[List[str]]:
    """The FLASER lines of a CARMEN log, split into fields."""
    with gzip.open(log, "rt") as f:
        return [ln.split() for ln in f if ln.startswith("FLASER ")]


def flaser_pose(t: List[str]) -> Tuple[float, float, float, float]:
    """(stamp, x, y, theta) of a FLASER line: the laser pose after the ranges, the ipc
    timestamp third from the end."""
    n = int(t[1])
    return float(t[-3]), float(t[2 + n]), float(t[3 + n]), float(t[4 + n])


def g17(v: float) -> str:
    return "%.17g" % v


def write_log_gz(path: Path, lines: List[List[str]]) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with gzip.open(path, "wt") as f:
        f.writelines(" ".join(t) + "\n" for t in lines)
    return path


def transformed(lines: List[List[str]], x0: float, y0: float, th0: float) -> List[List[str]]:
    """FLASER lines with both poses (laser and odometry) moved by the rigid transform
    (x0, y0, th0)."""
    c, s = math.cos(th0), math.sin(th0)
    out = []
    for t in lines:
        t = list(t)
        n = int(t[1])
        for at in (2 + n, 5 + n):
            x, y, th = float(t[at]), float(t[at + 1]), float(t[at + 2])
            t[at:at + 3] = [g17(x0 + c * x - s * y), g17(y0 + s * x + c * y), g17(th + th0)]
        out.append(t)
    return out


def run_tool(bin_dir: Path, *args: str) -> None:
    subprocess.run([str(bin_dir / args[0]), *args[1:]], check=True, stdout=subprocess.DEVNULL,
                   stderr=subprocess.PIPE, timeout=120)


def fixture_intel(scratch: Path, source: Path, bin_dir: Path) -> None:
    shutil.copy(source / "logs" / "intel.gfs.log.gz", scratch / "intel.log.gz")


def fixture_poses(scratch: Path, source: Path, bin_dir: Path) -> None:
    """intel.log.gz and intel's own laser poses as a SLAM back end's files: optimized.g2o
    (VERTEX_SE2 in scan order, 17 digits), trajectory.txt (TUM by stamp, the yaw as a
    quaternion about z) and corrected.log.gz (a CARMEN log of the FLASER lines alone)."""
    fixture_intel(scratch, source, bin_dir)
    lines = laser_lines(scratch / "intel.log.gz")
    poses = [flaser_pose(t) for t in lines]
    (scratch / "optimized.g2o").write_text(
        "".join(f"VERTEX_SE2 {i} {g17(x)} {g17(y)} {g17(th)}\n" for i, (_, x, y, th) in enumerate(poses)))
    (scratch / "trajectory.txt").write_text(
        "# timestamp tx ty tz qx qy qz qw\n"
        + "".join(f"{g17(t)} {g17(x)} {g17(y)} 0 0 0 {g17(math.sin(th / 2))} {g17(math.cos(th / 2))}\n"
                  for t, x, y, th in poses))
    write_log_gz(scratch / "corrected.log.gz", lines)


# The transform of the README's --add example: tuesday's poses are written in a frame that
# it takes back into monday's.
TUESDAY = (12.5, -3.0, 1.5708)


def fixture_sessions(scratch: Path, source: Path, bin_dir: Path) -> None:
    """monday.log.gz and tuesday.log.gz: intel's scans in two halves, tuesday's poses in a
    frame of its own (the inverse of the README's transform applied)."""
    lines = laser_lines(source / "logs" / "intel.gfs.log.gz")
    half = len(lines) // 2
    write_log_gz(scratch / "monday.log.gz", lines[:half])
    x, y, th = TUESDAY
    c, s = math.cos(th), math.sin(th)
    inverse = (-(c * x + s * y), s * x - c * y, -th)
    write_log_gz(scratch / "tuesday.log.gz", transformed(lines[half:], *inverse))


def fixture_runs(scratch: Path, source: Path, bin_dir: Path) -> None:
    """runs/run1.log.gz (intel) and runs/run2.log.gz (its first 300 scans)."""
    (scratch / "runs").mkdir()
    shutil.copy(source / "logs" / "intel.gfs.log.gz", scratch / "runs" / "run1.log.gz")
    write_log_gz(scratch / "runs" / "run2.log.gz", laser_lines(source / "logs" / "intel.gfs.log.gz")[:300])


def fixture_fr079_maps(scratch: Path, source: Path, bin_dir: Path) -> None:
    """carmen/fr079.map.gz: CARMEN's own map of fr079 with vasco's defaults (the golden
    map); today/fr079.map.gz and float/fr079.map.gz: log2map's, on cpu_threads (exact) and
    cpu_float."""
    for d in ("carmen", "today", "float"):
        (scratch / d).mkdir()
    shutil.copy(source / "tests" / "data" / "golden" / "maps" / "fr079-complete.gfs__vasco_default_ds4.map.gz",
                scratch / "carmen" / "fr079.map.gz")
    log = str(source / "logs" / "fr079-complete.gfs.log.gz")
    run_tool(bin_dir, "log2map", "-q", "--backend", "cpu_threads", log, str(scratch / "today" / "fr079.map.gz"))
    run_tool(bin_dir, "log2map", "-q", "--backend", "cpu_float", log, str(scratch / "float" / "fr079.map.gz"))


def fixture_freiburg(scratch: Path, source: Path, bin_dir: Path) -> None:
    shutil.copy(source / "tests" / "data" / "maps" / "freiburg.map", scratch / "freiburg.map")


def fixture_logs(scratch: Path, source: Path, bin_dir: Path) -> None:
    """logs/: the bundled logs, as the repository root has them."""
    (scratch / "logs").symlink_to(source / "logs", target_is_directory=True)


FIXTURES: Dict[str, Callable[[Path, Path, Path], None]] = {
    "intel": fixture_intel,
    "poses": fixture_poses,
    "sessions": fixture_sessions,
    "runs": fixture_runs,
    "fr079_maps": fixture_fr079_maps,
    "freiburg": fixture_freiburg,
    "logs": fixture_logs,
}

# ---------------------------------------------------------------------------------------
# The table: document -> block key -> check.

# The bench runs docs/performance.md quotes most.
BENCH_RUN = "bench/results/bench-2026-12-04-h200.txt"
MAPPING_RUN = "bench/results/mapping-2026-12-06-h100.txt"
PEERS_RUN = "bench/results/peers-2026-12-06b-2core.txt"

CHECKS: Dict[str, Dict[str, Check]] = {
    "README.md": {
        # Quick start.
        "sh: make demo": Check(
            "make-target",
            mentions={"demo": ["build/bin/log2map", "build/fr079.png", "build/fr079.map.gz"],
                      "test": ["ctest"]}),
        # Without CUDA.
        "sh: make CMAKE_FLAGS=-DVASCO_GPU_CUDA=OFF test": Check(
            "make-target", mentions={"test": ["-DVASCO_GPU_CUDA=OFF", "ctest"]}),
        # The tour.
        "sh: log2map logs/intel.gfs.log.gz intel.map.gz intel.pgm intel.p": Check(
            "run", fixture="logs", outputs=["intel.map.gz", "intel.pgm", "intel.yaml", "intel.png", "fine.map.gz"]),
        # The sample bag: the walkthrough's first command, then bag2map on it.
        "sh: carmen2bag logs/intel.gfs.log.gz intel.mcap": Check(
            "run", python=True, fixture="logs", outputs=["intel.mcap", "bag.pgm", "bag.yaml", "bag.map.gz"]),
        'python: log = vg.load_log("logs/intel.gfs.log.gz")': Check(
            "python", fixture="logs", outputs=["intel.png"]),
    },
    "docs/DESIGN.md": {
        "text: vasco_gpu.ros (ROS 2 node: wiring; LiveMap over Mapper, Posi": Check(
            "skip", reason="a diagram of the libraries (DESIGN §1), not a command"),
    },
    "docs/backends-and-accuracy.md": {
        "text: golden_check: no golden maps at ../shared/golden (SHA256SUMS": Check(
            "output",
            command='make -s -C "$VASCO_SOURCE" -o all golden BUILD="$VASCO_BUILD" '
                    'GOLDEN_DIR="$PWD/no-golden" GOLDEN_DATA="$PWD/no-data"',
            alternatives=[("../shared/golden", r"\S+")]),
        "text: summary: 27 cases": Check(
            "covered-by",
            files=[("tests/golden_check.cc", ["summary: %d cases", "identical to CARMEN"]),
                   ("Makefile", ["golden_check --golden $(GOLDEN_DIR)"])]),
    },
    "docs/bags-and-poses.md": {
        "sh: bag2map --z-band 0.25,1.0 cloud.mcap cloud.map.gz": Check(
            "covered-by", files=[("python/tests/test_bag_clouds.py", [
                'run_script("bag2map", "--z-band", "0.25,1.0", str(cloud_bag), str(out))  # docs/bags-and-poses.md'])]),
        "sh: log2map --poses optimized.g2o intel.log.gz after.map.gz": Check(
            "run", fixture="poses", outputs=["after.map.gz"]),
        "sh: bag2map run.mcap map.pgm map.map.gz": Check(
            "run", python=True, fixture="bags",
            outputs=["map.pgm", "map.yaml", "map.map.gz", "map.png", "run.log.gz"]),
        'python: log = vg.load_bag("run.mcap")': Check(
            "python", fixture="bags", outputs=["map.pgm", "map.yaml"], needs=["rosbags"]),
        "yaml: image: map.pgm": Check(
            "output", fixture="intel", command="log2map -q --backend cpu_threads intel.log.gz map.pgm",
            output_file="map.yaml"),
        "sh: ros2 run nav2_map_server map_server --ros-args -p yaml_filen": Check(
            "skip", reason="needs ROS 2 (nav2_map_server)"),
    },
    "docs/building.md": {
        "sh: make CMAKE_FLAGS=-DVASCO_GPU_CUDA=OFF test": Check(
            "make-target", mentions={"test": ["-DVASCO_GPU_CUDA=OFF", "ctest"]}),
    },
    "docs/c-api-and-carmen.md": {
        "make: VASCO = /opt/vasco_gpu": Check(
            "covered-by",
            files=[("tests/install/install_test.sh", ["-legrid", "-lmap_io", "-lreadlog", "-Wl,-rpath,"]),
                   ("tests/CMakeLists.txt", ["InstalledTreeServesCarmenClients"])]),
        "make: CFLAGS += $(shell pkg-config --cflags vasco_gpu)": Check(
            "covered-by",
            files=[("tests/install/install_test.sh", ["pkg-config --cflags --libs vasco_gpu)",
                                                      "pkg-config --libs vasco_gpu-static"])]),
        "cmake: find_package(vasco_gpu REQUIRED)": Check(
            "covered-by",
            files=[("tests/install/CMakeLists.txt", ["find_package(vasco_gpu REQUIRED)", "vasco_gpu::vasco_gpu ",
                                                     "vasco_gpu::vasco_gpu_shared"]),
                   ("tests/install/c_project/CMakeLists.txt", ["find_package(vasco_gpu REQUIRED)"])]),
    },
    "docs/cli.md": {
        "text: log2map [options] LOG OUT [OUT...]": Check(
            "synopsis", tool="log2map", fixture="intel",
            examples=["log2map -q --backend cpu_threads intel.log.gz a.map a.map.gz a.pgm a.png",
                      "log2map -q --backend cpu_threads --out-dir d --formats map.gz,png intel.log.gz",
                      "test -f a.yaml && test -f d/intel.map.gz && test -f d/intel.png"]),
        "sh: log2map monday.log.gz --add tuesday.log.gz@12.5,-3.0,1.5708": Check(
            "run", fixture="sessions", outputs=["both.map.gz"]),
        "text: # date: 2026-12-07 22:55 UTC": picked("bench/results/align-2026-12-07-2core.txt"),
        "text: # date: 2026-12-06 22:46 UTC": picked("bench/results/align-2026-12-06-h100.txt"),
        "sh: log2map -q --json first.log --add second.log@auto both.map": Check(
            "covered-by", files=[("tests/log2map_auto_test.cc", [
                "FindsTheTransformAndMapsAsIfItWereGiven", "\"@auto\"", "added_sessions",
                "aligned\\\":\\\"auto"])]),
        "text: log2map: second.log: aligned (@auto): transform 3.5014552772": Check(
            "covered-by", files=[("tests/log2map_auto_test.cc", ["second.log: aligned (@auto): transform "])]),
        "sh: log2map first.log --add fr079.log@auto both.map": Check(
            "covered-by", files=[("tests/log2map_auto_test.cc", [
                "AnotherBuildingIsRefusedAndNothingWritten", "EXPECT_EQ(r.status, 1)", "out.entries().empty()"])]),
        "text: log2map: fr079.log: not placed by alignment (\"@auto\"): no_ov": Check(
            "covered-by", files=[("tests/log2map_auto_test.cc", ["fr079.log\") + \": not placed by alignment\"",
                                                                 "best ("])]),
        "text: log2map: --backend auto: 3.4e+08 cell updates: about 0.302 s": Check(
            "output", fixture="intel", command="log2map --backend auto intel.log.gz auto.map.gz",
            # with a GPU that may be usable, its time; else why none is (backend_choice.h)
            alternatives=[("cores, 0.305 s on the GPU (0.29 s of it start-up): using cpu_threads",
                           r"cores(, [0-9.e+-]+ s on the GPU \([0-9.e+-]+ s of it start-up\): using (cpu_threads|cuda)"
                           r"|; (no usable GPU: .*|this build has no CUDA backend \(configured without nvcc\)): "
                           r"using cpu_threads)")]),
        "sh: log2map --out-dir maps --formats map.gz,png runs/*.log.gz": Check(
            "run", fixture="runs",
            outputs=["maps/run1.map.gz", "maps/run1.png", "maps/run2.map.gz", "maps/run2.png"]),
        "sh: mapdiff carmen/fr079.map.gz today/fr079.map.gz": Check(
            "run", fixture="fr079_maps", status={"mapdiff": 0}, outputs=["diff.png"]),
        "text: mapconvert [-q] [--mode trinary|scale|raw] IN OUT": Check(
            "synopsis", tool="mapconvert", fixture="freiburg",
            examples=["mapconvert -q --mode scale freiburg.map out.pgm", "test -f out.yaml",
                      "mapconvert freiburg.map out.map.gz", "mapconvert freiburg.map out.png",
                      "mapconvert --info freiburg.map", "mapconvert --version"]),
    },
    "docs/contributing.md": {
        "text: carmen_compat/ CARMEN's formats and C libraries; no mapping": Check("layout"),
        "sh: python3 tests/docs/readme_test.py --readme README.md --sourc": Check(
            "covered-by",
            files=[("tests/CMakeLists.txt", ["docs/readme_test.py", "--readme ${VASCO_SOURCE_DIR}/README.md",
                                             "--source ${VASCO_SOURCE_DIR}", "--bin ${CMAKE_BINARY_DIR}/bin"])]),
    },
    "docs/performance.md": {
        "sh: bench/run_all.sh build parse mapping session": Check(
            "covered-by", files=[("bench/run_all.sh", [
                "steps: parse oracle mapping large scaling session batch", "parse) run", "mapping) run",
                "session) run"])]),
        "text: # vasco_gpu benchmarks: build-gpu/bin/mapping_bench --datase": picked(MAPPING_RUN),
        "text: Targets (fr079, map phase):": quoted(MAPPING_RUN),
        "text: # vasco_gpu benchmarks: bench/run_all.sh build-bench parse o": picked(BENCH_RUN),
        "text: ## build-bench/bin/parse_bench": quoted(BENCH_RUN),
        "text: # vasco_gpu benchmarks: bench/run_all.sh build session": picked("bench/results/session-2026-12-07c-h100.txt"),
        "text: # commit: 7ae01d1": picked("bench/results/session-2026-12-07d-h100.txt"),
        "text: # commit: dc4ddaf": picked("bench/results/peers-2026-12-07-2core.txt"),
        "text: # commit: 260ad79": picked("bench/results/peers-2026-12-07b-2core.txt"),
        "text: ## python3 bench/batch_bench.py --bin build-bench/bin --copi": picked(BENCH_RUN),
        "text: # vasco_gpu benchmarks: bench/run_all.sh build batch":
            picked("bench/results/batch-2026-12-07d-h100.txt"),
        "text: # vasco_gpu benchmarks: bench/run_all.sh build peers": picked(PEERS_RUN),
        "text: re-render linear in cell updates (cpu_float): ns per update":
            picked("bench/results/large-site-2026-12-08d-2core.txt"),
        "text: re-render linear in cell updates (cuda_exact): ns per update":
            picked("bench/results/large-site-2026-12-07h-h100.txt"),
        "text: Where a user sees it: log2map --json --backend cpu_float, se": quoted(PEERS_RUN),
    },
    "bench/results/HISTORY.md": {
        "text: cuda batch --devices read-ahead logs/s / first row":
            picked("bench/results/batch-2026-12-06b-h100.txt"),
        "text: stages of one cuda batch, --devices (its choice), read-ahead":
            quoted("bench/results/batch-2026-12-06c-h100.txt"),
        "text: | data | backend | place | upload | map | finish + download":
            quoted("bench/results/session-2026-12-06-h100.txt"),
    },
    "docs/python.md": {
        "sh: pip install .": Check(
            "run", python=True, reason="python -c needs the package: python/tests/test_readme.py runs it",
            skip={"pip install": "pip install: CI's pip step (.ci/run) runs it"}),
        "sh: cmake -S . -B build-py -DVASCO_GPU_BUILD_PYTHON=ON -DPython_": Check(
            "covered-by",
            files=[("CMakeLists.txt", ["option(VASCO_GPU_BUILD_PYTHON"]),
                   ("python/CMakeLists.txt", ["add_custom_target(vasco_gpu_python"]),
                   ("python/tests/conftest.py", ["ROOT"])]),
        'python: log = vg.load_log("logs/fr079-complete.gfs.log.gz")': Check(
            "python", fixture="logs", outputs=["before.png", "after.png"]),
        'python: if __name__ == "__main__":': Check(
            "python", fixture="logs", needs=["dask.distributed"],
            outputs=["maps/intel.gfs.map.gz", "maps/intel.gfs.png", "maps/fr101.carmen.map.gz",
                     "maps/fr101.carmen.png"]),
        "text: # vasco_gpu benchmarks: bench/run_all.sh build-ray-pip ray":
            picked("bench/results/ray-2026-12-07-h100.txt"),
        "python: ray.init()": Check(
            "python", fixture="logs", needs=["ray"],
            outputs=["maps/intel.gfs.map.gz", "maps/intel.gfs.png", "maps/fr101.carmen.map.gz",
                     "maps/fr101.carmen.png"]),
        'python: log = vg.load_log("logs/intel.gfs.log.gz")': Check("python", fixture="logs", outputs=["merged.png"]),
    },
    "docs/sessions.md": {
        "cpp: vasco::MapperParams params;": Check("compile", harness=CXX_HARNESS),
        "c: vasco_mapper_params p;": Check("compile", harness=C_HARNESS),
    },
    "docs/ros.md": {
        'sh: ROS_DISTRO=kilted pip install ".[ros]" ./ros': Check(
            "covered-by", files=[(".ci/run", ["ROS_DISTRO=kilted", '"$vasco_wheel[dask,ray,ros]"', "./ros",
                                              "VASCO_REQUIRE_ROS_TESTS=1"])]),
        'sh: ROS_DISTRO=jazzy pip install ".[ros-jazzy]" ./ros': Check(
            "covered-by", files=[(".ci/run", ["ROS_DISTRO=jazzy", '"$vasco_wheel[ros-jazzy]"', "./ros",
                                              "python/tests/test_ros_*.py"])]),
        "sh: vasco_map_node --ros-args --params-file examples/ros/vasco_m": Check(
            "covered-by", files=[("python/tests/test_ros_lifecycle.py", ["vasco_mapper_nav2.yaml", "ParamsFileNode"]),
                                 ("python/tests/test_ros_slam_toolbox.py", ['"--params-file"'])]),
        'python: node = subprocess.Popen(["vasco_map_node", "--ros-args", "--': Check(
            "covered-by", files=[("python/tests/test_ros_lifecycle.py", ["vasco_mapper_nav2.yaml"]),
                                 ("python/tests/test_ros_node.py", ["SIGINT"])]),
        "yaml: lifecycle_manager_mapping:": Check(
            "skip", reason="needs nav2 (a system ROS 2): its keys are nav2's lifecycle manager's and static layer's"),
        "sh: export FASTDDS_BUILTIN_TRANSPORTS=SHM ROS_DOMAIN_ID=42": Check(
            "covered-by", files=[("python/tests/test_ros_node.py", ["docs/ros.md", "def test_the_docs_command_runs"])]),
        "sh: ros2 launch examples/ros/vasco_with_slam_toolbox.launch.py b": Check(
            "skip", reason="needs ros2 launch and slam_toolbox (a system ROS 2); python/tests/test_live_map.py "
                           "compiles the launch file and checks the node parameters it sets"),
        "text: # date: 2026-12-05 15:09 UTC": picked("bench/results/bench-ros-2026-12-05-h100-d.txt"),
        "text: # date: 2026-12-06 21:54 UTC": picked("bench/results/bench-ros-2026-12-06b-h100-kilted.txt"),
        "text: # date: 2026-12-05 14:58 UTC": picked("bench/results/bench-ros-2026-12-05-h100-c.txt"),
        "text: # date: 2026-12-05 15:13 UTC": picked("bench/results/bench-ros-2026-12-05-2core-e.txt"),
        "text: ## python3 bench/ros_map_transport.py":
            quoted("bench/results/bench-ros-transport-2026-12-05-2core-b.txt"),
    },
    "docs/walkthrough-bag.md": {
        # carmen2bag and mapdiff are not among test_readme.py's tools: the test runs the block
        # itself, each command as written, with the console scripts and the build's tools.
        "sh: carmen2bag logs/intel.gfs.log.gz intel.mcap": Check(
            "covered-by",
            files=[("python/tests/test_carmen2bag.py", ["walkthrough-bag.md", "def test_walkthrough_runs",
                                                        "shell_commands"])]),
    },
}


def check_for(doc: str, key: str) -> Optional[Check]:
    """The check of the block with this key in this document (a name as
    readme_blocks.doc_name gives it), or None."""
    return CHECKS.get(doc, {}).get(key)
