# `make test` is what CI runs (.ci/run) and what a new user runs: it
# installs what it needs into .venv, builds everything and runs every test.

PYTHON ?= python3
VENV   := .venv
VPY    := $(VENV)/bin/python
CARGO  ?= cargo

# One target directory for cargo and maturin, so the core is built once.
export CARGO_TARGET_DIR ?= $(CURDIR)/target

PY_CRATE  := crates/a2ml-py
PY_REQS   := tests/python/requirements.txt
WHEEL_DIR := $(CARGO_TARGET_DIR)/wheels
# The wheel is rebuilt when anything it is built from changes.
PY_INPUTS := $(shell find crates/a2ml-core crates/a2ml-py -type f -not -name '*.pyc') Cargo.toml Cargo.lock

.PHONY: test rust-test py-test python build clean compare

test: rust-test py-test

# A snapshot (insta) that differs fails its test and is never rewritten here, whatever
# INSTA_UPDATE says outside; `cargo insta review` accepts a deliberate change.
rust-test:
	INSTA_UPDATE=no $(CARGO) test --workspace --exclude a2ml-py

# The venv with the build and test tools; remade only when the pins change.
$(VENV)/.tools-installed: $(PY_REQS)
	$(PYTHON) -m venv $(VENV)
	$(VPY) -m pip install --quiet --disable-pip-version-check -r $(PY_REQS)
	touch $@

# Build the abi3 wheel (cp310-abi3) and install it into the venv, as a user's
# `pip install` would.
$(VENV)/.wheel-installed: $(VENV)/.tools-installed $(PY_INPUTS)
	rm -f $(WHEEL_DIR)/a2ml-*.whl
	$(VENV)/bin/maturin build --release --manifest-path $(PY_CRATE)/Cargo.toml --interpreter $(VPY) --out $(WHEEL_DIR)
	$(VPY) -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps $(WHEEL_DIR)/a2ml-*.whl
	touch $@

python: $(VENV)/.wheel-installed

# pytest, then the hand-written stubs: stubtest checks them against the
# installed module, and mypy (strict) checks that the tests type-check
# against them as a user's code would.
py-test: python
	$(VPY) -m pytest tests/python
	$(VPY) -m mypy.stubtest a2ml --mypy-config-file tests/python/mypy.ini
	$(VPY) -m mypy --config-file tests/python/mypy.ini tests/python

build:
	$(CARGO) build --release -p a2ml-cli

# Side by side with the peers users would pick instead (benches/compare/README.md): the
# peers and a release wheel of a2ml go into a venv of their own, never into .venv, and
# `make test` never runs them. Each script prints its table.
COMPARE_VENV    := .venv-compare
COMPARE_PY      := $(COMPARE_VENV)/bin/python
COMPARE_REQS    := benches/compare/requirements.txt
# Peers that may not install here (vamp-planner, ompl): each line tried on its own, a
# failure reported and skipped; the script of that peer then runs without it.
COMPARE_OPTIONAL := benches/compare/requirements-optional.txt
COMPARE_SCRIPTS := $(wildcard benches/compare/kinematics.py benches/compare/rrt.py)

$(COMPARE_VENV)/.tools-installed: $(COMPARE_REQS) $(COMPARE_OPTIONAL)
	$(PYTHON) -m venv $(COMPARE_VENV)
	$(COMPARE_PY) -m pip install --quiet --disable-pip-version-check -r $(COMPARE_REQS)
	@grep -v '^[[:space:]]*\(#\|$$\)' $(COMPARE_OPTIONAL) | while read -r peer; do \
	  if $(COMPARE_PY) -m pip install --quiet --disable-pip-version-check --only-binary :all: "$$peer" >/dev/null 2>&1; \
	  then echo "compare: optional peer $$peer installed"; \
	  else echo "compare: optional peer $$peer does not install here; its comparison is skipped"; fi; \
	done
	touch $@

$(COMPARE_VENV)/.wheel-installed: $(COMPARE_VENV)/.tools-installed $(PY_INPUTS)
	rm -f $(WHEEL_DIR)/a2ml-*.whl
	$(COMPARE_VENV)/bin/maturin build --release --manifest-path $(PY_CRATE)/Cargo.toml --interpreter $(COMPARE_PY) --out $(WHEEL_DIR)
	$(COMPARE_PY) -m pip install --quiet --disable-pip-version-check --force-reinstall --no-deps $(WHEEL_DIR)/a2ml-*.whl
	touch $@

compare: $(COMPARE_VENV)/.wheel-installed
	for script in $(COMPARE_SCRIPTS); do $(COMPARE_PY) $$script || exit 1; done

clean:
	$(CARGO) clean
	rm -rf $(VENV) $(COMPARE_VENV)
