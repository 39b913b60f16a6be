# asymslide developer commands (GNU make).  `make help` lists them.
SHELL := bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := help

PYTHON   ?= python3
VENV     := .venv
PY       := $(VENV)/bin/python
STAMP    := $(VENV)/.installed-stamp
CHROMIUM := /usr/bin/chromium
PORT     ?= 5006
ADDRESS  ?= 0.0.0.0
# hosts whose pages may open the app's websocket (never '*')
ALLOWED_ORIGIN ?= localhost:$(PORT)
# server processes (at most one per core; see README "Docker")
NUM_PROCS ?= 1
# where the Atlas tab reads atlases (default: ~/.cache/asymslide/atlases)
ATLAS_DIR ?=
LINT_DIRS ?= $(wildcard model app tests benchmarks)
PYTEST_ARGS ?=

# numba compiles once and keeps its machine code here (ignored by git)
export NUMBA_CACHE_DIR := $(CURDIR)/.numba_cache

.PHONY: help venv serve test screenshots bench lint check clean

help:  ## list the targets
	@grep -E '^[a-z]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/:.*## /\t/' | expand -t 10

venv: $(STAMP)  ## create .venv and install the project with its test and bench extras

# re-install only when pyproject.toml changes
$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test,bench]'
	touch $@

serve: venv  ## serve the app on http://localhost:5006 (Ctrl-C stops it, workers included)
	$(VENV)/bin/asymslide serve --port $(PORT) --address $(ADDRESS) \
	  --allow-websocket-origin $(ALLOWED_ORIGIN) --allow-websocket-origin 127.0.0.1:$(PORT) \
	  --num-procs $(NUM_PROCS) $(if $(ATLAS_DIR),--atlas-dir $(ATLAS_DIR))

test: venv  ## ruff, then every test (browser tests need /usr/bin/chromium)
	$(VENV)/bin/ruff check $(LINT_DIRS)
	@if [ ! -x $(CHROMIUM) ]; then \
	  echo "SKIPPING browser tests: $(CHROMIUM) not found (apt-get install -y chromium)"; fi
	$(PY) -m pytest $(PYTEST_ARGS)

screenshots: venv  ## refresh the README's screenshots in docs/ (make test writes them to build/screenshots/)
	ASYMSLIDE_UPDATE_SCREENSHOTS=1 $(PY) -m pytest -m ui tests/test_ui_smoke.py tests/test_app_atlas.py \
	  tests/test_app_lab.py tests/test_app_rupture.py tests/test_journeys.py::test_phone_layout_reflows_at_390_px

# every process a benchmark starts carries this id in its environment; the last step fails if one is left
bench: export ASYMSLIDE_RUN_ID := bench-$(shell date +%s%N)
bench: venv  ## run the benchmarks (timings live here, not in tests)
	@if [ -f benchmarks/run.py ]; then $(PY) benchmarks/run.py; \
	elif [ -f benchmarks/__main__.py ]; then $(PY) -m benchmarks; \
	else echo "no benchmarks yet: add benchmarks/run.py or benchmarks/__main__.py"; fi
	$(PY) benchmarks/latency.py  # browser slider-to-plot latency (needs $(CHROMIUM)); prints PASS/MISS, exits 0
	$(PY) benchmarks/atlas_latency.py  # Atlas tab slice-to-paint latency (needs $(CHROMIUM)); into results.md
	$(PY) benchmarks/first_page.py  # first page after start (numba cache and cold), All branches first open
	$(PY) benchmarks/load_test.py  # 20 sessions for 60 s; exits 1 on errors, p95 > 1 s or unbounded memory
	$(PY) -m asymslide.processes $$ASYMSLIDE_RUN_ID  # exits 1 if a benchmark left a process running

lint: venv  ## ruff on the Python code, hadolint on the Dockerfile
	$(VENV)/bin/ruff check $(LINT_DIRS)
	$(VENV)/bin/hadolint --failure-threshold warning Dockerfile

check: venv  ## check the public model API against ../shared/check_contract.py
	$(PY) ../shared/check_contract.py

clean:  ## remove caches and test output (keeps .venv)
	rm -rf .numba_cache .pytest_cache .hypothesis .ruff_cache test-results build
	find . -name __pycache__ -not -path './.venv/*' -prune -exec rm -rf {} +
