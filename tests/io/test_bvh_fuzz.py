"""Fuzzing the BVH reader: broken input gives a Motion or a MotionFileError, nothing else.

Every :class:`MotionFileError` from ``parse_bvh(..., path="fuzz.bvh")`` must
start with ``fuzz.bvh:<line>: `` and name a line that exists.  Inputs that do
parse must survive ``format_bvh`` -> ``parse_bvh`` unchanged (up to the 9
significant digits the writer keeps).
"""

from __future__ import annotations

import os
import re
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fuzzing import limits
from mocycle.errors import MocycleWarning, MotionFileError
from mocycle.io import atomic
from mocycle.io.bvh import format_bvh, parse_bvh, write_bvh
from mocycle.motion import Motion

pytestmark = pytest.mark.filterwarnings("ignore::mocycle.errors.MocycleWarning")

# The default run is deterministic (same examples every time, a few seconds);
# MOCYCLE_FUZZ_EXAMPLES=5000 hunts longer with fresh random examples.
_HUNT = os.environ.get("MOCYCLE_FUZZ_EXAMPLES")
FUZZ = settings(
    max_examples=int(_HUNT or 250),
    derandomize=not _HUNT,
    database=None if not _HUNT else settings.default.database,
    deadline=2000,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)

# Four joints: a 6-channel root, a 3-channel joint, a 0-channel joint with an
# End Site, and a non-root 6-channel joint with a space in its name and a
# lowercase, named "End site"; every joint has its own channel order.
VALID = """HIERARCHY
ROOT Hips
{
\tOFFSET 0.0 90.5 -1.25
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Chest
\t{
\t\tOFFSET 0 10 0
\t\tCHANNELS 3 Yrotation Xrotation Zrotation
\t\tJOINT Neck
\t\t{
\t\t\tOFFSET 0 12.5 1
\t\t\tCHANNELS 0
\t\t\tEnd Site
\t\t\t{
\t\t\t\tOFFSET 0 8 0
\t\t\t}
\t\t}
\t}
\tJOINT Left Leg
\t{
\t\tOFFSET 8 -4 0
\t\tCHANNELS 6 Zposition Yposition Xposition Xrotation Zrotation Yrotation
\t\tEnd site LeftToe
\t\t{
\t\t\tOFFSET 0 -40 3
\t\t}
\t}
}
MOTION
Frames: 3
Frame Time: 0.0083333
1.5 90 -2 10 20 30 5 -5 15 0.5 -4 8 1 2 3
1.75 90.25 -2.5 11 19 29 6 -4 14 0.25 -4.5 8.5 2 3 4
2 90.5 -3 12 18 28 7 -3 13 0 -5 9 3 4 5
"""
# Tabs between words (not inside joint names or "Frame Time:") and before each line end.
TABS = re.sub(r"(?<=[\w.:]) (?=[-\w])", "\t", VALID).replace("Left\tLeg", "Left Leg")
TABS = TABS.replace("Frame\tTime", "Frame Time").replace("\n", "\t\n")
FIRST_ROW_LINE = VALID.splitlines().index("Frame Time: 0.0083333") + 2  # 1-based
# A UTF-8 name, so that byte-level damage can break a multi-byte sequence.
VALID_BYTES = VALID.replace("Neck", "Nacken_\u00e4\u20ac").encode("utf-8")

VOCAB = [
    "HIERARCHY", "ROOT", "JOINT", "End Site", "End site", "OFFSET", "CHANNELS", "{", "}",
    "MOTION", "Frames:", "Frame Time:", "Xposition", "Yposition", "Zposition",
    "Xrotation", "Yrotation", "Zrotation", "0", "3", "6", "-1.5", "1e3", "nan", "inf", "Hips",
    "Left Leg", "Site",
]
SPECIAL_CHARS = list("{}:.-+eE0123456789 \t\n\r#") + ["\r\n", "\x00", "\x0b", "\xa0", "\u00e4"]


def n_lines(data: str | bytes) -> int:
    """Number of lines the way the reader counts them (CRLF and CR are line ends)."""
    text = data.decode("latin-1") if isinstance(data, bytes) else data
    return text.replace("\r\n", "\n").replace("\r", "\n").count("\n") + 1


