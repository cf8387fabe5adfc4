# Thin wrapper around CMake. `make` builds (Release) in build/, `make test`
# builds and runs the test suite, `make golden` checks every public CARMEN
# golden map, `make test-sanitize` and `make fuzz` run the suite under
# ASan/UBSan and the libFuzzer targets, `make demo` maps the bundled fr079 log.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
# The CUDA code of a development build (make, make test, make demo): machine
# code for the GPU of this machine where one is visible, PTX alone where none
# is (a GPU found later compiles it once, on first use). `make install` and the
# pip wheel build every architecture of cmake/cuda_architectures.cmake instead.
DEV_CUDA_ARCHS ?= $(shell nvidia-smi -L >/dev/null 2>&1 && echo native || echo 75-virtual)
CONFIGURE_ARGS = -DCMAKE_BUILD_TYPE=Release -DCMAKE_CUDA_ARCHITECTURES=$(DEV_CUDA_ARCHS) $(CMAKE_FLAGS)
INSTALL_BUILD ?= build-install
INSTALL_CONFIGURE_ARGS = -DCMAKE_BUILD_TYPE=Release -DVASCO_GPU_BUILD_TESTS=OFF -DVASCO_GPU_BUILD_BENCH=OFF $(CMAKE_FLAGS)

# $(call configure_in,DIR,ARGS): configures DIR when it has no cache yet or was
# last configured by make with other arguments, so that a changed CMAKE_FLAGS
# takes effect. (A -D flag, once given, stays in DIR's cache when a later make
# leaves it out, as with cmake itself; `make clean` forgets it.)
configure_in = if [ ! -f $(1)/CMakeCache.txt ] || [ "$$(cat $(1)/.make-configure-args 2>/dev/null)" != "$(2)" ]; then \
	  cmake -S . -B $(1) $(2) && echo "$(2)" > $(1)/.make-configure-args; fi
GOLDEN_DIR ?= ../shared/golden
GOLDEN_DATA ?= ../shared/data

.PHONY: all configure test test-sanitize fuzz fuzz-python fuzz-smoke golden demo bench bench-peers install deps clean

all: configure
	cmake --build $(BUILD) -j $(JOBS)

configure: deps
	@$(call configure_in,$(BUILD),$(CONFIGURE_ARGS))

# After the suite, each test that skipped and the reason it gave (tests/skipped_report.py).
test: all
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow; rc=$$?; \
	  python3 $(CURDIR)/tests/skipped_report.py $(abspath $(BUILD)) || true; exit $$rc

# Installs headers, static and shared libraries (also under CARMEN's names libegrid,
# libmap_io, libreadlog), tools, the CMake package, vasco_gpu.pc (shared) and
# vasco_gpu-static.pc into PREFIX, from a build of its own ($(INSTALL_BUILD):
# no tests, CUDA code for every architecture).
PREFIX ?= /usr/local
install: deps
	@$(call configure_in,$(INSTALL_BUILD),$(INSTALL_CONFIGURE_ARGS))
	cmake --build $(INSTALL_BUILD) -j $(JOBS)
	cmake --install $(INSTALL_BUILD) --prefix $(PREFIX)

# The CPU test suite under AddressSanitizer + UndefinedBehaviorSanitizer
# (a separate build in build-asan).
test-sanitize: deps
	@test -f build-asan/CMakeCache.txt || cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DVASCO_GPU_CUDA=OFF -DVASCO_GPU_SANITIZE=ON -DVASCO_GPU_BUILD_BENCH=OFF
	cmake --build build-asan -j $(JOBS)
	cd build-asan && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 ctest --output-on-failure -j $(JOBS) -LE slow

# libFuzzer targets (clang), seeded from the test data: each runs
# FUZZ_SECONDS (default 300; CI's fuzz-smoke: 20). New inputs go to build-fuzz/corpus.
FUZZ_SECONDS ?= 300
FUZZ_TARGETS = fuzz_log_reader fuzz_ini fuzz_map_reader fuzz_map_io fuzz_readlog fuzz_egrid fuzz_pipeline fuzz_session \
               fuzz_pose_file fuzz_map_server
fuzz: deps
	@test -f build-fuzz/CMakeCache.txt || CC=clang CXX=clang++ cmake -S . -B build-fuzz \
	  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DVASCO_GPU_CUDA=OFF -DVASCO_GPU_FUZZ=ON \
	  -DVASCO_GPU_BUILD_TESTS=OFF -DVASCO_GPU_BUILD_BENCH=OFF
	cmake --build build-fuzz -j $(JOBS) --target $(FUZZ_TARGETS)
	@set -e; for t in $(FUZZ_TARGETS); do \
	  mkdir -p build-fuzz/corpus/$$t; \
	  echo "== $$t ($(FUZZ_SECONDS) s)"; \
	  build-fuzz/bin/$$t -max_total_time=$(FUZZ_SECONDS) -rss_limit_mb=2048 -timeout=20 -print_final_stats=1 \
	    build-fuzz/corpus/$$t fuzz/seeds/$$t > build-fuzz/$$t.log 2>&1 || { tail -60 build-fuzz/$$t.log; exit 1; }; \
	  grep -E "executed_units|new_units_added" build-fuzz/$$t.log; \
	done
	@$(MAKE) --no-print-directory fuzz-python

