#!/usr/bin/env bash
# Everything to run on a machine with a GPU, in one go: build, the whole test
# suite, every public golden case through every exact path (CUDA exact mode
# included) when GOLDEN_DIR and GOLDEN_DATA name a copy of the goldens and
# their logs, compute-sanitizer (memcheck, racecheck) on the small GPU tests,
# a per-stage profile of both CUDA modes, and the benchmarks.
# Usage: [GOLDEN_DIR=... GOLDEN_DATA=...] [SKIP_BENCH=1] bash bench/gpu_run.sh OUTDIR [bench runs]
set -uo pipefail
out=${1:-/tmp/vasco_gpu_run}; runs=${2:-5}
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv > "$out/gpu.txt" 2>&1
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > "$out/configure.log" 2>&1 &&
  cmake --build build -j 16 > "$out/build.log" 2>&1 || { tail -40 "$out/build.log"; exit 1; }
(cd build && timeout 240 ctest -j 8 --timeout 120 -LE slow --output-on-failure > "$out/ctest.log" 2>&1); echo "ctest rc=$?" >> "$out/summary.txt"
tail -3 "$out/ctest.log" >> "$out/summary.txt"
grep -E "Skipped|Failed|\*\*\*" "$out/ctest.log" | grep -v "^Test project" >> "$out/summary.txt"
(cd build && ./bin/cuda_backend_test --gtest_filter='*FloatMode*' 2>&1 | grep -A4 "cuda float vs") >> "$out/summary.txt"
if [ -n "${GOLDEN_DIR:-}" ]; then
  timeout 300 build/bin/golden_check --golden "$GOLDEN_DIR" --data "$GOLDEN_DATA" > "$out/golden.txt" 2>&1
  echo "golden_check rc=$?" >> "$out/summary.txt"; sed -n '/^summary/,$p' "$out/golden.txt" >> "$out/summary.txt"
fi
small='CudaNoLostUpdates.*:CudaExact.*'
golden_small='Carried/GoldenCuda.ExactModeMatchesCarmen/*edge_cases*:Carried/GoldenCuda.FloatMode*/edge_cases*'
for tool in memcheck racecheck; do
  timeout 150 compute-sanitizer --tool $tool --error-exitcode 99 build/bin/cuda_backend_test --gtest_filter="$small" > "$out/sanitizer_$tool.log" 2>&1
  echo "compute-sanitizer $tool cuda_backend_test rc=$? : $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/sanitizer_$tool.log" | tail -1)" >> "$out/summary.txt"
  timeout 200 compute-sanitizer --tool $tool --error-exitcode 99 build/bin/golden_cuda_test --gtest_filter="$golden_small" > "$out/sanitizer_golden_$tool.log" 2>&1
  echo "compute-sanitizer $tool golden_cuda_test rc=$? : $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/sanitizer_golden_$tool.log" | tail -1)" >> "$out/summary.txt"
  timeout 200 compute-sanitizer --tool $tool --error-exitcode 99 build/bin/mapper_cuda_test --gtest_filter='MapperCuda.Finish*' > "$out/sanitizer_mapper_$tool.log" 2>&1
  echo "compute-sanitizer $tool mapper_cuda_test rc=$? : $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/sanitizer_mapper_$tool.log" | tail -1)" >> "$out/summary.txt"
  timeout 120 compute-sanitizer --tool $tool --error-exitcode 99 build/bin/exact_placement_cuda_test > "$out/sanitizer_placement_$tool.log" 2>&1
  echo "compute-sanitizer $tool exact_placement_cuda_test rc=$? : $(grep -E 'ERROR SUMMARY|RACECHECK SUMMARY' "$out/sanitizer_placement_$tool.log" | tail -1)" >> "$out/summary.txt"
done
if [ -n "${SKIP_BENCH:-}" ]; then cat "$out/summary.txt"; exit 0; fi
for mode in float exact; do
  VASCO_CUDA_PROFILE=1 build/bin/log2map --backend cuda --cuda-mode $mode logs/fr079-complete.gfs.log.gz /tmp/fr079_$mode.map.gz >> "$out/profile.txt" 2>&1
done
build/bin/oracle_o2_bench --runs 3 > "$out/oracle_o2.txt" 2>&1
build/bin/parse_bench > "$out/parse.txt" 2>&1
timeout 300 build/bin/mapping_bench --runs "$runs" > "$out/bench.txt" 2> "$out/bench.err"
cat "$out/summary.txt" "$out/profile.txt" "$out/oracle_o2.txt" "$out/parse.txt" "$out/bench.txt"
