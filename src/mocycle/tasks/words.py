"""Short plain words for what a task's facts say, for the front ends that have one line to say it in (Blender's
status bar and panel, the studio's library and loop status).  The technical detail stays where it is (the
exception's message, ``facts["failed_checks"][k]["reason"]``, the part's ``reason``); a front end shows it one
click away.  Standard library only (imported by the Blender add-on and the studio without numpy).
"""

from __future__ import annotations

import math

#: each loop check (:mod:`mocycle.cycle.checks`, :func:`mocycle.cycle.parts.part_checks`) in a few plain words
CHECK_WORDS = {
    "length": "the take holds less than one whole cycle",
    "fit": "the cycle found does not match the take's own cycles",
    "seam": "the loop jumps where it wraps",
    "stride": "the cycle does not match the steps",
    "turn": "the loop does not turn as the take does",
}

#: the longest message a one-line place shows before :func:`brief` cuts it
LINE = 160


def check_words(check) -> str:
    """One failed check (a ``FailedCheck`` or its ``to_dict()``) in plain words."""
    name = check.get("check", check.get("name", "")) if isinstance(check, dict) else getattr(check, "name", "")
    return CHECK_WORDS.get(str(name), f"it fails the {name} check")


def refusal(failed_checks) -> str:
    """Why a loop was refused, short: ``"not a loop: the loop jumps where it wraps"``; each failed check's own
    reason (with its numbers) is the detail."""
    words = list(dict.fromkeys(check_words(c) for c in failed_checks))
    return "not a loop: " + ("; ".join(words) if words else "it fails a loop check")


def brief(text: str, limit: int = LINE) -> str:
    """``text`` if it fits in ``limit`` characters, else cut after its last clause that does (at ``"; "``, a
    parenthesis or ``": "``) with ``" …"``: a line that says the start of the reason, never a page.  The whole
    text is the detail."""
    text = " ".join(str(text).split())
    if len(text) <= limit:
        return text
    head = text[: limit - 2]
    cut = max(head.rfind("; "), head.rfind(" ("), head.rfind(": "))
    if cut < limit // 3:  # no clause ends early enough: cut at a word
        cut = head.rfind(" ")
    return (head[:cut] if cut > 0 else head).rstrip(" ;:,") + " …"


def number(value, digits: int = 2, unit: str = "") -> str | None:
    """``value`` with ``digits`` decimals and its unit, or None when it is not a finite number (a figure that
    could not be measured is not shown as ``nan``)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    if not math.isfinite(v):
        return None
    return f"{v:.{digits}f}" + (f" {unit}" if unit else "")


def hints(text: str) -> str:
    """A library message with its hints (``option 'force'``, ``option 'model' = M2``: :class:`mocycle.errors.Hint`)
    said as the option's name, as a panel or form labels it (``Force``, ``Model set to M2``), never a CLI flag."""
    from ..errors import render_hints

    def name(option: str, value: str | None) -> str:
        label = option.replace("_", " ").capitalize()
        return label if value is None else f"{label} set to {value}"

    return render_hints(text, name)


def written_skate(feet, metrics) -> float | None:
    """The foot skate (units/s) of the loop written: after locking when the feet were locked (``feet``: a
    report's ``feet`` facts), else as fitted (``metrics``' ``skate``); ``None`` when not measured."""
    after = feet.get("skate_after") if isinstance(feet, dict) else None
    return after if after is not None else (metrics or {}).get("skate")
