#!/usr/bin/env bash
# Installs the build into a temporary prefix and builds a CARMEN-style client
# against the *installed* tree, static and shared: pkg-config (vasco_gpu,
# vasco_gpu-static), find_package (vasco_gpu::vasco_gpu and
# vasco_gpu::vasco_gpu_shared), CARMEN's own library names (-legrid -lmap_io
# -lreadlog), and those names beside a stand-in for CARMEN's libglobal (whose
# carmen_stdio must win over ours without a clash). Each client's map is
# compared with CARMEN's golden map of the same log (mapdiff: identical), and
# each binary is checked to use the library it was meant to.
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
golden="$src/tests/data/golden/maps/intel.gfs__vasco_default_ds4.map.gz"
log="$src/logs/intel.gfs.log.gz"
client="$src/tests/install/carmen_client.c"
prefix="$tmp/prefix"
lib="$prefix/lib"
cmake --install "$build" --prefix "$prefix" > "$tmp/install.log"
export PKG_CONFIG_PATH="$lib/pkgconfig"

fail() { echo "install_test: $*" >&2; exit 1; }

# Runs client binary $1 (named $2) on the log and compares its map with the golden.
run_and_compare() {
  "$1" "$log" "$tmp/$2.map" 2> "$tmp/$2.err" || { cat "$tmp/$2.err" >&2; fail "$2: the client failed"; }
  "$build/bin/mapdiff" -q "$golden" "$tmp/$2.map" || fail "$2: the map differs from CARMEN's"
}

# $1 uses the shared library (yes) or not (no).
expect_shared() {
  local needed
  needed=$(readelf -d "$1" | grep -c 'NEEDED.*libvasco_gpu\.so' || true)
  if [[ $2 == yes && $needed == 0 ]]; then fail "$1 does not use libvasco_gpu.so"; fi
  if [[ $2 == no && $needed != 0 ]]; then fail "$1 uses libvasco_gpu.so, should be static"; fi
}

# 0. What is installed: both kinds of library, under both kinds of name.
for name in vasco_gpu carmen_compat egrid map_io readlog; do
  [[ -e "$lib/lib$name.a" ]] || fail "lib$name.a is not installed"
done
for name in vasco_gpu egrid map_io readlog; do
  [[ -e "$lib/lib$name.so" ]] || fail "lib$name.so is not installed"
