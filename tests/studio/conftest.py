"""Takes for the studio tests: small generated motions written as BVH files (no shared data needed)."""

from __future__ import annotations

import os

import pytest

from mocycle import write
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    folder = tmp_path_factory.mktemp("takes")
    write(synthetic_walk(n_frames=240).motion, folder / "walk.bvh")
    write(synthetic_nonperiodic(n_frames=240).motion, folder / "wander.bvh")
    return folder


@pytest.fixture(scope="module")
def hostile(tmp_path_factory):
    """walk.bvh, a link to /etc/passwd, a non-UTF-8 name, a file that is not BVH, an HTML-looking name."""
    folder = tmp_path_factory.mktemp("hostile")
    write(synthetic_walk(n_frames=240).motion, folder / "walk.bvh")
    os.symlink("/etc/passwd", folder / "passwd.bvh")
    write(synthetic_walk(n_frames=120, seed=2).motion, os.fsdecode(os.fsencode(str(folder)) + b"/bad\xffname.bvh"))
    (folder / "notbvh.bvh").write_text("root:x:0:0:this is not a BVH file\n")
    write(synthetic_walk(n_frames=120, seed=3).motion, folder / '<img src=x onerror="window.__pwned=1">.bvh')
    return folder
