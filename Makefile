# eoam-sumo: every target creates the virtual environment when it is missing.
#
# The interpreter it is made from, unless PYTHON is given (README "Installs"): of
# PYTHON_CANDIDATES, those that are CPython 3.11 or newer with venv's pip (ensurepip) and the
# C headers (mypyc and the plant's extension compile against them); one whose core is linked
# into its executable before one that loads a shared libpython (the step loop spends half its
# time in the interpreter's core: on pyenv's shared build without profile-guided optimisation
# it took 16 % more time, the studies 3-14 % more; docs/performance.md); else python3. A
# virtual environment already made is kept: `make clean` first to change it.
PYTHON_CANDIDATES ?= python3 /usr/bin/python3
PYTHON_PROBE := import os, sys, sysconfig, importlib.util as u; \
	ok = sys.implementation.name == "cpython" and sys.version_info >= (3, 11) \
	and u.find_spec("ensurepip") is not None \
	and os.path.exists(os.path.join(sysconfig.get_paths()["include"], "Python.h")); \
	maps = "/proc/self/maps"; \
	shared = not os.path.exists(maps) or "libpython" in open(maps).read(); \
	ok and print(int(shared), sys.executable)
PYTHON ?= $(or $(shell for p in $(PYTHON_CANDIDATES); do $$p -c '$(PYTHON_PROBE)' 2>/dev/null; \
	done | sort -s -n -k1,1 | head -n 1 | cut -d' ' -f2-),python3)
VENV   := .venv
BIN    := $(VENV)/bin
STAMP  := $(VENV)/.installed
OUT    ?= out
# every direct and transitive dependency, build requirements and pip included, pinned
# (`make lock` refreshes it; README "Installs")
LOCK   := constraints.txt
PIP    := $(BIN)/python -m pip install --quiet --constraint $(LOCK) --build-constraint $(LOCK)
# the compiled build: a copy of the working tree with the step loop compiled in place by mypyc
# (setup.py, EOAM_SUMO_COMPILE=1); `make run` and `make bench` run it, `make test` the sources
COMPILED_TREE := build/compiled
COMPILED_STAMP := $(COMPILED_TREE)/.built
TREE_FILES = git ls-files --cached --others --exclude-standard -- \
	eoam_sumo tables vehicles scenarios networks tests/golden setup.py pyproject.toml README.md \
	| while read -r f; do [ -e "$$f" ] && echo "$$f"; done
RUN_COMPILED := PYTHONPATH=$(CURDIR)/$(COMPILED_TREE)

.PHONY: run study test test-fast test-compiled golden-strict golden-update tables bench lint network \
	lock compiled clean readme-pictures

