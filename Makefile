# Two commands on a fresh Debian 12 machine (see README.md):
#   make demo   installs what is missing, builds, runs the main demo, prints where results are
#   make test   installs what is missing, builds, runs ctest, pytest and pytest under mpirun -n 2
# Only Debian's archive is used. The system interpreter is named explicitly: the
# python3 first on PATH on these machines lacks Debian's packages.

PYTHON  ?= /usr/bin/python3
BUILD   ?= build
OUT     ?= results
JOBS    ?= 2
APT_PACKAGES := cmake make gcc g++ python3-sympy python3-dolfinx libdolfinx-dev python3-gmsh gmsh \
	libeigen3-dev python3-mpi4py python3-meshio pybind11-dev python3-pytest \
	python3-scipy python3-matplotlib python3-contourpy libgtest-dev libbenchmark-dev \
	python3-setuptools python3-venv openmpi-bin libnanoflann-dev libopenblas0-pthread python3-h5py
# only `make bench` installs these: benchmarks/work_precision.py compares with GetFEM's nodal P1,
# benchmarks/dem_peer.py runs LAMMPS's GRANULAR package (lmp) on demos/granular_column.py's test
BENCH_PACKAGES := python3-getfem lammps
# only `make test` installs these: tests/io/test_paraview.py opens the outputs in ParaView 5.11
# (pvpython and paraview.simple; python3-paraview pulls in paraview) offscreen under xvfb-run
# (Debian's ParaView renders through GLX only; xauth, which xvfb-run needs, is a Recommends)
TEST_PACKAGES := python3-paraview xvfb xauth
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1
export OMPI_MCA_rmaps_base_oversubscribe := 1
# demos, tests and benchmarks import dolfinx_forms and meshes from this tree (no sys.path edits)
export PYTHONPATH := $(CURDIR)$(if $(PYTHONPATH),:$(PYTHONPATH))
MPIRUN  ?= mpirun -n 2
SUDO    := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: deps bench-deps test-deps build warm test test-cpp test-python test-mpi demo bench calibrate \
	format clean

# $(call apt_install,PACKAGES): install those of PACKAGES that are missing
define apt_install
	@missing=$$(for p in $(1); do \
	  dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q 'install ok installed' || echo $$p; done); \
	if [ -n "$$missing" ]; then \
	  echo "Installing Debian packages:" $$missing; \
	  $(SUDO) apt-get update -q && \
	  DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -q --no-install-recommends $$missing; \
	fi
endef

deps:
	$(call apt_install,$(APT_PACKAGES))

bench-deps:
	$(call apt_install,$(BENCH_PACKAGES))

# after deps: two apt-get runs at once (make -j) would fight over dpkg's lock
test-deps: deps
	$(call apt_install,$(TEST_PACKAGES))

build: deps
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=$(PYTHON) \
	  -DCONTACT_BUILD_TESTS=ON -DCONTACT_BUILD_BENCHMARKS=ON
	cmake --build $(BUILD) -j $(JOBS)

test: build test-deps
	$(MAKE) --no-print-directory test-cpp test-python test-mpi

test-cpp:
	ctest --test-dir $(BUILD) --output-on-failure --no-tests=error -j $(JOBS)

test-python:
	$(PYTHON) -m pytest -m "not mpi" --color=no

test-mpi:
	OPENBLAS_NUM_THREADS=1 $(MPIRUN) $(PYTHON) -m pytest -m mpi -p no:cacheprovider --color=no

# compile the Hertz demo's forms once, on a coarse mesh (FFCx's JIT cache, ~/.cache/fenics,
# keys on the forms, not the mesh): the first real run starts warm (cut path: 1.4 s of JIT)
warm: build
	$(PYTHON) demos/hertz.py --discretization cut --h 0.25 --out $(BUILD)/warm/hertz-cut > /dev/null
	$(PYTHON) demos/hertz.py --h 0.25 --out $(BUILD)/warm/hertz > /dev/null

demo: warm
	$(PYTHON) demos/hertz.py --discretization cut --out $(OUT)/hertz

bench: build bench-deps
	mkdir -p benchmarks/results
	$(BUILD)/cpp_contact/contact_bench --benchmark_out=benchmarks/results/geometry.json \
	  --benchmark_out_format=json
	$(PYTHON) benchmarks/plot_geometry.py benchmarks/results/geometry.json
	$(PYTHON) benchmarks/work_precision.py --out-dir benchmarks/results

# the studies behind dolfinx_forms/defaults.py's tuned numbers (a few minutes)
calibrate: build
	$(PYTHON) benchmarks/calibration.py --out-dir benchmarks/results

format:
	clang-format -i cpp_contact/*/*.h cpp_contact/*/*.cpp
	black -q -l 100 dolfinx_forms tests demos benchmarks meshes 2>/dev/null || true

clean:
	rm -rf $(BUILD) dolfinx_forms/_cpp*.so
