"""Names from files are data on the terminal: joints named ``[/]``, ``[link=...]`` or with an ESC sequence, and
file names that are not UTF-8, print as visible text through every command (issue 30), never as rich markup,
a terminal hyperlink, a colour change or a traceback."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from typer.testing import CliRunner

import mocycle
from mocycle.cli import app
from mocycle.cli.common import escape
from mocycle.datasets import synthetic_walk
from mocycle.text import json_text, path_hex, printable, unicode_clean

runner = CliRunner()
SRC = str(Path(__file__).resolve().parents[1] / "src")

#: joint of the synthetic walk -> the hostile name it gets
HOSTILE = {"Spine": "[/]", "Neck": "[link=http://x]y[/link]", "Head": "\x1b[31mred"}


@pytest.fixture(scope="module")
def hostile(tmp_path_factory) -> Path:
    """The synthetic walk with three joints renamed (the BVH reader takes any name without white space)."""
    folder = tmp_path_factory.mktemp("hostile")
    text = mocycle.write(synthetic_walk(n_frames=90, fps=30).motion, folder / "plain.bvh").read_text()
    for old, new in HOSTILE.items():
        assert f"JOINT {old}\n" in text
        text = text.replace(f"JOINT {old}\n", f"JOINT {new}\n")
    path = folder / "hostile.bvh"
    path.write_text(text)
    assert set(HOSTILE.values()) <= set(mocycle.read(path).skeleton.names)
    return path


@pytest.fixture(scope="module")
def undecodable(tmp_path_factory) -> Path:
    """A take whose file name is not UTF-8 (the byte 0xff), as Python names it: ``bad\\udcffname.bvh``."""
    folder = tmp_path_factory.mktemp("bytes")
    plain = mocycle.write(synthetic_walk(n_frames=90, fps=30).motion, folder / "plain.bvh")
    target = os.path.join(os.fsencode(folder), b"bad\xffname.bvh")
    shutil.copyfile(os.fsencode(plain), target)
    return Path(os.fsdecode(target))


def _clean(result, code=0):
    """The run ended with ``code``, no exception escaped, and nothing but the text reached the terminal."""
    assert result.exit_code == code, result.output
    assert result.exception is None or isinstance(result.exception, SystemExit), repr(result.exception)
    assert "Traceback" not in result.output and "MarkupError" not in result.output
    assert "\x1b" not in result.output, "a control character from the file reached the terminal"
    return " ".join(result.output.split())


def test_printable_writes_what_is_not_text_as_visible_escapes():
    assert printable("walk.bvh") == "walk.bvh"  # ordinary text is untouched, non-ASCII letters too
    assert printable("Gehäuse") == "Gehäuse"
    assert printable("bad\udcffname.bvh") == "bad\\xffname.bvh"  # a byte that was not UTF-8
    assert printable(b"bad\xffname.bvh") == "bad\\xffname.bvh"
    assert printable("\x1b[31mred\x07\n") == "\\x1b[31mred\\x07\\x0a"
    assert printable("a\u202eb\x9bc\ud800") == "a\\u202eb\\x9bc\\ud800"  # bidi override, C1 CSI, lone surrogate
    assert unicode_clean("\x1b\udcff") == "\x1b\\xff"  # for JSON: only what UTF-8 cannot hold
    assert path_hex("walk.bvh") is None and path_hex("bad\udcff.bvh") == b"bad\xff.bvh".hex()


def test_escape_makes_names_plain_text_for_rich():
    from rich.console import Console

    console = Console(force_terminal=True, color_system="truecolor", width=200, highlight=False)
    with console.capture() as captured:
        for name in HOSTILE.values():
            console.print(f"[bold]{escape(name)}[/]")
    text = captured.get()
    assert "[/]" in text and "[link=http://x]y[/link]" in text and "\\x1b[31mred" in text
    assert "\x1b]8;" not in text and "\x1b[31m" not in text  # no hyperlink, no colour from the name


def test_json_text_is_valid_utf8_for_undecodable_names():
    text = json_text({"file": "bad\udcffname.bvh", "bad\udcffkey": 1.0, "esc": "\x1b"})
    text.encode("utf-8")  # strict: raises on a lone surrogate
    assert json.loads(text) == {"file": "bad\\xffname.bvh", "bad\\xffkey": 1.0, "esc": "\x1b"}


@pytest.mark.parametrize("command", [["info"], ["swings"], ["phase"], ["loop", "-o", "{tmp}/loop.bvh"],
                                     ["compress", "-o", "{tmp}/take.mck"], ["stretch", "--factor", "1.5", "-o",
                                                                             "{tmp}/long.bvh"]])
def test_hostile_joint_names_print_as_text(hostile, tmp_path, command):
    args = [a.format(tmp=tmp_path) for a in command]
    text = _clean(runner.invoke(app, [args[0], str(hostile), *args[1:]]))
    if args[0] in ("info", "swings"):  # the commands that list joints
        assert "[/]" in text and "[link=http://x]" in text and "\\x1b[31mred" in text


@pytest.mark.parametrize("command", ["info", "phase", "swings"])
def test_hostile_joint_names_in_json_are_the_names(hostile, command):
    result = runner.invoke(app, [command, str(hostile), "--json"])
    assert result.exit_code == 0, result.output
    facts = json.loads(result.stdout)
    if command == "info":
        assert set(HOSTILE.values()) <= set(facts["rotation_spread_deg"])  # JSON keeps the exact names
    if command == "swings":
        assert set(HOSTILE.values()) <= set(facts["swing_indices"])


def test_on_a_real_terminal_no_hyperlink_or_colour_comes_from_a_name(hostile):
    """With colour on (``FORCE_COLOR``) rich writes its own ESC sequences; none may come from the names."""
    env = {**os.environ, "PYTHONPATH": SRC, "FORCE_COLOR": "1", "COLUMNS": "200"}
    for command in ("info", "swings"):
        run = subprocess.run([sys.executable, "-m", "mocycle", command, str(hostile)], capture_output=True,
                             text=True, env=env, timeout=120)
        assert run.returncode == 0, run.stderr
        assert "\x1b[" in run.stdout  # colour is on
        assert "\x1b]8;" not in run.stdout and "\x1b[31mred" not in run.stdout
        assert "\\x1b[31mred" in run.stdout and "[link=http://x]" in run.stdout


def test_an_error_quoting_a_hostile_file_name_is_one_plain_line(tmp_path):
    bad = tmp_path / "[link=x]y[bold]\x1b[31m.bvh"  # (a file name holds no '/')
    bad.write_text("HIERARCHY\nROOT Hips\n{\n")
    text = _clean(runner.invoke(app, ["info", str(bad)]), code=1)
    assert text.startswith("error: ") and "[link=x]y[bold]\\x1b[31m.bvh" in text


@pytest.mark.parametrize("command", [["info"], ["phase"], ["swings"], ["loop", "-o", "{tmp}/loop.bvh"],
                                     ["report", "-o", "{tmp}/report.html"]])
def test_a_file_name_that_is_not_utf8_prints_escaped(undecodable, tmp_path, command):
    args = [a.format(tmp=tmp_path) for a in command]
    text = _clean(runner.invoke(app, [args[0], str(undecodable), *args[1:]]))
    if args[0] != "report":
        assert "bad\\xffname.bvh" in text
    else:
        assert "bad\\xffname.bvh" in (tmp_path / "report.html").read_text(encoding="utf-8")


def test_a_bad_file_whose_name_is_not_utf8_is_one_error_line(tmp_path):
    target = os.path.join(os.fsencode(tmp_path), b"bad\xff.bvh")
    with open(target, "wb") as fh:
        fh.write(b"HIERARCHY\nROOT Hips\n{\n")
    result = runner.invoke(app, ["info", os.fsdecode(target)])
    text = _clean(result, code=1)
    assert text.startswith("error: ") and "bad\\xff.bvh" in text and len(result.output.strip().splitlines()) == 1
    json_run = runner.invoke(app, ["info", os.fsdecode(os.path.join(os.fsencode(tmp_path), b"none\xff.bvh")),
                                   "--json"])
    assert json_run.exit_code == 1 and "Traceback" not in json_run.output