def assert_same_motion(a: Motion, b: Motion, exact: bool = True) -> None:
    sa, sb = a.skeleton, b.skeleton
    # names with white space inside are written one word each (a joint "Left Leg" as "Left_Leg")
    assert ["_".join(n.split()) for n in sa.names] == ["_".join(n.split()) for n in sb.names]
    assert np.array_equal(sa.parents, sb.parents)
    assert sa.channels == sb.channels
    assert [(s.parent, s.name and "_".join(s.name.split())) for s in sa.end_sites] == \
        [(s.parent, s.name and "_".join(s.name.split())) for s in sb.end_sites]
    assert a.frame_time == b.frame_time
    if exact:
        assert np.array_equal(sa.offsets, sb.offsets)
        assert [s.offset for s in sa.end_sites] == [s.offset for s in sb.end_sites]
        assert np.array_equal(a.rotations, b.rotations)
        assert np.array_equal(a.translations, b.translations)
    else:
        assert np.allclose(sa.offsets, sb.offsets, rtol=1e-8, atol=1e-12)
        assert np.allclose(
            [s.offset for s in sa.end_sites] or 0, [s.offset for s in sb.end_sites] or 0,
            rtol=1e-8, atol=1e-12,
        )
        dots = np.abs(np.sum(a.rotations * b.rotations, axis=-1))
        assert np.all(dots > 1 - 1e-9)
        assert np.allclose(a.translations, b.translations, rtol=1e-8, atol=1e-9)


def check(data: str | bytes) -> Motion | None:
    """parse_bvh gives a Motion (which round-trips) or a MotionFileError naming a real line.

    Warnings other than MocycleWarning (numpy's, say) are errors here: they are noise to users.
    """
    try:
        with limits(), warnings.catch_warnings():  # memory and time limits per example
            warnings.simplefilter("error")
            warnings.simplefilter("ignore", MocycleWarning)
            motion = parse_bvh(data, path="fuzz.bvh")
    except MotionFileError as exc:
        msg = str(exc)
        assert re.match(r"fuzz\.bvh:\d+: \S", msg), msg
        assert exc.line is not None and 1 <= exc.line <= n_lines(data), (exc.line, msg)
        return None
    assert isinstance(motion, Motion)
    assert motion.n_frames >= 1
    assert np.all(np.isfinite(motion.rotations)) and np.all(np.isfinite(motion.translations))
    again = parse_bvh(format_bvh(motion), path="roundtrip.bvh")
    assert again.n_frames == motion.n_frames
    assert_same_motion(motion, again, exact=False)
    return motion


# -- (a) truncation -------------------------------------------------------


def test_valid_text_parses():
    m = check(VALID)
    assert m is not None
    assert m.skeleton.names == ("Hips", "Chest", "Neck", "Left Leg")
    assert m.n_frames == 3


def test_truncated_at_every_position():
    full = parse_bvh(VALID)
    for k in range(len(VALID) + 1):
        m = check(VALID[:k])
        if m is not None:
            assert m.skeleton.names == full.skeleton.names
            assert 1 <= m.n_frames <= 3
            np.testing.assert_array_equal(m.rotations, full.rotations[: m.n_frames])


@FUZZ
@given(st.integers(0, len(VALID_BYTES)), st.sampled_from([b"\n", b"\r\n", b"\r"]))
def test_truncated_bytes_any_line_end(k, eol):
    check(VALID_BYTES.replace(b"\n", eol)[:k])


# -- (b) substitutions, deletions and insertions --------------------------

token = st.one_of(
    st.sampled_from(VOCAB),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.integers(-5, 10).map(str),
    st.text(alphabet="abcXYZ_ {}", min_size=1, max_size=5),
)
separator = st.sampled_from([" ", "\t", "\n", "\n", "\r\n", "\r", "\n\n"])


@st.composite
def edited(draw, base: str):
    """``base`` after 1-6 random edits of characters, words or whole lines."""
    text = base
    for _ in range(draw(st.integers(1, 6))):
        op = draw(st.sampled_from(["sub", "del", "ins", "word", "word", "dup_line", "drop_line"]))
        pos = draw(st.integers(0, max(len(text) - 1, 0)))
        char = draw(st.one_of(st.sampled_from(SPECIAL_CHARS), st.characters()))
        if op == "sub":
            text = text[:pos] + char + text[pos + 1 :]
        elif op == "del":
            text = text[:pos] + text[pos + draw(st.integers(1, 20)) :]
        elif op == "ins":
            text = text[:pos] + char + text[pos:]
        else:
            lines = text.split("\n")
            i = draw(st.integers(0, len(lines) - 1))
            if op == "word":  # replace, add or drop one word of a line
                words = lines[i].split(" ")
                k = draw(st.integers(0, len(words)))
                new = [draw(token)] if draw(st.booleans()) else []
                words[k : k + draw(st.integers(0, 1))] = new
                lines[i] = " ".join(words)
            else:
                lines[i : i + 1] = [lines[i]] * 2 if op == "dup_line" else []
            text = "\n".join(lines)
    return text


