#!/usr/bin/env bash
# Every benchmark of `make bench`, in one run on one machine, its whole output
# written to one file (bench/results/bench-DATE.txt unless BENCH_OUT names
# another) under a header: date, machine, GPU, commit. The docs' performance
# tables are quoted from such a file (docs/performance.md names it), never
# copied by hand.
#   bench/run_all.sh BUILD_DIR [STEP...]   (BUILD_DIR absolute or from the repository root;
#                                          steps: parse oracle mapping large scaling session batch align;
#                                          ros, the ROS 2 node, only when named: it needs the [ros] extra;
#                                          livemap, the node's Path steps without ROS (PYTHON's vasco_gpu),
#                                          only when named; transport, a map over Fast DDS's shared memory
#                                          with its defaults and the node's profile, only when named;
#                                          peers, MRPT's and OctoMap's grids beside ours (peer_bench, built by
#                                          make bench-peers), only when named; large-site, a synthetic site of
#                                          1e5 scans through log2map, a re-render and the node (PYTHON's
#                                          vasco_gpu and rclpy), only when named; ray, map_logs by executor,
#                                          Ray's actors among them (PYTHON's vasco_gpu and ray), only when named)
# COST_MODEL_OUT=FILE: batch_bench also writes auto's measured constants there
# (vasco_gpu/src/backend_cost_model.txt is such a file); BATCH_ARGS: more of
# batch_bench's options; BENCH_COMMIT: the commit to name where the tree is
# a copy without its git history; PYTHON: the interpreter of the ros step (one with vasco_gpu,
# rclpy and tf2_msgs), ROS_BENCH_ARGS: more of ros_node_bench.py's options; LIVEMAP_ARGS: live_map_steps.py's; PEER_ARGS: peer_bench's; ALIGN_ARGS: align_bench's;
# RAY_ARGS: ray_bench.py's; LARGE_SITE_ARGS: large_site_bench.py's (default: the CPU backends' rows, cpu_float; a GPU host names
# --backends cuda_float cuda_exact --node-backend cuda_float).
set -euo pipefail
build=${1:?usage: bench/run_all.sh BUILD_DIR [STEP...]}
shift
steps=${*:-parse oracle mapping large scaling session batch align}
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"  # the steps' paths are the repository's
out=${BENCH_OUT:-$root/bench/results/bench-$(date -u +%Y-%m-%d).txt}
mkdir -p "$(dirname "$out")"
tmp=$(mktemp "$out.XXXXXX")
trap 'rm -f "$tmp"' EXIT
{
  echo "# vasco_gpu benchmarks: bench/run_all.sh $build $steps"
  echo "# date: $(date -u '+%Y-%m-%d %H:%M UTC')"
  echo "# commit: ${BENCH_COMMIT:-$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)}"
  echo "# machine: $(nproc) cores, $(awk '/MemTotal/ {printf "%.0f GiB", $2 / 1048576}' /proc/meminfo), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ *//')"
  echo "# GPU: $(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null | head -1 || true)"
} > "$tmp"
run() {
  run_as "$*" "$@"
}
run_as() {  # run_as LABEL COMMAND...: the section is headed by LABEL (no interpreter's path)
  local label=$1
  shift
  echo >> "$tmp"
  echo "## $label" >> "$tmp"
  "$@" 2>&1 | tee -a "$tmp"
}
for step in $steps; do
  case $step in
    parse) run "$build/bin/parse_bench" ;;
    oracle) run "$build/bin/oracle_o2_bench" ;;
    mapping) run "$build/bin/mapping_bench" ;;
    large) run "$build/bin/mapping_bench" --large ;;
    scaling) run "$build/bin/mapping_bench" --thread-scaling ;;
    session) run "$build/bin/session_bench" ;;
    align) run "$build/bin/align_bench" ${ALIGN_ARGS:-} ;;
    batch) run python3 bench/batch_bench.py --bin "$build/bin" ${BATCH_ARGS:-} \
             ${COST_MODEL_OUT:+--cost-model-out "$COST_MODEL_OUT"} ;;
    ros) run_as "python3 bench/ros_node_bench.py ${ROS_BENCH_ARGS:-}" \
           "${PYTHON:-python3}" bench/ros_node_bench.py ${ROS_BENCH_ARGS:-} ;;
    livemap) run_as "python3 bench/live_map_steps.py ${LIVEMAP_ARGS:-}" \
               "${PYTHON:-python3}" bench/live_map_steps.py ${LIVEMAP_ARGS:-} ;;
    transport) run_as "python3 bench/ros_map_transport.py" "${PYTHON:-python3}" bench/ros_map_transport.py ;;
    peers) run "$build/bin/peer_bench" ${PEER_ARGS:-} ;;
    ray) run_as "python3 bench/ray_bench.py ${RAY_ARGS:-}" "${PYTHON:-python3}" bench/ray_bench.py ${RAY_ARGS:-} ;;
    large-site) run_as "python3 bench/large_site_bench.py --bin $build/bin ${LARGE_SITE_ARGS:-}" \
                  "${PYTHON:-python3}" bench/large_site_bench.py --bin "$build/bin" ${LARGE_SITE_ARGS:-} ;;
    *) echo "bench/run_all.sh: unknown step '$step'" >&2; exit 2 ;;
  esac
done
mv "$tmp" "$out"
trap - EXIT
echo "bench/run_all.sh: wrote $out"
