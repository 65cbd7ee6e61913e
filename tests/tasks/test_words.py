"""The short words the front ends show for a task's facts (``mocycle.tasks.words``)."""

import math

from mocycle.cycle.checks import FailedCheck
from mocycle.tasks import words

REFUSAL = ("take 0: not a loop (fit: the cycle fits the take 3.96 times worse than a plain cut of 60 frames "
           "(template error 0.734 against 0.185 rad; limit 2.21×): the period found (90.0 frames) is probably "
           "wrong; stride: the cycle (90.0 frames) is 50% off the strides (each foot lands every 60.0 frames here, "
           "the legs repeating)); --force writes it anyway")


def test_a_refusal_in_plain_words_from_its_checks():
    failed = [FailedCheck("fit", 3.96, 2.21, "..."), FailedCheck("stride", 0.5, 0.06, "...")]
    assert words.refusal(failed) == ("not a loop: the cycle found does not match the take's own cycles; the cycle "
                                     "does not match the steps")
    assert words.refusal([f.to_dict() for f in failed]) == words.refusal(failed)
    assert words.refusal([{"check": "new", "value": 1, "limit": 0, "reason": ""}]) == \
        "not a loop: it fails the new check"
    assert set(words.CHECK_WORDS) >= {"length", "fit", "seam", "stride", "turn"}


def test_brief_cuts_a_page_to_a_line_at_a_clause():
    assert words.brief("no repeating motion: the actor stands still") == "no repeating motion: the actor stands still"
    line = words.brief(REFUSAL)
    assert len(line) <= words.LINE and line.endswith(" …") and REFUSAL.startswith(line[:-2])
    assert words.brief("x" * 400, 50) == "x" * 48 + " …"
    assert words.brief("a\n  b") == "a b"


def test_numbers_that_could_not_be_measured_are_not_shown():
    assert words.number(1.234, 1, "frames") == "1.2 frames"
    assert words.number(math.nan) is None and words.number(None) is None and words.number(math.inf, 2, "s") is None
    assert words.number("x") is None
