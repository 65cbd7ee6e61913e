"""Strict JSON (json_text) and json.dumps' indented text at C speed (indented_json): the same bytes as before."""

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mocycle.text import indented_json, json_text, unicode_clean


def _json_text_before(facts, indent=2):
    """json_text as it was: a Python walk, then json.dumps (the pure-Python encoder when indenting)."""
    nulls = []

    def clean(x, where):
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
    return json.dumps(out, indent=indent, allow_nan=False)


SCALARS = (st.none() | st.booleans() | st.integers(-2**70, 2**70) | st.floats(allow_nan=True, allow_infinity=True)
           | st.text(alphabet=st.characters(codec=None, blacklist_categories=()), max_size=8)
           | st.sampled_from(["a\udcffb", "\ud800", "x, y", '"q"', "\n\t", "é€😀", "NaN", "Infinity"]))
KEYS = st.text(max_size=6) | st.sampled_from(["a\udcff", "null_because_not_finite"])
JSONISH = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=5) | st.tuples(inner, inner) | st.dictionaries(KEYS, inner, max_size=5)
    | st.dictionaries(st.integers(-5, 5) | st.booleans() | st.none(), inner, max_size=3),
    max_leaves=40,
)


@settings(max_examples=400, derandomize=True, deadline=None)
@given(obj=JSONISH, indent=st.sampled_from([0, 1, 2, 4, "\t", None]))
def test_indented_json_is_json_dumps(obj, indent):
    try:
        want = json.dumps(obj, indent=indent)
    except (TypeError, ValueError) as exc:
        with pytest.raises(type(exc)):
            indented_json(obj, indent)
        return
    assert indented_json(obj, indent) == want


@settings(max_examples=400, derandomize=True, deadline=None)
@given(obj=JSONISH, indent=st.sampled_from([1, 2, None]))
def test_json_text_is_what_it_was(obj, indent):
    try:
        want = _json_text_before(obj, indent)
    except (TypeError, ValueError) as exc:
        with pytest.raises(type(exc)):
            json_text(obj, indent)
        return
    got = json_text(obj, indent)
    assert got == want
    json.loads(got)  # strict JSON
    got.encode("utf-8")  # valid UTF-8: no lone surrogate


def test_numpy_values_non_finite_numbers_and_surrogates():
    facts = {"frames": np.int64(3), "period": np.float32(0.5), "curve": np.array([1.0, np.nan, 2.5]),
             "nested": {"x": [1.0, float("inf")], "names": ["ok", "bad\udcffname"], "plain": [1, 2.5, True]},
             "bad\udcffkey": -np.inf, "tuple": (1, 2), "empty": [], "e": {}}
    text = json_text(facts)
    assert text == _json_text_before(facts)
    assert json.loads(text)["null_because_not_finite"] == [
        "curve[1] (nan)", "nested.x[1] (inf)", "bad\\xffkey (-inf)"]


def test_circular_references_are_refused_like_json_dumps():
    a: list = [1]
    a.append([a])
    with pytest.raises(ValueError, match="Circular reference"):
        indented_json(a)


def test_subclasses_and_unknown_types_go_through_json_dumps():
    from collections import OrderedDict
    from enum import IntEnum

    class Level(IntEnum):
        LOW = 1

    obj = {"a": OrderedDict(b=[1, Level.LOW]), "c": [Level.LOW, 2.0], "d": {1: "x", 2.5: [None]}}
    assert indented_json(obj, 2) == json.dumps(obj, indent=2)
    with pytest.raises(TypeError):
        indented_json({"a": [{"b": object()}]}, 2)
