# GRANULAR-CHARGED: the two commands of the README.
#   make demo   install what is missing, obtain LAMMPS, build, run the reduced deposition study
#   make test   install what is missing, obtain LAMMPS, build, run every test (ctest)
# Options: LAMMPS_VERSION=20250204 (the older supported release; default 20260704, in build/),
#          LAMMPS_SOURCE_DIR=/path/to/lammps (own checkout), BUILD_DIR=build, JOBS=<n>
LAMMPS_VERSION ?=
LAMMPS_SOURCE_DIR ?=
# the non-default release builds in a folder of its own, so both can live side by side
BUILD_DIR ?= build$(if $(LAMMPS_VERSION),-$(LAMMPS_VERSION))
JOBS ?= $(shell nproc)
# ccache: paths relative to the checkout, so a fresh clone elsewhere reuses the cache
export CCACHE_BASEDIR := $(CURDIR)
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1

.PHONY: deps configure build test demo clean

deps:
	@scripts/install-deps.sh

$(BUILD_DIR)/CMakeCache.txt:
	$(MAKE) deps
	cmake -S . -B $(BUILD_DIR) -G Ninja -D CMAKE_BUILD_TYPE=Release \
	  $(if $(LAMMPS_SOURCE_DIR),-D LAMMPS_SOURCE_DIR=$(abspath $(LAMMPS_SOURCE_DIR))) \
	  $(if $(LAMMPS_VERSION),-D LAMMPS_VERSION=$(LAMMPS_VERSION))

configure: deps $(BUILD_DIR)/CMakeCache.txt

build: configure
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS) --timeout 1500

demo: build
	. $(BUILD_DIR)/env.sh && /usr/bin/python3 -m granular_charged demo --build-dir $(BUILD_DIR) --jobs 2

clean:
	rm -rf $(BUILD_DIR)
