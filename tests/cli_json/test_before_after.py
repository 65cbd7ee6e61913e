"""Every ``mocycle`` command prints, with ``--json``, the figures it printed before issue 12's task layer.

``before.json`` was made by ``make_before.py`` from the commit in ``before.commit``: first 6e2c70a (the code before
the task layer), then, after merging branches that change figures on purpose (issue 11's loop checks, root motion on
arcs, stretch of periodic regions), from the ``main`` commit merged last; timing fields are left out, numbers are
compared with a tolerance (other numpy versions, other BLAS; a compressed size within 0.1 %: the last bits of the
Euler conversion, changed in 6e69423, move it by a few bytes). A command may print keys it did not print before
(e.g. ``swings``' ``swing_indices``); every key it printed must be there with the same value.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cli_json.cases import CASES, run_all

BEFORE = json.loads((Path(__file__).parent / "before.json").read_text())


def _diff(a, b, where: str) -> list[str]:
    if isinstance(a, dict) and isinstance(b, dict):
        out = [f"{where}: keys {sorted(set(a) - set(b))} are gone"] if set(a) - set(b) else []
        for k in set(a) & set(b):
            out += _diff(a[k], b[k], f"{where}.{k}")
        return out
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return [f"{where}: length {len(a)} != {len(b)}"]
        return [d for k, (x, y) in enumerate(zip(a, b, strict=True)) for d in _diff(x, y, f"{where}[{k}]")]
    if isinstance(a, bool) or isinstance(b, bool) or not isinstance(a, int | float) or not isinstance(b, int | float):
        return [] if a == b else [f"{where}: {a!r} != {b!r}"]
    # a compressed size moves by a few bytes when a float's last bit does (the text's digits change)
    rel = 1e-3 if where.endswith("compressed_bytes") else 1e-5
    return [] if math.isclose(a, b, rel_tol=rel, abs_tol=1e-6) else [f"{where}: {a!r} != {b!r}"]


@pytest.fixture(scope="module")
def after(tmp_path_factory):
    return run_all(tmp_path_factory.mktemp("cli_json"))


def test_the_fixture_covers_every_case():
    assert set(BEFORE) == set(CASES)


@pytest.mark.parametrize("name", sorted(CASES))
def test_same_json_as_before(after, name):
    diffs = _diff(BEFORE[name], after[name], name)
    assert not diffs, "\n".join(diffs[:20])


def test_the_comparison_can_fail():
    assert _diff({"a": [1.0, 2.0]}, {"a": [1.0, 2.001]}, "x") == ["x.a[1]: 2.0 != 2.001"]
    assert _diff({"a": 1}, {"b": 1}, "x") and not _diff({"a": 1}, {"a": 1, "b": 2}, "x")
    assert not _diff({"compressed_bytes": 10661}, {"compressed_bytes": 10665}, "x")
    assert _diff({"compressed_bytes": 10661}, {"compressed_bytes": 10700}, "x")
