# RadarTune — `make run` starts the app, `make test` runs the whole suite headless.
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed

.PHONY: run test test-xcb lint contracts typecheck format stability bench fuzz clean

$(STAMP): pyproject.toml
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[dev]'
	# compile the app's first kernels now, not at the first start (docs/decisions/app-06)
	$(BIN)/python -m app.warm_up
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

# the app in the real window: Qt's xcb platform under Xvfb, on the two screens the layout was checked on at
# 100 % and 150 % (tests marked xcb; offscreen they are skipped)
XCB_SCREENS ?= 1366x768 1920x1080
test-xcb: $(STAMP)
	for screen in $(XCB_SCREENS); do for scale in 1 1.5; do \
	  QT_SCALE_FACTOR=$$scale QT_QPA_PLATFORM=xcb xvfb-run -a -s "-screen 0 $${screen}x24" \
	    $(BIN)/python -m pytest -q -m xcb tests/app || exit 1; \
	done; done

# the long fuzz profile (tests/fuzz): 10 000 generated and mutated input files through the CLI,
# prints the tally; FUZZ_INPUTS=... to change the count
FUZZ_INPUTS ?= 10000
fuzz: $(STAMP)
	RADARTUNE_FUZZ_INPUTS=$(FUZZ_INPUTS) QT_QPA_PLATFORM=offscreen $(BIN)/python -m pytest tests/fuzz -q

stability: $(STAMP)
	$(BIN)/radartune stability

bench: $(STAMP)
	$(BIN)/radartune bench all

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache .import_linter_cache .grimp_cache .mypy_cache
