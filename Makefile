# Thin wrapper around CMake. `make` builds (Release) in build/, `make test`
# builds and runs the test suite, `make demo` maps the bundled fr079 log.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=

.PHONY: all configure test test-full demo bench deps clean

all: configure
	cmake --build $(BUILD) -j $(JOBS)

configure:
	@test -f $(BUILD)/CMakeCache.txt || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

test: all
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

# Every case of the golden protocol, by hash, against the logs in ../shared/data (slow).
test-full: all
	cd $(BUILD) && ctest --output-on-failure -L slow

demo: all
	$(BUILD)/bin/log2map logs/fr079-complete.gfs.log.gz $(BUILD)/fr079.png $(BUILD)/fr079.map.gz

bench: all
	$(BUILD)/bin/mapping_bench

# Installs what is missing through apt-get (Debian/Ubuntu; needs root or sudo).
DEPS_PKGS = cmake g++ make zlib1g-dev libpng-dev libgtest-dev libgmock-dev libeigen3-dev libcli11-dev pkg-config
deps:
	@missing=""; for p in $(DEPS_PKGS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	else echo "all dependencies present"; fi

clean:
	rm -rf $(BUILD)
