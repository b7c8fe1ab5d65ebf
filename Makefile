# Two commands for a fresh machine (Python 3.11 is all it needs):
#   make run    set up .venv and run the whole pipeline on the quick corpus: record, gate, train
#               gbdt / mlp / anomaly_residual (structural graph), evaluate, print the results
#               tables (about 9 minutes on 2 cores)
#   make test   set up .venv and run the test suite (all of it; `make test-fast` skips the
#               tests that train a model, for the loop while developing)
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed-$(shell cat pyproject.toml | cksum | cut -d' ' -f1)

.PHONY: setup run test test-fast bench lint format clean

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

run: setup
	$(BIN)/python -m robohealth_mj.corpus corpus=quick
	$(BIN)/python -m robohealth_mj.dataset summarize outputs/corpus/quick/*/
	$(BIN)/python -m robohealth_mj.train -m +experiment=quick
	$(BIN)/python -m robohealth_mj.report outputs/campaign_quick

# Two pytest workers (pytest-xdist): the suite is one core's work end to end (training,
# subprocesses), so two halve its wall time; the DDS tests share one worker (tests/ros2/conftest.py)
# and the trained fixtures are built once for both (tests/conftest.py:cached).
TEST_WORKERS ?= 2

test: setup
	$(BIN)/python -m pytest -n $(TEST_WORKERS) --dist loadgroup

test-fast: setup
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
	rm -rf $(VENV) outputs .pytest_cache .ruff_cache
