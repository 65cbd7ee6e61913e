"""Defaults shared by the library and the task layer, in a module that imports nothing.

The command line builds its ``--help`` from the task options, whose defaults are these; keeping them here
lets it do so without loading numpy, scipy or scikit-learn (see ``docs/performance.md``).  The library
modules that own each default re-export it under the same name.
"""

#: Frame rate of AMC files, which do not store it (CMU: 120 fps); :mod:`mocycle.io.asfamc`.
AMC_FPS = 120.0
#: A periodic motion must wind at least this often over the take; :mod:`mocycle.phase.analysis`.
MIN_PERIODS = 1.2
#: Harmonics K of the harmonic regression (the thesis' K); :mod:`mocycle.cycle.harmonic_fit` caps it by the
#: frames a take has ('auto').
HARMONICS = 20
#: Acceptable Swing Error of a swing segmentation (paper: 0.4); :mod:`mocycle.swings.segment`.
SWING_THRESHOLD = 0.4

# The names of the keyframe methods (thesis 002), one home: the algorithms (:mod:`mocycle.keyframes`), the
# ``.mck`` reader's checks (:mod:`mocycle.io.mck`) and the task options all read them from here.
#: keyframe selections; :mod:`mocycle.keyframes.select`.
KEY_SELECTIONS = ("uniform", "scs", "pb", "rols")
#: temporal reconstruction schemes; :mod:`mocycle.keyframes.temporal`.
TEMPORAL_SCHEMES = ("linear", "hermite", "slerp", "rbf")
#: every keyframe scheme: the temporal ones and the spatial one; :mod:`mocycle.keyframes.compress`.
KEY_SCHEMES = TEMPORAL_SCHEMES + ("spatial",)
#: one-step 2-D projections; :mod:`mocycle.keyframes.projection`.
ONE_STEP_PROJECTIONS = ("pca", "mds", "isomap", "lle", "force", "tsne")
#: two-step 2-D projections (their keyframes are placed by a one-step projection first).
TWO_STEP_PROJECTIONS = ("rbfp", "lamp")
PROJECTIONS = ONE_STEP_PROJECTIONS + TWO_STEP_PROJECTIONS

# The names of the cycle methods (paper 001 and the KTH thesis), one home: the algorithms (:mod:`mocycle.cycle`)
# and the task options read them from here.
#: how a cycle is extracted; :mod:`mocycle.cycle.extract`.
CYCLE_METHODS = ("harmonic", "centroid", "cut")
#: harmonic regression models; :mod:`mocycle.cycle.harmonic`.
HARMONIC_MODELS = ("M1", "M2", "M3")
#: a loop's root: walks on the spot (facing kept) or moves on; :mod:`mocycle.cycle.result`.
ROOT_MODES = ("inplace", "motion")
#: phase to time; :mod:`mocycle.cycle.timeaxis`.
TIME_AXES = ("smooth", "rank", "gmm", "line")
#: what a task that writes motion does with the feet (lock them on the floor, keep them as made, or lock when
#: the root moves and feet are found); :mod:`mocycle.tasks.feet_option`.
FEET_MODES = ("auto", "lock", "keep")
