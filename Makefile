# Thin wrapper around CMake. `make` builds (Release) in build/, `make test`
# builds and runs the test suite, `make golden` checks every public CARMEN
# golden map, `make demo` maps the bundled fr079 log.
BUILD ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CMAKE_FLAGS ?=
GOLDEN_DIR ?= ../shared/golden
GOLDEN_DATA ?= ../shared/data

.PHONY: all configure test golden demo bench deps clean

all: configure
	cmake --build $(BUILD) -j $(JOBS)

configure: deps
	@test -f $(BUILD)/CMakeCache.txt || cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release $(CMAKE_FLAGS)

test: all
	cd $(BUILD) && ctest --output-on-failure -j $(JOBS) -LE slow

# Every public CARMEN golden case (../shared/golden) through every exact path,
# a line per case and path, then a summary; float paths reported against them.
golden: all
	@$(BUILD)/bin/golden_check --golden $(GOLDEN_DIR) --data $(GOLDEN_DATA); rc=$$?; \
	  if [ $$rc = 77 ]; then echo "make golden: $(GOLDEN_DIR) is not here: no golden maps to check against"; exit 0; fi; exit $$rc

demo: all
	$(BUILD)/bin/log2map logs/fr079-complete.gfs.log.gz $(BUILD)/fr079.png $(BUILD)/fr079.map.gz

# Parse speed, the -O2 reference, the mapping table, then the mapping-session
# table (GPU rows when a GPU is usable).
bench: all
	$(BUILD)/bin/parse_bench
	$(BUILD)/bin/oracle_o2_bench
	$(BUILD)/bin/mapping_bench
	$(BUILD)/bin/session_bench

# Installs what is missing through apt-get (Debian/Ubuntu; needs root or
# sudo); a no-op when everything is there. Every build runs it first.
DEPS_PKGS = cmake g++ make zlib1g-dev libpng-dev libgtest-dev libgmock-dev libcli11-dev libssl-dev pkg-config
deps:
	@command -v dpkg >/dev/null 2>&1 || { echo "make deps: no dpkg here; install $(DEPS_PKGS) by hand"; exit 0; }; \
	missing=""; for p in $(DEPS_PKGS); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
	  echo "installing:$$missing"; \
	  SUDO=""; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq $$missing; \
	fi

clean:
	rm -rf $(BUILD)
