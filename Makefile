# asymslide developer commands (GNU make).  `make help` lists them.
SHELL := bash
.SHELLFLAGS := -eu -o pipefail -c
.DEFAULT_GOAL := help

PYTHON   ?= python3
VENV     := .venv
PY       := $(VENV)/bin/python
STAMP    := $(VENV)/.installed-stamp
# every dependency pinned (all extras; CPython 3.11 on Linux): the .venv and the Docker image install from it
LOCK     := requirements.lock
# what make venv installs: the model, the atlas engine, the web app, and the test, bench and lock tools
EXTRAS   := atlas,app,test,bench,dev,docs
CHROMIUM := /usr/bin/chromium
PORT     ?= 5006
# the interface the server listens on: this machine only unless asked (make serve ADDRESS=0.0.0.0: every interface)
ADDRESS  ?= 127.0.0.1
# hosts whose pages may open the app's websocket (never '*')
ALLOWED_ORIGIN ?= localhost:$(PORT)
# server processes (at most one per core; see docs/getting-started.md, "Docker")
NUM_PROCS ?= 1
# where the Atlas tab reads atlases (default: ~/.cache/asymslide/atlases)
ATLAS_DIR ?=
LINT_DIRS ?= $(wildcard model atlas app asymslide tests benchmarks .ci docs/conf.py docs/_ext)
SHELL_SCRIPTS := .ci/run .ci/docker-smoke docker/entrypoint.sh
PYTEST_ARGS ?=

# numba compiles once and keeps its machine code here (ignored by git)
export NUMBA_CACHE_DIR := $(CURDIR)/.numba_cache

.PHONY: help venv lock serve test test-fast docs screenshots bench lint docker-smoke check clean

help:  ## list the targets
	@grep -E '^[a-z-]+:.*## ' $(MAKEFILE_LIST) | sed -E 's/:.*## /\t/' | expand -t 10

venv: $(STAMP)  ## create .venv and install the project with every extra at the versions of requirements.lock

# re-install only when pyproject.toml or the lock changes; -c: each package at its locked version
$(STAMP): pyproject.toml $(LOCK)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -c $(LOCK) -e '.[$(EXTRAS)]'
	$(PY) -m pip check
	touch $@

# UPGRADE=1: every package at its newest version allowed by pyproject.toml (else the current pins are kept)
UPGRADE ?=
lock:  ## re-pin requirements.lock after a change of pyproject.toml (make lock UPGRADE=1: newest versions)
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet $(if $(wildcard $(LOCK)),-c $(LOCK)) uv
	$(VENV)/bin/uv pip compile pyproject.toml --all-extras --python-version 3.11 --python-platform linux \
	  --custom-compile-command 'make lock' --quiet $(if $(UPGRADE),--upgrade) -o $(LOCK)

serve: venv  ## serve the app on http://localhost:5006 (Ctrl-C stops it, workers included)
	$(VENV)/bin/asymslide serve --port $(PORT) --address $(ADDRESS) \
	  --allow-websocket-origin $(ALLOWED_ORIGIN) --allow-websocket-origin 127.0.0.1:$(PORT) \
	  --num-procs $(NUM_PROCS) $(if $(ATLAS_DIR),--atlas-dir $(ATLAS_DIR))

test: venv  ## ruff, then every test (browser tests need /usr/bin/chromium)
	$(VENV)/bin/ruff check $(LINT_DIRS)
	@if [ ! -x $(CHROMIUM) ]; then \
	  echo "SKIPPING browser tests: $(CHROMIUM) not found (apt-get install -y chromium)"; fi
	$(PY) -m pytest $(PYTEST_ARGS)

# the fast lane: the model and the atlas layer, without the tests marked slow (tests/<layer>/: one folder per layer)
test-fast: venv  ## ruff, then the model's and the atlas engine's tests not marked slow (a minute with numba's cache warm)
	$(VENV)/bin/ruff check $(LINT_DIRS)
	$(PY) -m pytest tests/model tests/engine -m "not slow" $(PYTEST_ARGS)

docs: venv  ## build the documentation site into build/docs/html (warnings are errors; notebooks executed)
	$(VENV)/bin/sphinx-build -W --keep-going -b html docs build/docs/html

screenshots: venv  ## refresh the screenshots of the README and the docs site in docs/ (make test writes them to build/screenshots/)
	ASYMSLIDE_UPDATE_SCREENSHOTS=1 $(PY) -m pytest -m ui tests/browser/test_ui_smoke.py tests/app/test_app_atlas.py \
	  tests/app/test_app_lab.py tests/app/test_app_rupture.py tests/browser/test_journeys.py::test_phone_layout_reflows_at_390_px \
	  tests/browser/test_journeys.py::test_the_spectrum_names_both_verdicts_where_only_another_branch_is_unstable \
	  tests/app/test_app_sliding_map.py::test_the_map_says_where_only_another_branch_is_unstable \
	  tests/app/test_app_atlas_sliding.py::test_the_atlas_cell_says_where_only_another_branch_is_unstable

# every process a benchmark starts carries this id in its environment; the last step fails if one is left
bench: export ASYMSLIDE_RUN_ID := bench-$(shell date +%s%N)
bench: venv  ## run the benchmarks (timings live here, not in tests)
	@if [ -f benchmarks/run.py ]; then $(PY) benchmarks/run.py; \
	elif [ -f benchmarks/__main__.py ]; then $(PY) -m benchmarks; \
	else echo "no benchmarks yet: add benchmarks/run.py or benchmarks/__main__.py"; fi
	$(PY) benchmarks/latency.py  # browser slider-to-plot latency (needs $(CHROMIUM)); prints PASS/MISS, exits 0
	$(PY) benchmarks/map_refine.py  # the Stability map refined at its neutral curve against the 40 x 40 / 64 x 64 maps
	$(PY) benchmarks/drag.py  # a slider dragged with the mouse: redraws during the drag, lag after release, 10 sessions
	$(PY) benchmarks/atlas_latency.py  # Atlas tab slice-to-paint latency (needs $(CHROMIUM)); into results.md
	$(PY) benchmarks/first_page.py  # first page after start (numba cache and cold), All branches first open
	$(PY) benchmarks/load_test.py  # 20 sessions for 60 s; exits 1 on errors, p95 > 1 s or unbounded memory
	$(PY) -m tests.support.processes $$ASYMSLIDE_RUN_ID  # exits 1 if a benchmark left a process running

lint: venv  ## ruff on the Python code, hadolint on the Dockerfile, shellcheck on the shell scripts
	$(VENV)/bin/ruff check $(LINT_DIRS)
	$(VENV)/bin/hadolint --failure-threshold warning Dockerfile
	$(VENV)/bin/shellcheck $(SHELL_SCRIPTS)

docker-smoke: venv  ## build, run and stop the Docker image as CI does (as root; its own Docker daemon; ~8 min)
	bash .ci/docker-smoke

check: venv  ## check the public model API against ../shared/check_contract.py
	$(PY) ../shared/check_contract.py

clean:  ## remove caches and test output (keeps .venv)
	rm -rf .numba_cache .pytest_cache .hypothesis .ruff_cache test-results build
	find . -name __pycache__ -not -path './.venv/*' -prune -exec rm -rf {} +