@FUZZ
@given(edited(VALID))
def test_edited_text(text):
    check(text)


@FUZZ
@given(st.lists(st.tuples(st.integers(0, len(VALID_BYTES) - 1), st.binary(max_size=3)),
                min_size=1, max_size=6))
def test_edited_bytes(edits):
    data = bytearray(VALID_BYTES)
    for pos, chunk in edits:
        data[pos : pos + 1] = chunk  # replace one byte by 0-3 bytes: substitution/deletion/insertion
    check(bytes(data))


# -- (c) random text and bytes --------------------------------------------


@FUZZ
@given(st.text())
def test_random_text(text):
    check(text)


@FUZZ
@given(st.binary())
def test_random_bytes(data):
    check(data)


@FUZZ
@given(st.text(alphabet=[c for c in SPECIAL_CHARS if len(c) == 1] + list("HIERARCHYROTJNMSFrotafime")))
def test_random_text_after_hierarchy(text):
    check("HIERARCHY\n" + text)


# -- (d) token streams from the BVH vocabulary ----------------------------

PREFIXES = [
    "",
    "HIERARCHY\n",
    "HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 3 Zrotation Xrotation Yrotation\n",
    VALID[: VALID.index("MOTION")],
    VALID[: VALID.index("Frames:")],
    VALID[: VALID.index("1.5 90")],
]


@FUZZ
@given(st.sampled_from(PREFIXES), st.lists(st.tuples(token, separator), max_size=80))
def test_token_stream(prefix, pairs):
    check(prefix + "".join(t + s for t, s in pairs))


@st.composite
def bvh_texts(draw):
    """A structurally valid BVH with a random tree, random channels and random numbers."""
    n_joints = draw(st.integers(1, 5))
    parents = [-1] + [draw(st.integers(0, j - 1)) for j in range(1, n_joints)]
    number = st.floats(-1e4, 1e4, allow_nan=False).map(lambda x: f"{x:.6g}")
    chan_lists = []
    for j in range(n_joints):
        rot = draw(st.permutations(["Xrotation", "Yrotation", "Zrotation"]))
        pos = draw(st.permutations(["Xposition", "Yposition", "Zposition"]))
        kind = draw(st.sampled_from([0, 3, 6]) if j else st.sampled_from([3, 6]))
        chan_lists.append({0: [], 3: rot, 6: pos + rot}[kind])
    eol = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    ind = draw(st.sampled_from(["\t", "  ", ""]))
    out = ["HIERARCHY"]

    def emit(j, depth):
        pad = ind * depth
        name = f"J{j}" + draw(st.sampled_from(["", " part", "_x"]))
        out.append(f"{pad}{'ROOT' if j == 0 else 'JOINT'} {name}")
        out.append(pad + "{")
        out.append(f"{pad}{ind}OFFSET {draw(number)} {draw(number)} {draw(number)}")
        out.append(f"{pad}{ind}CHANNELS {len(chan_lists[j])} {' '.join(chan_lists[j])}".rstrip())
        kids = [k for k in range(n_joints) if parents[k] == j]
        for k in kids:
            emit(k, depth + 1)
        if not kids or draw(st.booleans()):
            out.append(pad + ind + draw(st.sampled_from(["End Site", "End site", "End Site tip"])))
            out.append(pad + ind + "{")
            out.append(f"{pad}{ind * 2}OFFSET {draw(number)} {draw(number)} {draw(number)}")
            out.append(pad + ind + "}")
        out.append(pad + "}")

    emit(0, 0)
    n_frames = draw(st.integers(1, 4))
    n_chan = sum(len(c) for c in chan_lists)
    out += ["MOTION", f"Frames: {n_frames}", "Frame Time: 0.0333333"]
    for _ in range(n_frames):
        out.append(" ".join(draw(number) for _ in range(n_chan)))
    return eol.join(out) + eol, n_frames


@FUZZ
@given(bvh_texts())
def test_random_valid_skeletons_parse(case):
    text, n_frames = case
    m = check(text)
    assert m is not None
    assert m.n_frames == n_frames


@FUZZ
@given(bvh_texts(), st.data())
def test_random_valid_skeletons_edited(case, data):
    check(data.draw(edited(case[0])))


# -- specific messages ----------------------------------------------------


