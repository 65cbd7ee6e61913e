"""Frame rows parsed by polars a chunk at a time (``mocycle[fast]``): the same motion, warning or error as the
careful parse, for every layout; plain rows take the fast path, anything else the usual one."""

import threading
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from helpers import random_motion
from mocycle.errors import MotionFileError
from mocycle.io import bvh, bvh_rows
from mocycle.io.bvh import format_bvh, motion_channels, read_bvh

pytest.importorskip("polars", reason="the fast BVH row parser needs polars (pip install 'mocycle[fast]')")


@pytest.fixture
def fast(monkeypatch):
    """Polars for any size, in pieces of about 2 kB (many chunks, a helper thread); records each fast read's
    outcome (True: read by polars, False: handed to the usual parse)."""
    monkeypatch.setattr(bvh_rows, "MIN_BYTES", 0)
    monkeypatch.setattr(bvh_rows, "MIN_BYTES_IMPORTED", 0)
    monkeypatch.setattr(bvh_rows, "CHUNK_BYTES", 2048)
    outcomes = []
    read_chunks = bvh._read_chunks

    def spy(*args):
        result = read_chunks(*args)
        outcomes.append(result is not None)
        return result

    monkeypatch.setattr(bvh, "_read_chunks", spy)
    return outcomes


def _take(n=300, seed=0):
    """A take's header and rows (9 significant digits, single spaces) with sign flips and a late-moving joint."""
    m = random_motion(n, seed=seed, spin=True)
    values = motion_channels(m)
    values[:, 3] += np.where(np.arange(n) % 37 == 5, 360.0, 0.0)
    head = format_bvh(m).split("Frame Time:")[0] + f"Frame Time: {m.frame_time!r}\n"
    rows = [" ".join(f"{v:.9g}" for v in row) for row in values]
    return head, rows


