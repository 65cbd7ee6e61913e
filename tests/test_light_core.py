"""Light core: importing mocycle's core loads no CLI, plotting, batch, web or Blender library.

Checked in a fresh interpreter with an import hook that records, for every forbidden package, the file
whose code imported it.  A required dependency may load one itself (scikit-learn loads ``rich`` for its
optional progress bars when rich is installed); mocycle's own modules, or any other package they pull
in, may not.
"""

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import mocycle

FORBIDDEN = ("typer", "rich", "click", "matplotlib", "dask", "distributed", "starlette", "uvicorn", "bpy",
             "pygltflib", "polars")
REQUIRED = ("numpy", "scipy", "sklearn", "ripser", "threadpoolctl", "joblib")
CORE = ["mocycle", "mocycle.errors", "mocycle.io", "mocycle.io.mck", "mocycle.io.mosw", "mocycle.motion",
        "mocycle.rotations", "mocycle.axes", "mocycle.features", "mocycle.datasets", "mocycle.phase",
        "mocycle.cycle", "mocycle.warp", "mocycle.swings", "mocycle.keyframes", "mocycle.tasks", "mocycle.tasks.author",
        "mocycle.viz", "mocycle.viz.data", "mocycle.io.gltf", "mocycle.clip", "mocycle.tasks.clips"]

_PROBE = r"""
import json, sys, traceback
FORBIDDEN = set(json.loads(sys.argv[1]))
hits = []

class Recorder:
    def find_spec(self, name, path=None, target=None):
        if name in FORBIDDEN:
            frames = [f.filename for f in traceback.extract_stack()[:-1]]
            callers = [f for f in frames if "importlib" not in f and not f.startswith("<")]
            hits.append([name, callers[-1] if callers else "?"])
        return None

sys.meta_path.insert(0, Recorder())
for module in json.loads(sys.argv[2]):
    __import__(module)
print(json.dumps(hits))
"""


def _site_package(filename: str) -> str | None:
    parts = Path(filename).parts
    for marker in ("site-packages", "dist-packages"):
        if marker in parts:
            i = parts.index(marker)
            return parts[i + 1] if i + 1 < len(parts) else None
    return None


def _imports(modules):
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    out = subprocess.run([sys.executable, "-c", _PROBE, json.dumps(FORBIDDEN), json.dumps(modules)],
                         capture_output=True, text=True, env=env, check=True)
    return json.loads(out.stdout)


def test_core_imports_no_front_end_library():
    modules = [m for m in CORE if importlib.util.find_spec(m) is not None]
    assert "mocycle.axes" in modules and "mocycle.viz.data" in modules
    bad = []
    for name, importer in _imports(modules):
        owner = _site_package(importer)
        if owner is not None and owner.split(".")[0] in REQUIRED:
            continue  # a required dependency's own choice
        bad.append(f"{name} imported by {importer}")
    assert not bad, "the core loads front-end libraries: " + "; ".join(bad)


def test_probe_sees_an_import_from_mocycle():
    """The hook works: the CLI's commands do import typer, from mocycle's own code (``mocycle.cli`` itself is
    light so that its signal handlers are in place before the commands load)."""
    pytest.importorskip("typer")
    hits = _imports(["mocycle.cli.common"])
    package_dir = Path(mocycle.__file__).parent
    assert any(name == "typer" and Path(importer).is_relative_to(package_dir) for name, importer in hits)


def test_console_script_without_typer_says_how_to_install():
    code = "import sys; sys.modules['typer'] = None; from mocycle.__main__ import main; main()"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env)
    assert r.returncode == 1
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "typer" in lines[0] and "pip install 'mocycle[cli]'" in lines[0]


def test_plots_leave_the_matplotlib_backend_alone(tmp_path):
    pytest.importorskip("matplotlib")
    code = f"""
import sys, matplotlib
matplotlib.use("svg")
from mocycle.datasets import synthetic_walk
from mocycle.swings import segment
from mocycle.viz import plot_swings
plot_swings(segment(synthetic_walk(n_frames=120).motion), {str(tmp_path / "s.png")!r})
assert matplotlib.get_backend() == "svg", matplotlib.get_backend()
assert "matplotlib.pyplot" not in sys.modules
"""
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    subprocess.run([sys.executable, "-c", code], check=True, env=env)
    assert (tmp_path / "s.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
