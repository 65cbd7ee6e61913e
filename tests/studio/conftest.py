"""Takes for the studio tests: small generated motions written as BVH files (no shared data needed)."""

from __future__ import annotations

import pytest

from mocycle import write
from mocycle.datasets import synthetic_nonperiodic, synthetic_walk


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    folder = tmp_path_factory.mktemp("takes")
    write(synthetic_walk(n_frames=240).motion, folder / "walk.bvh")
    write(synthetic_nonperiodic(n_frames=240).motion, folder / "wander.bvh")
    return folder