def _error(text: str) -> MotionFileError:
    with pytest.raises(MotionFileError) as info:
        parse_bvh(text, path="fuzz.bvh")
    return info.value


def test_superscript_channel_count_is_a_motion_file_error():
    # "³".isdigit() is True but int("³") raised a bare ValueError (found by this fuzzing).
    exc = _error(VALID.replace("CHANNELS 3 Y", "CHANNELS \u00b3 Y"))
    assert exc.line == 9


@pytest.mark.parametrize("word", ["1_5", "\u0661.5", "\uff11.5"])
def test_number_loadtxt_rejects_names_its_row(word):
    # float() accepts these, np.loadtxt does not: the bad row must still be the one named.
    exc = _error(VALID.replace("1.75 90.25", word + " 90.25"))
    assert exc.line == FIRST_ROW_LINE + 1, str(exc)


def test_no_rows_after_frame_time():
    for tail in ["", "\n", "\n\n  \n"]:
        text = VALID[: VALID.index("1.5 90") - 1] + tail
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no stray numpy warning either
            exc = _error(text)
        assert "no frame rows" in exc.reason


def test_missing_frame_time():
    exc = _error(VALID.replace("Frame Time: 0.0083333\n", ""))
    assert "Frame Time" in str(exc)
    assert str(exc).startswith(f"fuzz.bvh:{FIRST_ROW_LINE - 1}: ")


@pytest.mark.parametrize("value", ["0", "0.0", "-0.01", "nan", "inf", "", "abc"])
def test_bad_frame_time(value):
    exc = _error(VALID.replace("Frame Time: 0.0083333", f"Frame Time: {value}"))
    assert exc.line == FIRST_ROW_LINE - 1
    assert "Frame Time" in exc.reason


@pytest.mark.parametrize("row", [0, 1, 2])
def test_wrong_value_count_names_the_row(row):
    lines = VALID.split("\n")
    lines[FIRST_ROW_LINE - 1 + row] += " 7"
    exc = _error("\n".join(lines))
    assert exc.line == FIRST_ROW_LINE + row
    assert "15" in exc.reason and "16" in exc.reason


def test_non_number_names_the_row():
    exc = _error(VALID.replace("0.25 -4.5", "0.25 x4.5"))
    assert exc.line == FIRST_ROW_LINE + 1
    assert "x4.5" in exc.reason


@pytest.mark.parametrize("declared", [1, 2, 4, 100])
def test_frames_count_disagreeing_warns_and_rows_win(declared):
    text = VALID.replace("Frames: 3", f"Frames: {declared}")
    with pytest.warns(MocycleWarning, match="3 frame rows"):
        m = parse_bvh(text, path="fuzz.bvh")
    assert m.n_frames == 3
    assert_same_motion(m, parse_bvh(VALID))


def test_matching_frames_count_does_not_warn():
    with warnings.catch_warnings():
        warnings.simplefilter("error", MocycleWarning)
        parse_bvh(VALID)


@pytest.mark.parametrize(
    "variant",
    [
        VALID.replace("\n", "\r\n"),
        VALID.replace("\n", "\r"),
        VALID.replace("\t", "    "),
        TABS,
        VALID.replace("\n", "  \r\n").encode("utf-8"),
        b"\xef\xbb\xbf" + VALID.encode("utf-8"),
    ],
    ids=["crlf", "cr", "spaces", "tabs", "trailing-space-crlf-bytes", "bom"],
)
def test_line_end_and_whitespace_variants_are_the_same_motion(variant):
    assert_same_motion(parse_bvh(variant, path="fuzz.bvh"), parse_bvh(VALID))


def test_lowercase_named_end_site_and_names_with_spaces():
    m = parse_bvh(VALID)
    assert "Left Leg" in m.skeleton.names
    sites = {s.name: s for s in m.skeleton.end_sites}
    assert set(sites) == {None, "LeftToe"}
    assert sites["LeftToe"].parent == m.skeleton.index("Left Leg")
    assert sites["LeftToe"].offset == (0.0, -40.0, 3.0)
    text = format_bvh(m)
    assert "JOINT Left_Leg" in text and "End Site LeftToe" in text  # one word each
    assert_same_motion(parse_bvh(text), m, exact=False)


def test_non_root_six_channel_joint_keeps_positions():
    m = parse_bvh(VALID)
    leg = m.skeleton.index("Left Leg")
    # channels are Zposition Yposition Xposition: the file lists z, y, x
    expected = [[8, -4, 0.5], [8.5, -4.5, 0.25], [9, -5, 0]]
    np.testing.assert_array_equal(m.translations[:, leg], expected)
    again = parse_bvh(format_bvh(m))
    np.testing.assert_allclose(again.translations[:, leg], expected, rtol=1e-9)
    assert again.skeleton.channels[leg] == m.skeleton.channels[leg]
    assert_same_motion(again, m, exact=False)


