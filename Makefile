# Two commands for a fresh machine:
#   make run   - create .venv, install thermodem, run the default example, print where results are
#   make test  - create .venv, install thermodem with test extras, run the whole test suite
PYTHON ?= python3
VENV ?= .venv
BIN := $(VENV)/bin
OUT ?= results/default

.PHONY: run test venv lint bench clean-cache

# pip -qq: errors only (no notices, no deprecation warnings of the build); an error still
# prints and stops make
PIP_QUIET := --quiet --quiet --disable-pip-version-check --no-warn-script-location

$(BIN)/python:
	@echo "creating $(VENV) and installing thermodem (about a minute, once)"
	$(PYTHON) -m venv $(VENV)
	@$(BIN)/python -m pip install $(PIP_QUIET) --upgrade pip

$(VENV)/.installed: pyproject.toml | $(BIN)/python
	@$(BIN)/python -m pip install $(PIP_QUIET) -e ".[test]"
	@touch $@

venv: $(VENV)/.installed

run: venv
	$(BIN)/thermodem run examples/default.yaml --output $(OUT) --overwrite
	@echo "Results written to $(OUT) (open $(OUT)/particles.pvd in ParaView)"

# two pytest workers (pytest-xdist): the suite is mostly compilation and small single-threaded
# runs, so the two cores halve it (15 -> 8 min with an empty Numba cache)
test: venv
	$(BIN)/python -m pytest -q -n 2 --dist worksteal

lint: venv
	$(BIN)/ruff check src tests bench tools
	$(BIN)/ruff format --check src tests bench tools

bench: venv
	$(BIN)/python bench/bench_packed_bed.py --n 50000

clean-cache:
	find src -name '__pycache__' -type d -prune -exec rm -rf {} +
