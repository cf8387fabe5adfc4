#!/usr/bin/env bash
# The JIT path, on a machine with a GPU: a build holding PTX alone (compute_75,
# no machine code for any GPU) must run everything the default build runs.
# It builds build-ptx with CMAKE_CUDA_ARCHITECTURES=75-virtual, lists what the
# kernels' library holds (cuobjdump), times the first CUDA run with an empty
# JIT cache against the next run (the cache filled) and against a run with
# the cache disabled, then runs the GPU suite and the golden sweep (both CUDA
# modes) on the cached PTX.
# Usage: [GOLDEN_DIR=... GOLDEN_DATA=...] bash bench/jit_check.sh OUTDIR
set -uo pipefail
out=${1:-/tmp/vasco_gpu_jit}
mkdir -p "$out"
b=build-ptx
log=logs/intel.gfs.log.gz
summary="$out/jit_summary.txt"
since() { awk -v a="$1" -v b="$EPOCHREALTIME" 'BEGIN { printf "%.3f", b - a }'; }
: > "$summary"

t0=$EPOCHREALTIME
cmake -S . -B $b -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=75-virtual > "$out/ptx_configure.log" 2>&1 &&
  cmake --build $b -j "$(nproc)" > "$out/ptx_build.log" 2>&1 || { tail -40 "$out/ptx_build.log"; exit 1; }
printf 'PTX-only build: %.0f s on %s cores\n' "$(since "$t0")" "$(nproc)" >> "$summary"
kernels=$(find $b -name 'libvasco_cuda_kernels.a' | head -1)
{
  echo "cuobjdump --list-elf --list-ptx $kernels:"
  cuobjdump --list-elf --list-ptx "$kernels" 2>&1 | sed 's/^/  /' | sort -u
} >> "$summary"

# Wall-clock seconds of one log2map run on the GPU, in either mode.
run_s() {
  local t
  t=$EPOCHREALTIME
  "$b/bin/log2map" --backend cuda --cuda-mode "$1" --quiet "$log" "$out/jit_$1.map.gz" || echo "log2map failed" >> "$summary"
  since "$t"
}
export CUDA_CACHE_PATH="$out/jit_cache"
rm -rf "$CUDA_CACHE_PATH"
for mode in float exact; do
  first=$(run_s $mode); second=$(run_s $mode)
  nocache=$(CUDA_CACHE_DISABLE=1 run_s $mode)
  printf 'log2map --backend cuda --cuda-mode %-5s %s: empty JIT cache %.3f s, cache filled %.3f s, cache disabled %.3f s\n' \
    $mode "$(basename $log)" "$first" "$second" "$nocache" >> "$summary"
done
echo "JIT cache: $(du -sh "$CUDA_CACHE_PATH" | cut -f1)" >> "$summary"

(cd $b && timeout 300 ctest -j 8 --timeout 200 -L gpu -LE slow --output-on-failure > "$out/ptx_ctest.log" 2>&1)
echo "PTX-only ctest -L gpu rc=$?: $(grep -E 'tests passed|tests failed' "$out/ptx_ctest.log")" >> "$summary"
grep -E "\(Failed\)|\(Timeout\)" "$out/ptx_ctest.log" >> "$summary"
if [ -n "${GOLDEN_DIR:-}" ]; then
  timeout 300 $b/bin/golden_check --golden "$GOLDEN_DIR" --data "$GOLDEN_DATA" \
    --paths cuda_exact,mapper/cuda,egrid_c_api/cuda_exact,cuda_float,mapper-grown/cuda > "$out/ptx_golden.txt" 2>&1
  echo "PTX-only golden_check rc=$?" >> "$summary"
  sed -n '/^summary/,$p' "$out/ptx_golden.txt" >> "$summary"
fi
cat "$summary"