def test_joint_with_zero_channels():
    m = parse_bvh(VALID)
    neck = m.skeleton.index("Neck")
    assert m.skeleton.channels[neck] == ()
    np.testing.assert_array_equal(m.rotations[:, neck], np.tile([0.0, 0, 0, 1], (3, 1)))
    np.testing.assert_array_equal(m.translations[:, neck], np.tile([0, 12.5, 1], (3, 1)))
    text = format_bvh(m)
    assert "CHANNELS 0\n" in text
    assert_same_motion(parse_bvh(text), m, exact=False)


# -- write_bvh never leaves a partial file --------------------------------


class _FailingFile:
    """Wraps a real file: writes the first half of the data, then fails like a full disk."""

    def __init__(self, fh):
        self.fh = fh

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.fh.close()
        return False

    def write(self, data):
        self.fh.write(data[: len(data) // 2])
        self.fh.flush()
        raise OSError(28, "No space left on device")


def test_write_bvh_failure_mid_write_leaves_nothing(tmp_path, monkeypatch):
    real_fdopen = os.fdopen
    monkeypatch.setattr(atomic.os, "fdopen", lambda *a, **k: _FailingFile(real_fdopen(*a, **k)))
    target = tmp_path / "out.bvh"
    with pytest.raises(MotionFileError, match="No space left"):
        write_bvh(parse_bvh(VALID), target)
    assert list(tmp_path.iterdir()) == []


def test_write_bvh_failure_at_replace_keeps_old_file(tmp_path, monkeypatch):
    target = tmp_path / "out.bvh"
    target.write_text("old contents")

    def fail(src, dst):
        raise OSError(13, "Permission denied")

    monkeypatch.setattr(atomic.os, "replace", fail)
    with pytest.raises(MotionFileError, match="Permission denied"):
        write_bvh(parse_bvh(VALID), target)
    assert list(tmp_path.iterdir()) == [target]
    assert target.read_text() == "old contents"


def test_write_bvh_interrupted_by_other_exception_leaves_nothing(tmp_path, monkeypatch):
    def interrupt(src, dst):
        raise KeyboardInterrupt

    monkeypatch.setattr(atomic.os, "replace", interrupt)
    with pytest.raises(KeyboardInterrupt):
        write_bvh(parse_bvh(VALID), tmp_path / "out.bvh")
    assert list(tmp_path.iterdir()) == []


def test_write_bvh_formatter_failure_leaves_nothing(tmp_path, monkeypatch):
    import mocycle.io.bvh as bvh

    def boom(motion, names=None):  # fails after the first piece was written
        yield "HIERARCHY\n"
        raise RuntimeError("formatter failed")

    monkeypatch.setattr(bvh, "bvh_chunks", boom)
    with pytest.raises(RuntimeError):
        bvh.write_bvh(parse_bvh(VALID), tmp_path / "out.bvh")
    assert list(tmp_path.iterdir()) == []


def test_write_bvh_success_round_trips(tmp_path):
    from mocycle.io.bvh import one_word_names
    from mocycle.motion import EndSite, Skeleton

    m = parse_bvh(VALID)
    with pytest.warns(MocycleWarning, match="one word each"):  # "Left Leg": written as Left_Leg
        path = write_bvh(m, tmp_path / "out.bvh")
    assert [p.name for p in tmp_path.iterdir()] == ["out.bvh"]
    sk = m.skeleton
    joints, sites, _ = one_word_names(sk)
    written = Motion(Skeleton(tuple(joints), sk.parents, sk.offsets, sk.channels,
                              tuple(EndSite(e.parent, e.offset, n) for e, n in zip(sk.end_sites, sites, strict=True))),
                     m.rotations, m.translations, m.frame_time)
    assert_same_motion(parse_bvh(path.read_bytes()), written, exact=False)


def test_no_channels_round_trip():
    from mocycle.io.bvh import format_bvh
    from mocycle.motion import Motion, Skeleton

    still = Motion.rest(Skeleton(("a", "b"), [-1, 0], [[0, 0, 0], [0, 1, 0]], ((), ())), 4)
    back = parse_bvh(format_bvh(still), path="fuzz.bvh")
    assert back.n_frames == 4 and back.skeleton.n_channels == 0
