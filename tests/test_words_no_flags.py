"""Messages raised or warned below the front ends name no CLI flag (issue 39): Blender and the studio show them
to users who have no flags.  What would help is said as a hint (``mocycle.errors.Hint``: ``option 'force'``),
which each front end renders in its own terms (the CLI as ``--force``)."""

import ast
import re
from pathlib import Path

from mocycle.errors import Hint, render_hints
from mocycle.tasks import words

SRC = Path(__file__).resolve().parents[1] / "src" / "mocycle"
FRONT_ENDS = {"cli", "studio", "blender", "batch", "viz"}
FLAG = re.compile(r"(?<![\w-])--[a-z][a-z-]+")
#: file:line -> why a flag there is fine (none so far)
ALLOWED: dict[str, str] = {}


def _message_strings(call: ast.Call):
    for node in ast.walk(call):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            yield node


def _is_message_call(node: ast.AST) -> bool:
    """``raise X(...)`` is found by its Raise node; here: ``warnings.warn(...)`` / ``warn(...)``."""
    if not isinstance(node, ast.Call):
        return False
    f = node.func
    return (isinstance(f, ast.Attribute) and f.attr in ("warn", "warn_explicit")) or \
        (isinstance(f, ast.Name) and f.id == "warn")


def test_no_cli_flag_in_library_messages():
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if path.relative_to(SRC).parts[0] in FRONT_ENDS:
            continue
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and node.exc is not None:
                strings = _message_strings(node.exc)
            elif _is_message_call(node):
                strings = _message_strings(node)
            else:
                continue
            for s in strings:
                where = f"{path.relative_to(SRC.parent)}:{s.lineno}"
                if FLAG.search(s.value) and where not in ALLOWED:
                    found.append(f"{where}: {s.value!r}")
    assert not found, "CLI flags in library messages (say them as mocycle.errors.Hint):\n" + "\n".join(found)


def test_front_ends_render_a_hint_in_their_own_terms():
    from mocycle.tasks.flags import as_flags

    text = f"take 0: not a loop (seam: ...); {Hint('force')} writes it anyway"
    assert text.endswith("; option 'force' writes it anyway")
    assert as_flags(text, "loop") == "take 0: not a loop (seam: ...); --force writes it anyway"
    assert as_flags(f"use {Hint('model', 'M2')} or fewer harmonics") == "use --model M2 or fewer harmonics"
    assert as_flags(f"pass {Hint('gltf_scale')} (metres per unit)") == "pass --gltf-scale (metres per unit)"
    assert as_flags(f"got {Hint('which', 3)}", "loop") == "got --part 3"
    assert words.hints(text).endswith("; Force writes it anyway")
    assert words.hints(f"use {Hint('model', 'M2')}") == "use Model set to M2"
    assert render_hints("no hint here", lambda o, v: "x") == "no hint here"


def test_every_hint_names_an_option_the_cli_knows():
    """A hint in a library message names an ``Options`` field (or a front-end option the CLI declares): renaming
    the field without the message would leave the CLI printing a flag that does not exist."""
    from mocycle.errors import HINT
    from mocycle.tasks.flags import flags

    known = set(flags()) | {"force", "take"}  # --force and --take: the CLI's own flags of every task that reads
    found = []
    for path in sorted(SRC.rglob("*.py")):
        if path.relative_to(SRC).parts[0] in FRONT_ENDS:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Constant) and isinstance(node.value, str):
                found += [(f"{path.name}:{node.lineno}", m.group(1)) for m in HINT.finditer(node.value)]
    assert found, "no hint found: the pattern no longer matches the messages"
    unknown = [f"{where}: {option}" for where, option in found if option not in known]
    assert not unknown, unknown
