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
echo "install_test: pkg-config, find_package, CARMEN's library names (static and shared) and a program's own" \
     "libglobal all give CARMEN's map"