# The Python fuzzers. That of the bag reader's and the node's tf tree (fuzz/fuzz_bag_tf.py): NumPy only, run
# by FUZZ_PYTHON (default python3; CI gives its venv's). Without NumPy there it says so and stops.
FUZZ_PYTHON ?= python3
# Then the node's fuzzer (fuzz/fuzz_node.py: the ROS 2 node in-process), run by FUZZ_ROS_PYTHON (default
# FUZZ_PYTHON), a Python with rclpy, the node's messages and vasco_gpu; without them it is skipped, said
# so, unless VASCO_REQUIRE_ROS_TESTS=1, where that fails.
FUZZ_ROS_PYTHON ?= $(FUZZ_PYTHON)
fuzz-python:
	@$(FUZZ_PYTHON) -c "import numpy" 2>/dev/null || { echo "fuzz-python: $(FUZZ_PYTHON) has no NumPy: give FUZZ_PYTHON=a Python with NumPy"; exit 1; }
	@mkdir -p build-fuzz
	@echo "== fuzz_bag_tf ($(FUZZ_SECONDS) s)"
	$(FUZZ_PYTHON) fuzz/fuzz_bag_tf.py --seconds $(FUZZ_SECONDS) --artifact-dir build-fuzz
	@if $(FUZZ_ROS_PYTHON) -c "import rclpy, tf2_msgs, vasco_gpu.ros.node" 2>/dev/null; then \
	  echo "== fuzz_node ($(FUZZ_SECONDS) s)"; \
	  echo "$(FUZZ_ROS_PYTHON) fuzz/fuzz_node.py --seconds $(FUZZ_SECONDS) --artifact-dir build-fuzz"; \
	  $(FUZZ_ROS_PYTHON) fuzz/fuzz_node.py --seconds $(FUZZ_SECONDS) --artifact-dir build-fuzz; \
	elif [ "$$VASCO_REQUIRE_ROS_TESTS" = 1 ]; then \
	  echo "fuzz-python: VASCO_REQUIRE_ROS_TESTS=1 and $(FUZZ_ROS_PYTHON) has no rclpy, tf2_msgs or vasco_gpu.ros: give FUZZ_ROS_PYTHON=a Python with the ROS 2 extra"; exit 1; \
	else \
	  echo "fuzz-python: fuzz_node skipped: $(FUZZ_ROS_PYTHON) has no rclpy, tf2_msgs or vasco_gpu.ros (give FUZZ_ROS_PYTHON=a Python with the ROS 2 extra)"; \
	fi

fuzz-smoke:
	$(MAKE) fuzz FUZZ_SECONDS=20

# Every public CARMEN golden case (../shared/golden) through every exact path,
# a line per case and path, then a summary; float paths reported against them.
golden: all
	@$(BUILD)/bin/golden_check --golden $(GOLDEN_DIR) --data $(GOLDEN_DATA); rc=$$?; \
	  if [ $$rc = 77 ]; then echo "make golden: $(GOLDEN_DIR) is not here: no golden maps to check against"; exit 0; fi; exit $$rc

# Builds log2map alone, then maps the bundled log.
demo: configure
	cmake --build $(BUILD) -j $(JOBS) --target log2map
	$(BUILD)/bin/log2map logs/fr079-complete.gfs.log.gz $(BUILD)/fr079.png $(BUILD)/fr079.map.gz

# Parse speed, the -O2 reference, the mapping table, the large site, cpu_threads
# from one core to all, the mapping-session table (GPU rows when a GPU is
# usable), then the batch rates: bench/run_all.sh runs them in that order and
# writes the whole output, under a header (date, machine, commit), to
# bench/results/bench-DATE.txt (BENCH_OUT=FILE for another), the file the
# docs' performance tables are quoted from.
bench: all
	cmake --build $(BUILD) -j $(JOBS) --target benchmarks
	bash bench/run_all.sh $(BUILD)

# Our CPU backends beside MRPT's COccupancyGridMap2D and OctoMap's OcTree on the same logs and poses.
# Needs the optional packages libmrpt-maps-dev and liboctomap-dev (neither `make deps` nor CI installs
# them; without them the peers' rows say "not built"). The re-configure finds them when they were
# installed after $(BUILD) was first configured.
bench-peers: all
	@cmake -S . -B $(BUILD) > /dev/null
	cmake --build $(BUILD) -j $(JOBS) --target peer_bench
	$(BUILD)/bin/peer_bench

# Installs what is missing through apt-get (Debian/Ubuntu; needs root or
# sudo); a no-op when everything is there. Every build runs it first.
# DEPS_OPTIONAL_PKGS are used when present (libisal-dev: ISA-L's inflate,
# about 3.5x zlib's, for .gz logs; help2man: the tools' man pages); failing to
# install them (no network, no such package) is reported, not an error: the
# build then uses zlib, and makes no man pages.
DEPS_PKGS = cmake g++ make zlib1g-dev libpng-dev libgtest-dev libgmock-dev libcli11-dev libssl-dev pkg-config
DEPS_OPTIONAL_PKGS = libisal-dev help2man
deps:
	@command -v dpkg >/dev/null 2>&1 || { echo "make deps: no dpkg here; install $(DEPS_PKGS) (and, optionally, $(DEPS_OPTIONAL_PKGS)) by hand"; exit 0; }; \
	missing=""; for p in $(DEPS_PKGS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	optional=""; for p in $(DEPS_OPTIONAL_PKGS); do dpkg -s $$p >/dev/null 2>&1 || optional="$$optional $$p"; done; \
	SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing || exit 1; \
	fi; \
	if [ -n "$$optional" ]; then \
	  echo "installing (optional):$$optional"; \
	  { [ -n "$$missing" ] || $$SUDO apt-get update -qq; } >/dev/null 2>&1; \
	  DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$optional >/dev/null 2>&1 \
	    || echo "make deps: optional$$optional not installed (without libisal-dev .gz logs inflate with zlib; without help2man no man pages)"; \
	fi

clean:
	rm -rf $(BUILD) $(INSTALL_BUILD)
