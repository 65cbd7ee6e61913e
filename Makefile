# Two commands on a fresh machine with Python 3.11 and pip:
#   make demo   set up .venv and run the main job on the built-in synthetic walk
#               (the core needs numpy, scipy, scikit-learn, ripser; ".[test]" also pulls the
#               cli and plot extras, typer/rich and matplotlib, which the demo and the tests use)
#   make check  the fast tier, before each commit (a few minutes): ruff, mypy on the core, and the unit
#               tests without Blender, a browser, Node.js or the slow ones (pytest -m "not browser and not slow and not node")
#   make test   lint with ruff, run the whole suite with numpy 2.x (.venv) and again
#               with numpy 1.26 (.venv-numpy1, the line Blender bundles), then the Blender
#               extension in headless Blender 5.0.1 and 4.2 LTS (make test-blender)
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
BIN    := $(VENV)/bin
NP1    := .venv-numpy1

.PHONY: demo check test test-numpy2 test-numpy1 lint bench clean blender-extension test-blender test-blender50 test-blender42 test-blender45 js chromium

# the glTF tests' JavaScript side (Khronos glTF validator, three.js): tests/js/package-lock.json
JS := tests/js
$(JS)/node_modules/.installed: $(JS)/package-lock.json
	command -v npm >/dev/null || (apt-get update && apt-get install -y nodejs npm) \
		|| { echo "the glTF tests need Node.js 18+ and npm (apt-get install nodejs npm)"; exit 1; }
	cd $(JS) && npm ci --no-audit --no-fund
	touch $@

js: $(JS)/node_modules/.installed

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
	$(BIN)/ruff check src tests benchmarks blender tests_blender

# the fast tier (see the top): no Node.js, chromium or Blender needed; make test runs everything
check: $(VENV)/.installed
	$(BIN)/ruff check src tests benchmarks blender tests_blender
	$(BIN)/mypy
	$(BIN)/python -m pytest -q -p no:cacheprovider -m "not browser and not slow and not node"

test-numpy2: $(VENV)/.installed $(JS)/node_modules/.installed
	$(BIN)/python -c "import numpy; print('numpy', numpy.__version__)"
	$(BIN)/python -m pytest -q

test-numpy1: $(NP1)/.installed $(JS)/node_modules/.installed
	$(NP1)/bin/python -c "import numpy; print('numpy', numpy.__version__)"
	$(NP1)/bin/python -m pytest -q -p no:cacheprovider

# the studio's browser tests drive Debian's chromium through Playwright (never `playwright install`)
chromium:
	@command -v chromium >/dev/null 2>&1 || { apt-get update -qq && apt-get install -y -qq chromium; }

test: lint chromium test-numpy1 test-numpy2 test-blender

bench: $(VENV)/.installed
	$(BIN)/python -m pip install --quiet -e ".[bench]"
	$(BIN)/python benchmarks/io.py
	$(BIN)/python benchmarks/phase.py
	$(BIN)/python benchmarks/cycles.py
	$(BIN)/python benchmarks/stretch.py
	$(BIN)/python benchmarks/swings.py
	$(BIN)/python benchmarks/keyframes.py
	$(BIN)/python benchmarks/feet.py
	$(BIN)/python benchmarks/batch.py

# --- Blender extension (docs/blender.md) ------------------------------------------------------------------
# Headless Blender from PyPI (the bpy module, Python 3.11), one venv per animation API: 5.0.1 (slotted actions)
# and 4.2 LTS (legacy action.fcurves); both with numpy 1.26, the numpy Blender brings. bpy links to X11/GL
# client libraries: installed with apt-get when `import bpy` fails (a fresh root CI machine).
BPY50 := .venv-bpy50
BPY42 := .venv-bpy42
BPY_VERSION_50 := 5.0.1
BPY_VERSION_45 := 4.5.15
BPY_VERSION_42 := 4.2.23
BPY_LIBS := libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libxext6 libxxf86vm1 libsm6 libgl1

.venv-bpy%/.installed:
	$(PYTHON) -m venv .venv-bpy$*
	.venv-bpy$*/bin/python -m pip install --quiet --upgrade pip
	.venv-bpy$*/bin/python -m pip install --quiet "bpy==$(BPY_VERSION_$*)" "numpy>=1.26,<2" \
		pytest setuptools wheel
	.venv-bpy$*/bin/python -c "import bpy" 2>/dev/null || \
		(apt-get update -qq && apt-get install -y -qq --no-install-recommends $(BPY_LIBS))
	.venv-bpy$*/bin/python -c "import bpy, numpy; print('bpy', bpy.app.version_string, 'numpy', numpy.__version__)"
	touch $@

# dist/mocycle-<version>-<platform>.zip for linux-x64, windows-x64 and macos-arm64, with Blender's own
# `extension build --split-platforms` (blender/build_extension.py says how)
blender-extension: $(BPY50)/.installed
	$(BPY50)/bin/python blender/build_extension.py

test-blender50: $(BPY50)/.installed
	cd tests_blender && ../$(BPY50)/bin/python -m pytest -q

test-blender42: $(BPY42)/.installed
	cd tests_blender && ../$(BPY42)/bin/python -m pytest -q

test-blender: test-blender50 test-blender42

# not part of make test: 4.5 LTS, the first LTS with slotted actions (F-curves without group names)
test-blender45: .venv-bpy45/.installed
	cd tests_blender && ../.venv-bpy45/bin/python -m pytest -q

clean:
	rm -rf $(VENV) $(NP1) $(BPY50) $(BPY42) .venv-bpy45 out .pytest_cache .ruff_cache build dist $(JS)/node_modules