$(STAMP): pyproject.toml setup.py $(LOCK)
	test -x $(BIN)/python || $(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --constraint $(LOCK) --upgrade pip setuptools wheel
	$(PIP) -e '.[test]'
	touch $(STAMP)

## The main job: the paper's Table 2 (64 co-simulations), printed beside the paper's; then
## the same 64 cases under the safe policy with V2X, also beside the paper's.
run: $(COMPILED_STAMP)
	$(RUN_COMPILED) $(BIN)/eoam-sumo batch scenarios/table2.toml --out $(OUT)/table2 --jobs 2
	cat $(OUT)/table2/table2.md
	$(RUN_COMPILED) $(BIN)/eoam-sumo batch scenarios/table2_safe_v2x.toml \
		--out $(OUT)/table2_safe_v2x --jobs 2
	cat $(OUT)/table2_safe_v2x/table2.md

## Any command on the compiled build (its workers too), e.g. a study:
##   make study ARGS="batch scenarios/vehicles.toml --out out/vehicles"
study: $(COMPILED_STAMP)
	$(RUN_COMPILED) $(BIN)/eoam-sumo $(ARGS)

## Every test on the Python sources, the SUMO co-simulations and the golden Table 2 within its
## tolerances included (what CI runs, with test-compiled). It changes nothing outside the
## project: the sumo-gui tests (tests/sim/test_gui.py) run on DISPLAY or on Xvfb when either
## is there, and otherwise skip, saying why (.ci/run installs Xvfb on CI's machine).
test: $(STAMP)
	$(BIN)/python -m pytest

## The tests that need no SUMO (-m "not sumo"), with SUMO made unreachable so that a test
## needing it without its marker fails here.
test-fast: $(STAMP)
	PYTHONPATH="$(CURDIR)/tests/no_sumo$${PYTHONPATH:+:$$PYTHONPATH}" $(BIN)/python -m pytest -m "not sumo"

## The golden Table 2 (within its tolerances) on the compiled build.
test-compiled: $(COMPILED_STAMP)
	cd $(COMPILED_TREE) && ../../$(BIN)/python -m tests.golden.table2_golden --expect-compiled

## Same machine, strict: every time series byte-identical to the digests recorded on this
## machine (`make golden-update` records them; docs/reproducibility.md).
golden-strict: $(STAMP)
	$(BIN)/python -m tests.golden.table2_golden --strict

## Rewrite the golden files from a run of Table 2 (a change meant to alter results; explain
## each changed cell in the commit).
golden-update: $(STAMP)
	$(BIN)/python -m tests.golden.table2_golden --update

tables: $(STAMP)
	$(BIN)/eoam-sumo tables --out tables --jobs 2

bench: $(COMPILED_STAMP)
	$(RUN_COMPILED) $(BIN)/eoam-sumo bench --out $(OUT)/bench

## The README's pictures (docs/img/), from fresh runs: Table 2 of the paper's batch, one frame
## of an evasion in it (oncoming car at 500 m, 55 km/h, mu 1.0: past the obstacle in the
## opposite lane) and the UN R152 scorecard. Commit them when they change.
README_OUT := $(OUT)/readme
readme-pictures: $(STAMP)
	$(BIN)/eoam-sumo batch scenarios/table2.toml --out $(README_OUT)/table2 --jobs 2 --no-progress
	$(BIN)/eoam-sumo animate $(README_OUT)/table2/cases/onc-500_v55_mu1.0 --out docs/img/evasion.png
	$(BIN)/eoam-sumo protocol unr152 --out $(README_OUT)/r152 --jobs 2
	cp $(README_OUT)/table2/table2.png docs/img/table2.png
	cp $(README_OUT)/r152/scorecard.png docs/img/scorecard.png

## ruff (rules chosen in pyproject.toml; formatting checked) and mypy over eoam_sumo/.
lint: $(STAMP)
	$(BIN)/ruff check eoam_sumo tests setup.py
	$(BIN)/ruff format --check eoam_sumo tests setup.py
	$(BIN)/python -m mypy

## Rebuild networks/*.net.xml from the plain XML sources with netconvert.
network: $(STAMP)
	$(BIN)/python -m eoam_sumo.netbuild networks

## Refresh constraints.txt: the newest versions pyproject.toml allows, resolved in a fresh
## environment, every package pinned (commit it after `make test` passes with it).
lock:
	rm -rf build/lock-venv
	$(PYTHON) -m venv build/lock-venv
	build/lock-venv/bin/python -m pip install --quiet --upgrade pip setuptools wheel
	build/lock-venv/bin/python -m pip install --quiet '.[test]'
	{ echo "# eoam-sumo's pinned install: every package make installs (make lock refreshes it)"; \
	  build/lock-venv/bin/python -m pip freeze --all --exclude eoam-sumo; } > $(LOCK)
	rm -rf build/lock-venv

## The compiled build: the working tree copied to build/compiled and compiled in place.
compiled: $(COMPILED_STAMP)

$(COMPILED_STAMP): $(STAMP) $(shell $(TREE_FILES))
	rm -rf $(COMPILED_TREE)
	mkdir -p $(COMPILED_TREE)
	$(TREE_FILES) | tar -cf - -T - | tar -xf - -C $(COMPILED_TREE)
	cd $(COMPILED_TREE) && EOAM_SUMO_COMPILE=1 ../../$(BIN)/python setup.py --quiet \
		build_ext --inplace
	touch $(COMPILED_STAMP)

clean:
	rm -rf $(VENV) $(OUT) build
	find eoam_sumo -name '*.so' -delete
