"""Feet that stay planted: foot joints of any rig, contact detection, foot locking, the skate measure.

Below :mod:`mocycle.cycle`, which imports it (loops locked across their seam: :func:`mocycle.cycle.lock_cycle`);
nothing here knows of cycles.
"""

from .detect import Contacts, detect_contacts, ranges
from .legs import Foot, body_height, find_feet, up_axis
from .lock import lock_feet
from .plant import floor_height, foot_points, plant_lowest_foot
from .skate import foot_jumps, largest_leg_step, skate

__all__ = ["Contacts", "Foot", "body_height", "detect_contacts", "find_feet", "floor_height", "foot_points",
           "foot_jumps", "largest_leg_step", "lock_feet", "plant_lowest_foot", "ranges", "skate", "up_axis"]
