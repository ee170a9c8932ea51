# Two commands on a fresh Debian/Ubuntu machine with Rust installed:
#   make run    build, then train, sweep and validate the POD pipelines of both benchmark
#               systems, writing reports/pendulum and reports/fourbar (installs packages first)
#   make test   the whole test suite, release build
# The system libraries (HDF5, OpenBLAS) are installed through apt when missing, as root or
# through sudo; they are linked statically (build.rs, docs/startup.md), and gfortran brings
# libgfortran.a for OpenBLAS's LAPACK (without it the shared libgfortran.so.5 is linked).
# h5py, matplotlib, pytest, meshio and maturin (the Python package's build and tests, the read-back
# tests, the README's plotting example) are installed with pip when python3 is there and
# they are not.

SYSTEM_PACKAGES := libhdf5-dev libopenblas-dev pkg-config gfortran
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: run test bench bench-routes bench-exudyn deps thesis zoo

deps:
	@missing=""; \
	for p in $(SYSTEM_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
		echo "installing system packages:$$missing"; \
		$(SUDO) apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi
	@if command -v python3 >/dev/null && ! python3 -c "import h5py, numpy, matplotlib, pytest, maturin, meshio" 2>/dev/null; then \
		python3 -m pip install --quiet --root-user-action=ignore h5py numpy matplotlib pytest meshio "maturin>=1.9,<2" 2>/dev/null || echo "note: h5py/matplotlib/pytest/meshio/maturin not installed; the Python tests will fail or be skipped"; \
	fi

run: deps
	cargo build --release
	./target/release/flexrom run pipelines/pendulum.toml
	./target/release/flexrom run pipelines/fourbar.toml
	@echo "flexrom is target/release/flexrom; 'cargo install --path .' puts it on PATH"

test: deps
	# HDF5's file locking stays on: the tests spawn flexrom while they hold HDF5 files open, and
	# the descriptors libhdf5 opens are close-on-exec (src/io/h5_open.rs), so no child keeps a
	# test's file locked. No OPENBLAS_NUM_THREADS: the library sets its OpenBLAS to one thread
	# before its first LAPACK call (src/linalg/lapack.rs), in the test binaries as in flexrom
	cargo test --release
	# the Python package (python/, docs/python.md): built with maturin and installed from this
	# folder, then its tests against the binary just built and the example script
	python3 -m pip install --quiet --root-user-action=ignore --no-build-isolation .
	python3 -m pytest -q python/tests

bench: deps
	cargo build --release
	cargo bench --bench full_order
	cargo bench --bench online

# the four-bar's 100-load sweep by the full route and the reduced one (with and without its
# estimate), whole processes in turn, medians (docs/benchmarks.md, "Full or reduced")
bench-routes: deps
	cargo build --release
	python3 benches/sweep_routes.py

# greedy training and the error estimate on 32 generated mechanisms (docs/zoo.md; ~1 h on 2 cores)
zoo: deps
	cargo build --release
	cargo run --release --example zoo -- --out target/zoo

# the pendulum in Exudyn (in-process) and flexrom (whole process), side by side
bench-exudyn: deps
	cargo build --release
	@python3 -c "import exudyn, h5py" 2>/dev/null || python3 -m pip install --quiet exudyn==1.13.6 h5py numpy
	python3 benches/exudyn/pendulum.py

# the thesis table (docs/thesis.md) on stdout, one line of progress per pipeline on stderr;
# stops at the first failure, naming the command, its exit code and its messages
# (the plain whole-system rows fail by design, as in the thesis, and are marked as such)
thesis: deps
	cargo build --release
	bash pipelines/thesis/reproduce.sh