done
[[ -f "$prefix/include/carmen/map.h" ]] || fail "carmen/map.h is not installed"
[[ ! -e "$prefix/include/vasco_gpu/internal" ]] || fail "the internal headers (vasco_gpu/internal/) are installed"
# Every installed header stands on its own: none reaches a header that is not installed.
for h in "$prefix"/include/vasco_gpu/*.h* "$prefix"/include/carmen_compat/*.h; do
  echo "#include \"${h#"$prefix/include/"}\"" | c++ -std=c++17 -fsyntax-only -I"$prefix/include" -x c++ - \
    || fail "${h#"$prefix/include/"} does not compile on its own"
done
for h in "$prefix"/include/carmen/*.h "$prefix"/include/vasco_gpu/mapper_c.h; do
  echo "#include \"${h#"$prefix/include/"}\"" | cc -std=c99 -fsyntax-only -I"$prefix/include" -x c - \
    || fail "${h#"$prefix/include/"} does not compile as C on its own"
done

# 1. pkg-config alone (the client itself uses libm), a C compiler and linker.
cc -std=c99 -o "$tmp/pc_shared" "$client" $(pkg-config --cflags --libs vasco_gpu) -lm
expect_shared "$tmp/pc_shared" yes
run_and_compare "$tmp/pc_shared" pc_shared
cc -std=c99 -o "$tmp/pc_static" "$client" $(pkg-config --cflags --libs vasco_gpu-static)
expect_shared "$tmp/pc_static" no
run_and_compare "$tmp/pc_static" pc_static

# 2. find_package(vasco_gpu): static and shared targets.
cmake -S "$src/tests/install" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release \
  > "$tmp/consumer.log"
cmake --build "$tmp/consumer" > "$tmp/consumer_build.log"
expect_shared "$tmp/consumer/carmen_client" no
run_and_compare "$tmp/consumer/carmen_client" cmake_static
expect_shared "$tmp/consumer/carmen_client_shared" yes
run_and_compare "$tmp/consumer/carmen_client_shared" cmake_shared

# 3. A CARMEN Makefile's -l flags. Shared: nothing else is needed.
carmen_flags=(-I"$prefix/include" -L"$lib" -legrid -lreadlog -lmap_io)
cc -std=c99 -o "$tmp/names_shared" "$client" "${carmen_flags[@]}" -Wl,-rpath,"$lib" -lm
expect_shared "$tmp/names_shared" yes
run_and_compare "$tmp/names_shared" names_shared
# Static: the archives under CARMEN's names, then what they need.
static_names=(-I"$prefix/include" -L"$lib" -Wl,-Bstatic -legrid -lreadlog -lmap_io -Wl,-Bdynamic)
cc -std=c99 -o "$tmp/names_static" "$client" "${static_names[@]}" $(pkg-config --libs vasco_gpu-static)
expect_shared "$tmp/names_static" no
run_and_compare "$tmp/names_static" names_static

# 4. Beside CARMEN's own libglobal (a stand-in): its carmen_stdio is used,
# ours gives way without a duplicate-symbol error, static and shared.
cc -std=c99 -c -I"$prefix/include" -o "$tmp/fake_libglobal.o" "$src/tests/install/fake_libglobal.c"
ar rcs "$tmp/libglobal.a" "$tmp/fake_libglobal.o"
cc -std=c99 -o "$tmp/global_static" "$client" -L"$tmp" -lglobal "${static_names[@]}" \
  $(pkg-config --libs vasco_gpu-static)
cc -std=c99 -o "$tmp/global_shared" "$client" -L"$tmp" -lglobal "${carmen_flags[@]}" -Wl,-rpath,"$lib" -lz -lm
expect_shared "$tmp/global_shared" yes
for kind in global_static global_shared; do
  run_and_compare "$tmp/$kind" "$kind"
  grep -q "fake libglobal: carmen_fopen($log)" "$tmp/$kind.err" || fail "$kind: libglobal's carmen_fopen was not used"
done
# CARMEN's own Makefiles' order, -lglobal last: the first library that
# defines carmen_stdio gives it (an archive member is not pulled in for a
# symbol already defined), so ours is used, libglobal's callers included;
# still no duplicate-symbol error and the same map (docs: carmen_stdio and libglobal).
cc -std=c99 -o "$tmp/global_last_static" "$client" "${static_names[@]}" -L"$tmp" -lglobal \
  $(pkg-config --libs vasco_gpu-static)
cc -std=c99 -o "$tmp/global_last_shared" "$client" "${carmen_flags[@]}" -L"$tmp" -lglobal -Wl,-rpath,"$lib" -lz -lm
for kind in global_last_static global_last_shared; do
  run_and_compare "$tmp/$kind" "$kind"
  if grep -q "fake libglobal: carmen_fopen" "$tmp/$kind.err"; then
    fail "$kind: libglobal's carmen_fopen was used after our libraries (the docs say ours is)"
  fi
done
# 5. A CMake project in C alone: find_package + the static target, nothing more.
cmake -S "$src/tests/install/c_project" -B "$tmp/c_project" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_BUILD_TYPE=Release > "$tmp/c_project.log" 2>&1 || { cat "$tmp/c_project.log" >&2; fail "C project: configure"; }
cmake --build "$tmp/c_project" > "$tmp/c_project_build.log" 2>&1 \
  || { tail -30 "$tmp/c_project_build.log" >&2; fail "C project: build"; }
run_and_compare "$tmp/c_project/carmen_client" c_project

# 6. The CUDA runtime is inside our libraries: no libcudart.so is needed to run
# a static client (nor by libvasco_gpu.so), and the static one runs with an
# empty library path.
for bin in "$tmp/pc_static" "$tmp/names_static" "$tmp/consumer/carmen_client" "$lib/libvasco_gpu.so"; do
  [[ -e $bin ]] || continue
  if readelf -d "$bin" | grep -q 'NEEDED.*libcudart'; then fail "$bin needs libcudart.so"; fi
done
env LD_LIBRARY_PATH= "$tmp/pc_static" "$log" "$tmp/no_path.map" 2> "$tmp/no_path.err" \
  || { cat "$tmp/no_path.err" >&2; fail "the static client does not run with an empty library path"; }

# 7. Stand-ins for CARMEN's own programs, unchanged CARMEN-style callers of
# our API (tests/install/*_standin.c), built through pkg-config shared.
standin() { cc -std=c99 -o "$tmp/$1" "$src/tests/install/$1.c" $(pkg-config --cflags --libs vasco_gpu) -lm; }
for p in maptool_standin logtool_standin oldlaser_standin make_named_maps; do standin "$p"; done
maps="$tmp/maps"
mkdir -p "$maps"
"$tmp/make_named_maps" "$maps" > "$maps/strip_bytes"
# Runs a stand-in; a crash (a signal) fails the test whatever the program printed.
run_standin() {
  local rc=0
  "$@" > "$tmp/standin.out" 2> "$tmp/standin.err" || rc=$?
  if (( rc >= 128 )); then cat "$tmp/standin.err" >&2; fail "$* died of signal $((rc - 128))"; fi
  return $rc
}
expect_out() { grep -qxF -- "$1" "$tmp/standin.out" || { cat "$tmp/standin.out" >&2; fail "$2: no line '$1'"; }; }
size_of() { stat -c %s "$1"; }

# maptool info on a map whose only gridmap and places are named: CARMEN reads them.
run_standin "$tmp/maptool_standin" info "$maps/named_only.map" || fail "maptool info: failed on named chunks"
expect_out "size : 100 x 120" "maptool info (named gridmap)"
expect_out "places : 3" "maptool info (named places)"
# toppm: the named gridmap as a picture, and no stderr line for the missing off-limits chunk.
run_standin "$tmp/maptool_standin" toppm "$maps/named_only.map" "$tmp/named.ppm" || fail "maptool toppm failed"
[[ ! -s "$tmp/standin.err" ]] || { cat "$tmp/standin.err" >&2; fail "maptool toppm wrote to stderr"; }
[[ $(head -c 2 "$tmp/named.ppm") == P6 ]] || fail "maptool toppm: not a PPM"
# add_place reallocs the places read: no crash, and the gridmap survives.
run_standin "$tmp/maptool_standin" add_place "$maps/named_only.map" p 1 2 || fail "maptool add_place failed"
run_standin "$tmp/maptool_standin" info "$maps/named_only.map" || fail "maptool info after add_place"
expect_out "size : 100 x 120" "maptool info after add_place"
# strip keeps what CARMEN keeps: only the unnamed gridmap goes, named gridmaps stay.
while read -r name bytes; do
  run_standin "$tmp/maptool_standin" strip "$maps/$name" "$maps/stripped_$name" gridmap || fail "strip $name"
  want=$(( $(size_of "$maps/$name") - bytes ))
  got=$(size_of "$maps/stripped_$name")
  [[ $got == "$want" ]] || fail "strip $name gridmap: $got bytes, CARMEN keeps the named chunks: $want"
done < "$maps/strip_bytes"
run_standin "$tmp/maptool_standin" info "$maps/stripped_rich.map" || fail "info on the stripped map"
expect_out "size : 110 x 110" "maptool info of rich.map without its unnamed gridmap"
# A damaged trailing chunk does not hide the intact gridmap before it.
run_standin "$tmp/maptool_standin" info "$src/tests/data/maps/damaged/thickwean.map.gz" \
  || fail "maptool info on thickwean (damaged last chunk)"
expect_out "size : 477 x 170" "maptool info on thickwean"

# clf-get-oldlaser: a ROBOTLASER1 line with a huge remission count between two good ones.
good="ROBOTLASER1 0 -1.570796 3.141593 0.785398 81.900000 0.010000 0 4 1.00 2.00 3.00 4.00 0"
pose="0.100000 0.200000 0.300000 0.000000 0.000000 0.000000 0.000000 0.000000 0.300000 0.100000 1000000.000000"
printf '%s\n' "$good $pose 999.500000 test 0.500000" \
  "ROBOTLASER1 0 -1.570796 3.141593 0.785398 81.900000 0.010000 0 4 1.00 2.00 3.00 4.00 2000000000 1.0 $pose 1000.0 test 1.0" \
  "$good $pose 1001.500000 test 1.500000" > "$tmp/huge_remissions.log"
run_standin "$tmp/oldlaser_standin" "$tmp/huge_remissions.log" || true
expect_out "FLASER 4 1.00 2.00 3.00 4.00 0.100000 0.200000 0.300000 0.000000 0.000000 0.000000 1001.500000 test 1001.500000" \
  "clf-get-oldlaser after a bad line"

# logtool: the same counts as the log's own lines, through our carmen_stdio and
# through a CARMEN-like libglobal; on a corrupt gzip log, a message and no crash.
zcat "$log" > "$tmp/plain.log"
want_lasers=$(grep -c -E '^(FLASER|ROBOTLASER1) ' "$tmp/plain.log")
cc -std=c99 -o "$tmp/logtool_global" "$src/tests/install/logtool_standin.c" -L"$tmp" -lglobal "${static_names[@]}" \
  $(pkg-config --libs vasco_gpu-static)
for tool in logtool_standin logtool_global; do
  run_standin "$tmp/$tool" "$log" || fail "$tool on $log"
  grep -qE "^messages [0-9]+ lasers $want_lasers\$" "$tmp/standin.out" || { cat "$tmp/standin.out" >&2; fail "$tool: want $want_lasers lasers"; }
  run_standin "$tmp/$tool" "$src/tests/data/logs/corrupt.log.gz" || true
done

echo "install_test: pkg-config, find_package (C and C++ projects), CARMEN's library names (static and shared)," \
     "a program's own libglobal and stand-ins for CARMEN's maptool, logtool and clf-get-oldlaser all behave as CARMEN's"
