# Two commands for a fresh machine (Python 3.11 is all it needs):
#   make run    set up .venv and run the whole pipeline on the quick corpus: record, gate, train
#               gbdt / mlp / anomaly_residual (structural graph), evaluate, print the results
#               tables (about 9 minutes on 2 cores)
#   make test   set up .venv (and .venv-sros2, the DDS binding with security, for the secured-graph
#               tests) and run the test suite (all of it; `make test-fast` skips the tests that
#               train a model, for the loop while developing)
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)

.PHONY: setup setup-sros2 run test test-fast bench lint format clean

setup: $(STAMP)

$(STAMP): pyproject.toml
	@# LightGBM's wheel links the system's OpenMP runtime (libgomp1); install it where missing.
	@ldconfig -p | grep -q libgomp.so.1 || (apt-get update -qq && apt-get install -y -qq libgomp1) \
		|| echo "warning: libgomp1 is missing and could not be installed; the gbdt variant needs it"
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	# CPU build of torch first (a local file on these machines), so nothing pulls a CUDA build.
	$(BIN)/python -m pip install --quiet torch==2.13.0
	# The project with every extra (`full`: simulation, training, the live monitor) and the test
	# tools; a deployment machine needs only `pip install '.[monitor]'` (no torch).
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	rm -f $(VENV)/.installed-* && touch $@

# A second environment for the monitor on an SROS2-secured graph (docs/ros2_live.md, "A secured
# graph"): PyPI's Cyclone DDS wheels carry no DDS Security, Debian's Cyclone DDS 0.10.2 does, so
# the binding is built from its sdist against Debian's (in seconds). The build reads include/,
# lib/ and bin/ under CYCLONEDDS_HOME and keeps the library's path, so that folder lives in the
# environment. The secured tests (tests/ros2/test_security.py) run their participants in it.
SROS2_VENV  := .venv-sros2
SROS2_HOME  := $(SROS2_VENV)/cyclonedds
SROS2_STAMP := $(SROS2_VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)
MULTIARCH   := $(shell gcc -print-multiarch 2>/dev/null || echo x86_64-linux-gnu)

setup-sros2: $(SROS2_STAMP)

$(SROS2_STAMP): pyproject.toml
	@dpkg -s cyclonedds-dev cyclonedds-tools >/dev/null 2>&1 && command -v gcc >/dev/null \
		|| (apt-get update -qq && apt-get install -y -qq cyclonedds-dev cyclonedds-tools gcc libc6-dev)
	$(PYTHON) -m venv $(SROS2_VENV)
	mkdir -p $(SROS2_HOME)
	ln -sfn /usr/include $(SROS2_HOME)/include
	ln -sfn /usr/lib/$(MULTIARCH) $(SROS2_HOME)/lib
	ln -sfn /usr/bin $(SROS2_HOME)/bin
	$(SROS2_VENV)/bin/python -m pip install --quiet --upgrade pip
	@# no cache: a wheel built elsewhere would point at another CYCLONEDDS_HOME
	CYCLONEDDS_HOME=$(abspath $(SROS2_HOME)) $(SROS2_VENV)/bin/python -m pip install --quiet \
		--no-cache-dir --no-binary cyclonedds cyclonedds==0.10.2
	$(SROS2_VENV)/bin/python -m pip install --quiet -e '.[sros2]'
	rm -f $(SROS2_VENV)/.installed-* && touch $@

run: setup
	$(BIN)/python -m robohealth_mj.corpus corpus=quick
	$(BIN)/python -m robohealth_mj.dataset summarize outputs/corpus/quick/*/
	$(BIN)/python -m robohealth_mj.train -m +experiment=quick
	$(BIN)/python -m robohealth_mj.report outputs/campaign_quick

# Two pytest workers (pytest-xdist): the suite is one core's work end to end (training,
# subprocesses), so two halve its wall time; the DDS tests share one worker (tests/ros2/conftest.py)
# and the trained fixtures are built once for both (tests/conftest.py:cached). The run ends with
# its fifteen slowest tests, so a CI log says where the ten-minute budget goes.
TEST_WORKERS ?= 2

test: setup setup-sros2
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadgroup --durations=15

test-fast: setup setup-sros2
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadgroup -m "not slow"

bench: setup
	$(BIN)/python -m robohealth_mj.bench sim

lint: setup
	$(BIN)/ruff check robohealth_mj tests studies
	$(BIN)/ruff format --check robohealth_mj tests studies

format: setup
	$(BIN)/ruff format robohealth_mj tests studies
	$(BIN)/ruff check --fix robohealth_mj tests studies

clean:
	rm -rf $(VENV) $(SROS2_VENV) outputs .pytest_cache .ruff_cache
