"""Text that leaves mocycle: names from files made printable, and strict JSON.

Names that come from files (joint names, take names, paths, error messages quoting a file) are data: they may
hold bytes that are not UTF-8 (a file name ``bad\\xffname.bvh`` reaches Python as ``'bad\\udcffname.bvh'``, a
lone surrogate, by the ``surrogateescape`` rule of :func:`os.fsdecode`), terminal control codes (ESC
sequences that recolour, retitle or hyperlink the terminal) or characters that turn the text around
(bidirectional overrides). :func:`printable` writes each such character as a visible escape, the way Python's
``backslashreplace`` does, so the text can be printed, encoded as UTF-8 and read by a person:

* a byte that was not UTF-8 (a surrogate U+DC80..U+DCFF) -> ``\\xNN`` (the byte);
* any other lone surrogate -> ``\\udNNN``;
* C0 and C1 control characters and DEL -> ``\\xNN``; bidirectional controls -> ``\\uNNNN``.

:func:`json_text` (what ``--json``, batch's ``results.json`` and its records write) keeps control characters
(JSON escapes them) and writes only the lone surrogates that way, so the JSON is valid UTF-8. The front ends
add their own escaping on top (``rich.markup.escape`` in the CLI, HTML escaping in the studio).

Importing this module loads nothing but the standard library (numpy only when :func:`json_text` runs).
"""

from __future__ import annotations

import json
import math
import os
import re

__all__ = ["json_text", "path_hex", "printable", "renamed", "unicode_clean", "valid_unicode"]

_SURROGATES = re.compile("[\ud800-\udfff]")
_UNPRINTABLE = re.compile("[\x00-\x1f\x7f-\x9f\u200e\u200f\u202a-\u202e\u2066-\u2069\ud800-\udfff]")


def _escape(match: re.Match) -> str:
    code = ord(match.group())
    if 0xDC80 <= code <= 0xDCFF:  # a byte that was not UTF-8 (surrogateescape)
        return f"\\x{code - 0xDC00:02x}"
    return f"\\x{code:02x}" if code <= 0xFF else f"\\u{code:04x}"


def printable(text) -> str:
    """``text`` (any object, as ``str``) with undecodable bytes, control and bidirectional characters written
    as visible escapes (``bad\\xffname.bvh``, ``\\x1b[31mred``); text without them comes back unchanged."""
    text = os.fsdecode(text) if isinstance(text, bytes) else str(text)
    return _UNPRINTABLE.sub(_escape, text)


def unicode_clean(text: str) -> str:
    """``text`` with lone surrogates written as escapes (as :func:`printable` does) and nothing else changed:
    what strict UTF-8 (a JSON or CSV file) can hold."""
    return _SURROGATES.sub(_escape, text)


def valid_unicode(text: str) -> str:
    """``text`` with every lone surrogate (text that is no Unicode: ``"\\ud800"`` from a JSON escape, a byte that
    was not UTF-8) replaced by U+FFFD, what a file that must be UTF-8 can hold."""
    return _SURROGATES.sub("\ufffd", text)


def renamed(names, fix, fmt: str, what: str = "joint name") -> list[str]:
    """``names`` as the format ``fmt`` can hold them: ``fix(name)`` of each, then a changed name that meets
    another gets ``.1``, ``.2``...; when any changed, one :class:`~mocycle.errors.MocycleWarning` says which
    (the first five), so a writer says it once per file."""
    import warnings

    from .errors import MocycleWarning

    names = [str(n) for n in names]
    fixed = [fix(n) for n in names]
    changed = [i for i, (a, b) in enumerate(zip(names, fixed, strict=True)) if a != b]
    if not changed:
        return fixed
    moved = set(changed)
    taken = {fixed[i] for i in range(len(fixed)) if i not in moved}
    following: dict[str, int] = {}  # base -> the next number to try (linear in the names)
    for i in changed:
        base = name = fixed[i]
        k = following.get(base, 1)
        while name in taken:
            name, k = f"{base}.{k}", k + 1
        following[base] = k
        taken.add(name)
        fixed[i] = name
    shown = ", ".join(f"{printable(repr(names[i]))} -> {printable(repr(fixed[i]))}" for i in changed[:5])
    more = f" and {len(changed) - 5} more" if len(changed) > 5 else ""
    plural = "s" if len(changed) > 1 else ""
    warnings.warn(f"{len(changed)} {what}{plural} changed to what {fmt} can hold: {shown}{more}", MocycleWarning,
                  stacklevel=3)
    return fixed


def path_hex(path) -> str | None:
    """The bytes of a path as hex when its name is not valid Unicode (its printable form then differs from
    the name itself), else ``None``: enough to find the very file again."""
    text = os.fspath(path)
    if isinstance(text, bytes):
        return text.hex()
    return os.fsencode(text).hex() if _SURROGATES.search(text) else None


