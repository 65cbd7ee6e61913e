"""Option fields shared by ``compress`` and ``project`` (keyframes, thesis 002)."""

from __future__ import annotations

from ..defaults import KEY_SELECTIONS as SELECT_CHOICES
from ..defaults import ONE_STEP_PROJECTIONS as SEED_CHOICES
from ..defaults import PROJECTIONS as PROJECTION_CHOICES
from .options import Choice, Flag, Real, option


def ratio(help: str = "Keyframes as a fraction of the frames (thesis: 0.03)."):
    return option(0.03, help, Real(0, 1, low_open=True))


def select():
    return option("uniform", "Keyframe selection: uniform, scs (curve simplification), pb (position based) or rols.",
                  Choice(SELECT_CHOICES))


def projection():
    return option("mds", "2-D projection of the spatial scheme: pca, mds, isomap, lle, force, tsne, rbfp or lamp.",
                  Choice(PROJECTION_CHOICES))


def seed_projection():
    return option("mds", "First-step projection of rbfp and lamp (the keyframes' 2-D places): pca, mds, isomap, "
                         "lle, force or tsne.", Choice(SEED_CHOICES))


def optimize(help: str = "Optimise the 2-D trajectory (Algorithm 12)."):
    return option(False, help, Flag())
