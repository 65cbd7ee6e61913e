# Two commands on a fresh machine with Python 3.11 and pip:
#   make demo   set up .venv and run the main job on the built-in synthetic walk
#               (the core needs numpy, scipy, scikit-learn, ripser; ".[test]" also pulls the
#               cli and plot extras, typer/rich and matplotlib, which the demo and the tests use)
#   make check  the fast tier, before each commit (a few minutes): ruff, mypy on the whole package, and the unit
#               tests without Blender, a browser, Node.js or the slow ones (pytest -m "not browser and not slow and not node")
#   make test   lint with ruff, run the whole suite with numpy 2.x (.venv) and again
#               with numpy 1.26 (.venv-numpy1, the line Blender 4.2-5.0 bundle), then the Blender
#               extension in headless Blender 5.2 LTS (Python 3.13) and 4.2 LTS (Python 3.11) (make test-blender)
PYTHON ?= $(shell command -v python3.11 || command -v python3)
# Python 3.13 for headless Blender 5.1+ (the bpy wheels are cp313): the first python3.13 that runs, on the PATH or
# in pyenv's versions (pyenv's shim on the PATH fails when 3.13 is not a selected version)
PYTHON313 ?= $(shell for p in python3.13 "$${PYENV_ROOT:-$$HOME/.pyenv}"/versions/3.13*/bin/python3.13; do \
	"$$p" -c 'import sys; assert sys.version_info[:2] == (3, 13)' 2>/dev/null && { command -v "$$p"; break; }; done)
VERSION := $(shell sed -n 's/^version = "\(.*\)"/\1/p' pyproject.toml | head -n 1)
VENV   := .venv
BIN    := $(VENV)/bin
NP1    := .venv-numpy1

.PHONY: demo check test test-numpy2 test-numpy1 lint bench clean blender-extension test-blender-zips test-blender \
	test-blender52 test-blender51 test-blender50 test-blender42 test-blender45 js chromium

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
# Headless Blender from PyPI (the bpy module), one venv per Blender: 5.2 LTS (Python 3.13, numpy 2, slotted actions,
# no action.fcurves) and 4.2 LTS (Python 3.11, numpy 1.26, legacy action.fcurves) run in make test; 5.1, 5.0 and
# 4.5 LTS on demand. bpy links to X11/GL client libraries: installed with apt-get when `import bpy` fails (a fresh root
# CI machine).
BPY52 := .venv-bpy52
BPY42 := .venv-bpy42
BPY_VERSION_52 := 5.2.3
BPY_VERSION_51 := 5.1.2
BPY_VERSION_50 := 5.0.1
BPY_VERSION_45 := 4.5.15
BPY_VERSION_42 := 4.2.23
BPY_PYTHON_52 := $(PYTHON313)
BPY_PYTHON_51 := $(PYTHON313)
BPY_PYTHON_50 := $(PYTHON)
BPY_PYTHON_45 := $(PYTHON)
BPY_PYTHON_42 := $(PYTHON)
BPY_NUMPY_52 := "numpy>=2.2,<3"
BPY_NUMPY_51 := "numpy>=2.2,<3"
BPY_NUMPY_50 := "numpy>=1.26,<2"
BPY_NUMPY_45 := "numpy>=1.26,<2"
BPY_NUMPY_42 := "numpy>=1.26,<2"
BPY_LIBS := libx11-6 libxrender1 libxfixes3 libxi6 libxkbcommon0 libxext6 libxxf86vm1 libsm6 libgl1

.venv-bpy%/.installed:
	@test -n "$(BPY_PYTHON_$*)" || { echo "error: bpy $(BPY_VERSION_$*) needs Python 3.13 (cp313 wheels for Blender \
	5.1+): no working python3.13 on the PATH or in pyenv (pyenv install 3.13, or make PYTHON313=/path/to/python3.13)"; \
	exit 1; }
	$(BPY_PYTHON_$*) -m venv .venv-bpy$*
	.venv-bpy$*/bin/python -m pip install --quiet --upgrade pip
	.venv-bpy$*/bin/python -m pip install --quiet "bpy==$(BPY_VERSION_$*)" $(BPY_NUMPY_$*) pytest setuptools wheel \
		pygltflib "ufbx>=0.0.5,<0.1"
	.venv-bpy$*/bin/python -c "import bpy" 2>/dev/null || \
		(apt-get update -qq && apt-get install -y -qq --no-install-recommends $(BPY_LIBS))
	.venv-bpy$*/bin/python -c "import bpy, numpy, sys; print('bpy', bpy.app.version_string, 'Python', \
		sys.version.split()[0], 'numpy', numpy.__version__)"
	touch $@

# dist/mocycle-<version>-<platform>.zip for linux-x64, windows-x64 and macos-arm64, each with the cp311 and cp313
# wheels side by side, with Blender 5.2's own `extension build --split-platforms` (blender/build_extension.py)
blender-extension: $(BPY52)/.installed
	$(BPY52)/bin/python blender/build_extension.py

# every platform's zip holds a wheel per Python it claims (3.11, 3.13) for each package, listed in its manifest
# (a pure-Python test of the main suite, where it skips while dist/ is empty; run here on the zips just built)
test-blender-zips: blender-extension
	MOCYCLE_BLENDER_DIST=$(CURDIR)/dist $(BPY52)/bin/python -m pytest -q -p no:cacheprovider tests/test_blender_zips.py

# the Blender tests install the linux zip built above (MOCYCLE_BLENDER_ZIP) into each Blender; pygltflib (the glTF-out
# test writes .glb files) and ufbx (the FBX-in tests read what Blender exports; a wheel, no compiler) are added to a bpy
# venv made before they were part of the recipe above
ZIP_LINUX := $(CURDIR)/dist/mocycle-$(VERSION)-linux_x64.zip
BLENDER_TESTS = .venv-bpy$(1)/bin/python -c "import pygltflib, ufbx; ufbx.bake_anim" 2>/dev/null || \
	.venv-bpy$(1)/bin/python -m pip install --quiet pygltflib "ufbx>=0.0.5,<0.1"; \
	cd tests_blender && MOCYCLE_BLENDER_ZIP=$(ZIP_LINUX) nice -n 5 ../.venv-bpy$(1)/bin/python -m pytest -q

test-blender52: .venv-bpy52/.installed blender-extension
	$(call BLENDER_TESTS,52)

test-blender51: .venv-bpy51/.installed blender-extension
	$(call BLENDER_TESTS,51)

test-blender50: .venv-bpy50/.installed blender-extension
	$(call BLENDER_TESTS,50)

test-blender45: .venv-bpy45/.installed blender-extension
	$(call BLENDER_TESTS,45)

test-blender42: .venv-bpy42/.installed blender-extension
	$(call BLENDER_TESTS,42)

# 5.2 LTS (Python 3.13) and 4.2 LTS (Python 3.11): the first and the last Blender the extension supports, both
# animation APIs. `make test-blender51`, `test-blender50` and `test-blender45` (not in make test) run the same tests.
test-blender: test-blender-zips test-blender52 test-blender42

clean:
	rm -rf $(VENV) $(NP1) $(BPY52) $(BPY42) .venv-bpy51 .venv-bpy50 .venv-bpy45 out .pytest_cache .ruff_cache build dist $(JS)/node_modules