def _outcome(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            m = read_bvh(path)
        except MotionFileError as exc:
            return ("error", str(exc)), [str(w.message) for w in caught]
    arrays = (m.rotations.tobytes(), m.translations_at(0).tobytes(),
              [(j, m.joint_translations(j).tobytes()) for j in m.tracked_joints])
    return ("motion", arrays), [str(w.message) for w in caught]


def _same_as_careful(path, monkeypatch):
    """read_bvh with polars gives what it gives without polars (np.loadtxt, then the careful parse); the
    fixture records both reads."""
    got = _outcome(path)
    with monkeypatch.context() as m:
        m.setattr(bvh_rows, "wanted", lambda n: False)
        want = _outcome(path)
    assert got[0][0] == want[0][0], (got[0], want[0])
    assert got == want
    return got


def _write(tmp_path, head, rows, eol="\n", end="\n"):
    path = tmp_path / "take.bvh"
    path.write_bytes((head.replace("\n", eol) + eol.join(rows) + end).encode("utf-8"))
    return path


PLAIN = {
    "single spaces": lambda rows: rows,
    "a space closing every row": lambda rows: [r + " " for r in rows],
    "a space closing every row but the last": lambda rows: [r + " " for r in rows[:-1]] + rows[-1:],
}


@pytest.mark.parametrize("layout", PLAIN)
@pytest.mark.parametrize("eol", ["\n", "\r\n"])
@pytest.mark.parametrize("end", ["\n", "", "\n\n  \n"])
def test_plain_rows_take_the_fast_path_to_the_same_motion(tmp_path, monkeypatch, fast, layout, eol, end):
    head, rows = _take()
    path = _write(tmp_path, head, PLAIN[layout](rows), eol, end.replace("\n", eol))
    kind, _ = _same_as_careful(path, monkeypatch)[0]
    assert kind == "motion" and fast[0] is True


def _edit(rows, k, text):
    rows = list(rows)
    rows[k] = text
    return rows


OTHER = {
    "tabs": lambda rows: [r.replace(" ", "\t") for r in rows],
    "runs of spaces": lambda rows: [r.replace(" ", "  ") for r in rows],
    "leading spaces": lambda rows: ["  " + r for r in rows],
    "a blank line inside": lambda rows: rows[:150] + [""] + rows[150:],
    "spaces then tabs": lambda rows: [r + " \t" for r in rows],
    "a byte-order mark on a row": lambda rows: _edit(rows, 170, "\ufeff" + rows[170]),
    "a value missing": lambda rows: _edit(rows, 200, rows[200].rsplit(" ", 1)[0]),
    "a value too many": lambda rows: _edit(rows, 200, rows[200] + " 1.5"),
    "a value too many after a closing space": lambda rows: [r + " " for r in rows[:200]] + [rows[200] + " 2"],
    "nan": lambda rows: _edit(rows, 120, rows[120].replace(" ", " nan ", 1)),
    "inf": lambda rows: _edit(rows, 120, "inf " + rows[120].split(" ", 1)[1]),
    "1e31": lambda rows: _edit(rows, 220, "1e31 " + rows[220].split(" ", 1)[1]),
    "a quoted number": lambda rows: _edit(rows, 90, '"1.5" ' + rows[90].split(" ", 1)[1]),
    "a word": lambda rows: _edit(rows, 90, "x " + rows[90].split(" ", 1)[1]),
    "a comma": lambda rows: _edit(rows, 90, "1,5 " + rows[90].split(" ", 1)[1]),
    "a non-ASCII digit": lambda rows: _edit(rows, 90, "\u0661 " + rows[90].split(" ", 1)[1]),
    "digit separators": lambda rows: _edit(rows, 90, "1_000 " + rows[90].split(" ", 1)[1]),
    "a NUL": lambda rows: _edit(rows, 90, rows[90] + "\x00"),
    "a CR alone": lambda rows: _edit(rows, 90, rows[90].replace(" ", "\r", 1)),
    "a letter": lambda rows: _edit(rows, 90, rows[90] + "\xe9"),
}


@pytest.mark.parametrize("layout", OTHER)
def test_other_layouts_and_damage_give_what_the_careful_parse_gives(tmp_path, monkeypatch, fast, layout):
    head, rows = _take()
    path = _write(tmp_path, head, OTHER[layout](rows))
    _same_as_careful(path, monkeypatch)
    assert fast[0] is False


@pytest.mark.parametrize("claimed", [1, 299, 301, 10_000, 10**9])
def test_a_frames_count_that_disagrees_warns_and_the_rows_win(tmp_path, monkeypatch, fast, claimed):
    head, rows = _take()
    path = _write(tmp_path, head.replace("Frames: 300", f"Frames: {claimed}"), rows)
    (kind, _), caught = _same_as_careful(path, monkeypatch)
    assert kind == "motion" and any(f"'Frames: {claimed}' but 300 frame rows" in w for w in caught)
    assert fast[0] is (claimed == 301)  # fewer rows than claimed: the arrays are trimmed


def test_the_frames_count_is_allocated_only_within_the_frame_budget(tmp_path, monkeypatch, fast):
    head, rows = _take()
    path = _write(tmp_path, head, rows)
    monkeypatch.setenv("MOCYCLE_MAX_FRAMES", "299")  # the rows are there: read the usual way, as before
    kind, _ = _same_as_careful(path, monkeypatch)[0]
    assert kind == "motion" and fast[0] is False


def test_the_helper_thread_ends_with_the_read(tmp_path, monkeypatch, fast):
    head, rows = _take(2000)
    path = _write(tmp_path, head, rows)
    before = threading.active_count()
    read_bvh(path)
    assert fast == [True] and threading.active_count() == before
    path = _write(tmp_path, head, _edit(rows, 1500, "x " + rows[1500].split(" ", 1)[1]))  # refused part-way
    with pytest.raises(MotionFileError, match=r"take\.bvh:\d+: expected a finite number"):
        read_bvh(path)
    assert threading.active_count() == before


@pytest.mark.parametrize("total", [1, 5 << 20, (16 << 20) + 3, 531 << 20])
def test_pieces_grow_from_a_small_first_one_and_shrink_towards_the_end(total):
    sizes, left = [], total
    while left:
        sizes.append(bvh_rows.piece_bytes(len(sizes), left))
        left -= sizes[-1]
    small = bvh_rows.CHUNK_BYTES * bvh_rows.SMALL_SHARE
    assert sum(sizes) == total and min(sizes) > 0 and max(sizes) < bvh_rows.CHUNK_BYTES + small
    assert sizes[0] <= max(small, total - small)  # the first parse starts after a small read
    if len(sizes) > 2:
        assert sizes[-1] < 2 * small  # the last pieces' conversions are short
        peak = sizes.index(max(sizes))
        assert sizes[:peak + 1] == sorted(sizes[:peak + 1])
        assert sizes[peak:-1] == sorted(sizes[peak:-1], reverse=True)


def test_a_long_file_reads_fast_only_when_polars_is_worth_importing(monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "polars", __import__("polars"))
    assert bvh_rows.wanted(bvh_rows.MIN_BYTES_IMPORTED) and not bvh_rows.wanted(bvh_rows.MIN_BYTES_IMPORTED - 1)


TOKENS = ["1", "-0", "0.5", "+2.5", ".5", "5.", "1e3", "1E-3", "-1.5e+2", "1e400", "1e-400", "nan", "inf", "-inf",
          "NaN", "x", '"1"', "1,5", "1_0", "0x1", "١", "1d3", "", " ", "\t", "1e", "--1", "+", "null", "NA", "TRUE"]


@settings(max_examples=60, derandomize=True, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(edits=st.lists(st.tuples(st.integers(0, 299), st.integers(0, 10), st.sampled_from(TOKENS)), max_size=4),
       sep=st.sampled_from([" ", "  ", "\t"]), closing=st.sampled_from(["", " "]))
def test_fuzzed_rows_give_what_the_careful_parse_gives(tmp_path, monkeypatch, fast, edits, sep, closing):
    head, rows = _take()
    rows = [r.split(" ") for r in rows]
    for k, col, token in edits:
        rows[k][col] = token
    path = _write(tmp_path, head, [sep.join(r) + closing for r in rows])
    _same_as_careful(path, monkeypatch)
