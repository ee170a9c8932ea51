# Two commands on a fresh Debian/Ubuntu machine with Rust installed:
#   make run    build and simulate both benchmark systems (installs system packages first)
#   make test   the whole test suite, release build
# The system libraries (HDF5, OpenBLAS) are installed through apt when missing, as root or
# through sudo.

SYSTEM_PACKAGES := libhdf5-dev libopenblas-dev pkg-config
SUDO := $(shell [ "$$(id -u)" = 0 ] || echo sudo)

.PHONY: run test bench deps

deps:
	@missing=""; \
	for p in $(SYSTEM_PACKAGES); do dpkg -s $$p >/dev/null 2>&1 || missing="$$missing $$p"; done; \
	if [ -n "$$missing" ]; then \
		echo "installing system packages:$$missing"; \
		$(SUDO) apt-get update -qq && \
		DEBIAN_FRONTEND=noninteractive $(SUDO) apt-get install -y -qq --no-install-recommends $$missing; \
	fi

run: deps
	cargo build --release
	./target/release/flexrom demo data/models/pendulum.toml data/models/fourbar.toml

test: deps
	cargo test --release

bench: deps
	cargo bench --bench full_order
