# Difference Engine - top-level targets. `make help` lists them.
# Every target sets itself up on first use (scripts/setup.sh: .venv from PyPI).
SHELL := /bin/bash
ROOT := $(abspath .)
VENV := $(ROOT)/.venv
SETUP := $(VENV)/.setup-stamp
ENV := source $(VENV)/env.sh &&
PY := $(VENV)/bin/python
DE := $(VENV)/bin/diffengine
OUT := $(ROOT)/out
DEMO_FILE ?= sw/scenes/fig7_25.cmd

.PHONY: help setup demo test test-py test-c test-rtl test-long bench clean

help:
	@echo "make demo        render the shipped default command file to out/demo.png"
	@echo "make test        run every test (sets itself up on first use)"
	@echo "make test-long   long random regressions (not part of make test)"
	@echo "make bench       speed benchmarks, recorded in docs/performance.md"
	@echo "make setup       create .venv from scripts/requirements.txt"
	@echo "make clean       remove build products (keeps .venv)"

setup: $(SETUP)
$(SETUP): scripts/setup.sh scripts/requirements.txt sw/pyproject.toml
	./scripts/setup.sh

demo: $(SETUP)
	@mkdir -p $(OUT)
	$(ENV) $(DE) model $(DEMO_FILE) -o $(OUT)/demo.png
	$(ENV) $(DE) plot $(DEMO_FILE) -o $(OUT)/demo_scanlines.png
	@echo "demo: wrote $(OUT)/demo.png and $(OUT)/demo_scanlines.png"

# make test = Python model tests + C host tests (if present) + RTL tests (if present).
test: test-py test-c test-rtl

test-py: $(SETUP)
	$(ENV) cd sw && $(PY) -m pytest -q -n 2 tests

test-c:
	@if [ -f sw/hsr/Makefile ]; then $(MAKE) -C sw/hsr test; fi

test-rtl: $(SETUP)
	@if ls tb/*/test_*.py >/dev/null 2>&1; then $(ENV) cd tb && $(PY) -m pytest -q -n 2 .; fi

bench: $(SETUP)
	$(ENV) $(PY) scripts/bench_model.py

clean:
	rm -rf $(OUT) build sim/out
