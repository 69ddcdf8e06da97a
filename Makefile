# Quick start: `make demo` then `make test`. Both create .venv when missing.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
# Python writes its bytecode caches (__pycache__, ignored by git) under make, whatever the
# shell says: with PYTHONDONTWRITEBYTECODE set, every process (each CLI run a test starts,
# each pytest worker) compiled aura_ums and its dependencies from source again, and
# collecting the tests took 20 s instead of 7.
unexport PYTHONDONTWRITEBYTECODE
VENV := .venv
BIN := $(VENV)/bin
REPORT ?= report

.PHONY: demo test lint typecheck pytest bench figures docs lock clean

$(BIN)/python:
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else "aura-ums needs Python >= 3.11, got " + sys.version.split()[0])'
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# Every install comes from uv.lock (exact versions and hashes of all packages); pyproject.toml
# holds the compatible ranges. After changing a dependency there, run `make lock`.
UV_VERSION := 0.13.9
UV := $(BIN)/uv
UV_STAMP := $(VENV)/.stamp-uv-$(UV_VERSION)
# --locked: stop if uv.lock no longer matches pyproject.toml. --inexact: keep what another
# stamp installed (the dev tools under `make docs`). The package itself is rebuilt each time,
# since its C kernels may have changed.
SYNC := UV_PROJECT_ENVIRONMENT=$(VENV) $(UV) sync --locked --inexact --reinstall-package aura-ums --quiet

# Named by its version: a new UV_VERSION installs that uv.
$(UV_STAMP): | $(BIN)/python
	$(BIN)/python -m pip install --quiet uv==$(UV_VERSION)
	@touch $@

# The install also compiles the C kernels: rebuild when their source changes.
BUILD_INPUTS := pyproject.toml uv.lock setup.py $(wildcard src/aura_ums/_native/*.c src/aura_ums/_native/*.h)

$(VENV)/.stamp-install: $(BUILD_INPUTS) | $(UV_STAMP)
	$(SYNC)
	@touch $@

$(VENV)/.stamp-dev: $(BUILD_INPUTS) | $(UV_STAMP)
	$(SYNC) --extra dev --extra opencv --extra foxglove --extra ros --extra codac --extra dask
	@touch $@ $(VENV)/.stamp-install

$(VENV)/.stamp-docs: $(BUILD_INPUTS) | $(UV_STAMP)
	$(SYNC) --extra docs
	@touch $@ $(VENV)/.stamp-install

# Re-resolve uv.lock after a change of pyproject.toml's dependencies (upgrades nothing else;
# `make lock LOCK_ARGS=--upgrade` takes the newest versions the ranges allow).
lock: | $(UV_STAMP)
	$(UV) lock $(LOCK_ARGS)

demo: $(VENV)/.stamp-install
	$(BIN)/aura-ums demo --out $(REPORT) --overwrite

figures: $(VENV)/.stamp-install
	$(BIN)/aura-ums figures --out $(REPORT)/figures --overwrite

lint: $(VENV)/.stamp-dev
	$(BIN)/ruff check src tests benchmarks setup.py
	$(BIN)/ruff format --check src tests benchmarks setup.py
	$(BIN)/lint-imports

typecheck: $(VENV)/.stamp-dev
	$(BIN)/mypy

# Every core runs tests (pytest-xdist; CI has two). PYTEST_WORKERS=0 runs them in one process.
PYTEST_WORKERS ?= auto
PYTEST := MPLBACKEND=Agg $(BIN)/python -m pytest -q -n $(PYTEST_WORKERS) --dist worksteal

# The second pass runs the library on the numpy reference (AURA_UMS_NATIVE=0: an install
# without a C compiler): the switch, the doctests of the kernel-facing packages and the
# soundness checks of growth, the map, the manager and the Expecter. The first pass already
# holds every kernel to its reference (tests/_native, hypothesis) and replays a real log on
# both paths (tests/_native/test_native_replay.py).
REFERENCE_PASS := tests/_native/test_native_switch.py tests/geometry tests/uncertainty/test_map.py \
	tests/uncertainty/test_growth.py tests/expecter/test_expecter_soundness.py tests/manager/test_map_manager.py \
	src/aura_ums/_native src/aura_ums/geometry src/aura_ums/uncertainty src/aura_ums/expecter src/aura_ums/manager

pytest: $(VENV)/.stamp-dev
	$(PYTEST)
	AURA_UMS_NATIVE=0 $(PYTEST) $(REFERENCE_PASS)

# The three checks run side by side (mypy keeps one core busy, pytest every core); each one's
# output is printed whole when it ends. Any failure fails `make test`.
test: $(VENV)/.stamp-dev
	@$(MAKE) --no-print-directory -j3 --output-sync=target lint typecheck pytest

# Speed against named baselines, measured in the same run (prints tables; asserts nothing).
bench: $(VENV)/.stamp-dev
	$(BIN)/python benchmarks/bench_growth.py
	$(BIN)/python benchmarks/bench_reduce.py
	$(BIN)/python benchmarks/bench_expecter.py
	$(BIN)/python benchmarks/bench_perception.py
	$(BIN)/python benchmarks/bench_sim.py
	$(BIN)/python benchmarks/bench_loop.py

# The documentation site (docs/): every warning, unresolved references included, is an error.
docs: $(VENV)/.stamp-docs
	MPLBACKEND=Agg $(BIN)/sphinx-build -E -W --keep-going -n -q -b html docs docs/_build/html
	@echo "docs: open docs/_build/html/index.html"

clean:
	rm -rf $(VENV) $(REPORT) build dist src/*.egg-info
