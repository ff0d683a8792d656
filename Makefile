# eoam-sumo: every target creates the virtual environment when it is missing.
PYTHON ?= python3
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out
# the modules compiled at install (setup.py): a change to one installs (compiles) again
COMPILED_SOURCES := $(shell sed -n 's/^ *"\(eoam_sumo\/[a-z0-9_/]*\.py\)",$$/\1/p' setup.py)

.PHONY: run test test-fast tables bench lint network clean

$(STAMP): pyproject.toml setup.py $(COMPILED_SOURCES)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e '.[test]'
	touch $(STAMP)

## The main job: the paper's Table 2 (64 co-simulations), printed beside the paper's; then
## the same 64 cases under the safe policy with V2X, also beside the paper's.
run: $(STAMP)
	$(BIN)/eoam-sumo batch scenarios/table2.toml --out $(OUT)/table2 --jobs 2
	cat $(OUT)/table2/table2.md
	$(BIN)/eoam-sumo batch scenarios/table2_safe_v2x.toml --out $(OUT)/table2_safe_v2x --jobs 2
	cat $(OUT)/table2_safe_v2x/table2.md

## Every test, the SUMO co-simulations included (what CI runs).
test: $(STAMP)
	$(BIN)/python -m pytest

## The tests that need no SUMO (-m "not sumo"), with SUMO made unreachable so that a test
## needing it without its marker fails here.
test-fast: $(STAMP)
	PYTHONPATH="$(CURDIR)/tests/no_sumo$${PYTHONPATH:+:$$PYTHONPATH}" $(BIN)/python -m pytest -m "not sumo"

tables: $(STAMP)
	$(BIN)/eoam-sumo tables --out tables --jobs 2

bench: $(STAMP)
	$(BIN)/eoam-sumo bench --out $(OUT)/bench

## ruff (rules chosen in pyproject.toml) and mypy over eoam_sumo/.
lint: $(STAMP)
	$(BIN)/ruff check eoam_sumo tests
	$(BIN)/python -m mypy

## Rebuild networks/*.net.xml from the plain XML sources with netconvert.
network: $(STAMP)
	$(BIN)/python -m eoam_sumo.netbuild networks

clean:
	rm -rf $(VENV) $(OUT) build eoam_sumo/compiled_sources.json
	find eoam_sumo -name '*.so' -delete
