# Two commands on a fresh machine with Python 3.11 and pip:
#   make demo   set up .venv and run the main job on the built-in synthetic walk
#               (the core needs numpy, scipy, scikit-learn, ripser; ".[test]" also pulls the
#               cli and plot extras, typer/rich and matplotlib, which the demo and the tests use)
#   make test   lint with ruff, run the whole suite with numpy 2.x (.venv) and again
#               with numpy 1.26 (.venv-numpy1, the line Blender bundles)
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
NP1    := .venv-numpy1

.PHONY: demo test test-numpy2 test-numpy1 lint bench clean chromium

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $@

$(NP1)/.installed: pyproject.toml
	$(PYTHON) -m venv $(NP1)
	$(NP1)/bin/python -m pip install --quiet --upgrade pip
	$(NP1)/bin/python -m pip install --quiet "numpy>=1.26,<2" -e ".[test]"
	touch $@

demo: $(VENV)/.installed
	$(BIN)/mocycle demo --out out/demo

lint: $(VENV)/.installed
	$(BIN)/ruff check src tests benchmarks

test-numpy2: $(VENV)/.installed
	$(BIN)/python -c "import numpy; print('numpy', numpy.__version__)"
	$(BIN)/python -m pytest -q

test-numpy1: $(NP1)/.installed
	$(NP1)/bin/python -c "import numpy; print('numpy', numpy.__version__)"
	$(NP1)/bin/python -m pytest -q -p no:cacheprovider

# the studio's browser tests drive Debian's chromium through Playwright (never `playwright install`)
chromium:
	@command -v chromium >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq chromium; }

test: lint chromium test-numpy1 test-numpy2

bench: $(VENV)/.installed
	$(BIN)/python -m pip install --quiet -e ".[bench]"
	$(BIN)/python benchmarks/io.py
	$(BIN)/python benchmarks/phase.py
	$(BIN)/python benchmarks/cycles.py
	$(BIN)/python benchmarks/stretch.py
	$(BIN)/python benchmarks/swings.py
	$(BIN)/python benchmarks/keyframes.py
	$(BIN)/python benchmarks/feet.py

clean:
	rm -rf $(VENV) $(NP1) out .pytest_cache .ruff_cache
