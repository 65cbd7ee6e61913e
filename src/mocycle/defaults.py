"""Defaults shared by the library and the task layer, in a module that imports nothing.

The command line builds its ``--help`` from the task options, whose defaults are these; keeping them here
lets it do so without loading numpy, scipy or scikit-learn (see ``docs/performance.md``).  The library
modules that own each default re-export it under the same name.
"""

#: Frame rate of AMC files, which do not store it (CMU: 120 fps); :mod:`mocycle.io.asfamc`.
AMC_FPS = 120.0
#: A periodic motion must wind at least this often over the take; :mod:`mocycle.phase.analysis`.
MIN_PERIODS = 1.2
#: Acceptable Swing Error of a swing segmentation (paper: 0.4); :mod:`mocycle.swings.segment`.
SWING_THRESHOLD = 0.4
