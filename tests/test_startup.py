"""Start-up: what the command line imports for ``--help`` and for ``loop``, checked as sets of modules.

The times themselves are measured by ``benchmarks/speed.py`` (``docs/performance.md``); these tests keep the
heavy libraries off the paths that do not use them, which is what the times follow from.
"""

import json
import os
import subprocess
import sys

import pytest

from mocycle.datasets import synthetic_walk
from mocycle.io import write

#: what each path must not import: (module prefix, why)
NOT_FOR_HELP = ("numpy", "scipy", "sklearn", "ripser", "pyRipser", "rich", "pydantic", "matplotlib")
NOT_FOR_LOOP = ("sklearn", "ripser", "scipy.stats", "scipy.signal", "scipy.interpolate", "scipy.optimize",
                "scipy.ndimage", "scipy.integrate", "matplotlib", "joblib", "mocycle.keyframes", "mocycle.swings",
                "mocycle.warp")

_RUN = r"""
import json, sys
sys.argv = ["mocycle"] + json.loads(sys.argv[1])
from mocycle.__main__ import main
try:
    main()
except SystemExit as exc:
    code = exc.code
else:
    code = 0
sys.stdout.flush()
print("\n@@" + json.dumps({"code": code, "modules": sorted(sys.modules)}))
"""


def run_cli(args, **env):
    """Run the console script's ``main`` in a fresh interpreter; its exit code and every module it loaded."""
    environ = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p), **env}
    out = subprocess.run([sys.executable, "-c", _RUN, json.dumps([str(a) for a in args])], capture_output=True,
                         text=True, env=environ, check=True).stdout
    return json.loads(out.rsplit("@@", 1)[1])


def loaded(modules, prefixes):
    return sorted(m for m in modules if any(m == p or m.startswith(p + ".") for p in prefixes))


def test_help_imports_no_numpy_and_no_command():
    pytest.importorskip("typer")
    result = run_cli(["--help"])
    assert result["code"] == 0
    assert loaded(result["modules"], NOT_FOR_HELP) == []
    commands = [m for m in result["modules"] if m.startswith("mocycle.cli.") and m != "mocycle.cli.common"]
    assert commands == [], "mocycle --help imported command modules"


@pytest.fixture(scope="module")
def walk_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("startup") / "walk.bvh"
    write(synthetic_walk(n_frames=240, fps=30).motion, path)
    return path


def test_loop_loads_only_what_a_loop_uses(walk_file, tmp_path):
    pytest.importorskip("typer")
    result = run_cli(["loop", walk_file, "-o", tmp_path / "cycle.bvh"])
    assert result["code"] == 0 and (tmp_path / "cycle.bvh").exists()
    assert loaded(result["modules"], NOT_FOR_LOOP) == []
    assert "mocycle.phase.cohomology" in result["modules"]  # the phase was found, by the light path


def test_the_command_table_matches_the_commands():
    """``mocycle --help`` shows each command's first help paragraph from a table: the table must say what the
    commands say, and name the module that defines each."""
    typer_main = pytest.importorskip("typer.main")
    from mocycle.cli import app
    from mocycle.cli.common import COMMANDS, LazyGroup

    group = typer_main.get_command(app)
    assert isinstance(group, LazyGroup)
    assert set(group.commands) == set(COMMANDS)  # registered in import order, listed in the table's
    assert group.list_commands(None) == list(COMMANDS)
    for name, (module, summary) in COMMANDS.items():
        command = group.commands[name]
        assert command.callback.__module__ == f"mocycle.cli.{module}"
        placeholder = type(command)(name=name, help=summary)
        for limit in (45, 80, 500):
            assert placeholder.get_short_help_str(limit) == command.get_short_help_str(limit), name


def test_a_misspelt_command_is_suggested():
    pytest.importorskip("typer")
    out = subprocess.run([sys.executable, "-m", "mocycle", "lopo"], capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)})
    assert out.returncode == 2 and "Did you mean 'loop'" in out.stderr