def json_text(facts, indent: int | None = 2) -> str:
    """Strict JSON of ``facts``: NaN and infinities become ``null``, and the JSON says which and why; strings
    (keys too) with lone surrogates get them escaped (:func:`unicode_clean`), so the text is valid UTF-8.

    ``json.dumps`` would write ``NaN``/``Infinity``, which JSON parsers refuse.  The paths of the values
    written as ``null`` are listed under ``"null_because_not_finite"`` (for a dict at the top).

    The text is ``json.dumps(facts, indent=indent)`` of the cleaned facts, written at the speed of the C
    encoder (:func:`indented_json`); facts that need no cleaning (no non-finite number, no numpy value, no
    surrogate: what the C encoder takes as they are) are not walked in Python at all.
    """
    separators = (",", ": ") if indent is not None else (", ", ": ")
    try:
        text = json.JSONEncoder(separators=separators, allow_nan=False).encode(facts)
    except (TypeError, ValueError):  # a number that is not finite, a numpy value: clean the facts first
        text = None
    if text is None or _SURROGATE_ESCAPE.search(text):
        text = json.JSONEncoder(separators=separators, allow_nan=False).encode(_cleaned(facts))
    return text if indent is None else _indent(text, indent)


#: a surrogate escaped by json.dumps: a lone one, or half of a pair (either may have been a lone surrogate in
#: the facts, which :func:`unicode_clean` writes otherwise); an escaped backslash before ``u`` also matches
_SURROGATE_ESCAPE = re.compile(r"\\u[dD][89a-fA-F]")


def _cleaned(facts: object) -> object:
    """``facts`` as JSON takes them: numpy values as Python's, non-finite numbers as ``None`` (their paths under
    ``"null_because_not_finite"`` of a dict at the top), lone surrogates escaped (:func:`unicode_clean`)."""
    import numpy as np

    nulls: list[str] = []

    def clean(x, where: str):
        if isinstance(x, str):
            return unicode_clean(x)
        if isinstance(x, (float, np.floating)):
            if math.isfinite(x):
                return float(x)
            nulls.append(f"{where or 'value'} ({x})")
            return None
        if isinstance(x, np.integer):
            return int(x)
        if isinstance(x, np.ndarray):
            x = x.tolist()
        if isinstance(x, dict):
            return {(unicode_clean(k) if isinstance(k, str) else k): clean(v, f"{where}.{k}" if where else str(k))
                    for k, v in x.items()}
        if isinstance(x, (list, tuple)):
            return [clean(v, f"{where}[{i}]") for i, v in enumerate(x)]
        return x

    out = clean(facts, "")
    if nulls and isinstance(out, dict):
        out["null_because_not_finite"] = [unicode_clean(n) for n in nulls]
    return out


def indented_json(obj, indent: int | str | None = 2, allow_nan: bool = True) -> str:
    """``json.dumps(obj, indent=indent, allow_nan=allow_nan)``: the same text, at the speed of the C encoder.

    Python's C encoder writes no indentation (3.11-3.13), so ``json.dumps`` with ``indent`` runs the
    pure-Python encoder.  Here the C encoder writes the compact text and :func:`_indent` breaks its lines.
    """
    if indent is None:
        return json.dumps(obj, allow_nan=allow_nan)
    return _indent(json.JSONEncoder(separators=(",", ": "), allow_nan=allow_nan).encode(obj), indent)


def _indent(text: str, indent: int | str) -> str:
    """Compact JSON (ASCII, item separator ``","``, key separator ``": "``) laid out as ``json.dumps`` lays
    it out with ``indent``: a line per item, indented by depth; ``[]`` and ``{}`` stay whole.

    numpy passes over the bytes: the string delimiters (quotes after an even run of backslashes), the
    brackets and commas outside strings, their depths (a cumulative sum), then each line break inserted by
    shifting the bytes after it (a cumulative sum of the inserted lengths)."""
    import numpy as np

    pad = " " * indent if isinstance(indent, int) else str(indent)
    if pad and pad != pad[0] * len(pad):  # an indent of mixed characters: json.dumps itself
        return json.dumps(json.loads(text), indent=pad)
    data = np.frombuffer(text.encode("ascii"), dtype=np.uint8)
    n = data.size
    marks = np.flatnonzero((data == 44) | (data == 91) | (data == 93) | (data == 123) | (data == 125))
    if marks.size == 0:
        return text
    quotes = np.flatnonzero(data == 34)
    escaped = np.zeros(quotes.size, dtype=bool)
    for k in np.flatnonzero(data[np.maximum(quotes - 1, 0)] == 92).tolist():  # a backslash before: rare
        q = int(quotes[k])
        run = q - 1
        while run >= 0 and data[run] == 92:
            run -= 1
        escaped[k] = (q - 1 - run) % 2 == 1
    delimiters = quotes[~escaped]
    marks = marks[np.searchsorted(delimiters, marks) % 2 == 0]  # outside strings: an even number of quotes before
    kind = data[marks]
    opens, closes = (kind == 91) | (kind == 123), (kind == 93) | (kind == 125)
    depth = np.cumsum(opens.astype(np.int64)) - np.cumsum(closes)  # inside an opening, outside a closing
    empty_open = opens & np.append(closes[1:], False) & np.append(marks[1:] == marks[:-1] + 1, False)
    empty_close = np.append(False, empty_open[:-1])
    after = ((opens & ~empty_open) | (kind == 44))  # a line break after an opening and after a comma
    before = closes & ~empty_close  # and before a closing
    at = np.concatenate([marks[after] + 1, marks[before]])
    length = 1 + len(pad) * np.concatenate([depth[after], depth[before]])
    added = np.zeros(n, dtype=np.int64)
    added[at] = length
    shift = np.cumsum(added)
    out = np.full(n + int(shift[-1]), ord(pad[0]) if pad else 10, dtype=np.uint8)
    position = np.arange(n) + shift
    out[position] = data
    out[position[at] - length] = 10
    return out.tobytes().decode("ascii")
