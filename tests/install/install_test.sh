#!/usr/bin/env bash
# Installs the build into a temporary prefix and builds a CARMEN-style client
# against the *installed* tree three ways — pkg-config, find_package, and
# CARMEN's own library names (-legrid -lmap_io -lreadlog) — then compares each
# client's map with CARMEN's golden map of the same log (mapdiff: identical).
#   install_test.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1 src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
golden="$src/tests/data/golden/maps/intel.gfs__vasco_default_ds4.map.gz"
log="$src/logs/intel.gfs.log.gz"
cmake --install "$build" --prefix "$tmp/prefix" > "$tmp/install.log"
export PKG_CONFIG_PATH="$tmp/prefix/lib/pkgconfig"

# 1. pkg-config alone, a C compiler.
cc -std=c99 -o "$tmp/client_pc" "$src/tests/install/carmen_client.c" $(pkg-config --cflags --libs vasco_gpu)
"$tmp/client_pc" "$log" "$tmp/pc.map"
"$build/bin/mapdiff" -q "$golden" "$tmp/pc.map"

# 2. find_package(vasco_gpu).
cmake -S "$src/tests/install" -B "$tmp/consumer" -DCMAKE_PREFIX_PATH="$tmp/prefix" -DCMAKE_BUILD_TYPE=Release > "$tmp/consumer.log"
cmake --build "$tmp/consumer" > "$tmp/consumer_build.log"
"$tmp/consumer/carmen_client" "$log" "$tmp/cmake.map"
"$build/bin/mapdiff" -q "$golden" "$tmp/cmake.map"

# 3. A CARMEN Makefile's -l flags, with the rest of pkg-config's list.
cc -std=c99 -o "$tmp/client_names" "$src/tests/install/carmen_client.c" -I"$tmp/prefix/include" \
   -L"$tmp/prefix/lib" -legrid -lreadlog -lmap_io $(pkg-config --libs vasco_gpu)
"$tmp/client_names" "$log" "$tmp/names.map"
"$build/bin/mapdiff" -q "$golden" "$tmp/names.map"
echo "install_test: pkg-config, find_package and CARMEN's library names all give CARMEN's map"
