# RadarTune — `make run` starts the app, `make test` runs the whole suite headless.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test lint contracts typecheck format stability bench clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	touch $(STAMP)

run: $(STAMP)
	$(BIN)/radartune gui

lint: $(STAMP)
	$(BIN)/ruff check .
	$(BIN)/ruff format --check .

# layer contracts of pyproject.toml [tool.importlinter]: which package may import which
contracts: $(STAMP)
	$(BIN)/lint-imports

# mypy on core/ as configured in pyproject.toml [tool.mypy] (incremental: .mypy_cache)
typecheck: $(STAMP)
	$(BIN)/mypy

format: $(STAMP)
	$(BIN)/ruff format .
	$(BIN)/ruff check --fix .

test: lint contracts typecheck
	QT_QPA_PLATFORM=offscreen $(BIN)/python -m pytest

stability: $(STAMP)
	$(BIN)/radartune stability

bench: $(STAMP)
	$(BIN)/radartune bench all

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache .import_linter_cache .grimp_cache .mypy_cache
