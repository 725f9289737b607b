# cosim: every target sets up .venv first (idempotent), so a fresh clone needs only `make demo` / `make test`.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
SCENARIO ?= warehouse-random
OUT    ?= runs/demo

.PHONY: setup demo test lint bench clean help

help:  ## list the targets
	@grep -E '^[a-z-]+:.*##' $(MAKEFILE_LIST) | sed 's/:.*## /\t/'

$(STAMP): pyproject.toml
	@$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "cosim needs Python >= 3.11, found " + sys.version.split()[0]'
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

setup: $(STAMP)  ## create .venv and install cosim with its dev tools

demo: setup  ## run the default scenario and say where the results are
	$(BIN)/cosim run $(SCENARIO) --out $(OUT) --force

test: setup  ## the whole test suite
	$(BIN)/python -m pytest -q

lint: setup  ## ruff and mypy --strict
	$(BIN)/ruff check cosim models adapters studies tests bench
	$(BIN)/mypy cosim models adapters

bench: setup  ## benchmarks -> bench/results.json
	$(BIN)/python bench/run.py --out bench/results.json

clean:  ## remove the virtual environment, caches and run outputs
	rm -rf $(VENV) runs .pytest_cache .mypy_cache .ruff_cache build *.egg-info
	find . -name __pycache__ -type d -prune -exec rm -rf {} +
