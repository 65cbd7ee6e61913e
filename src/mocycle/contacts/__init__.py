"""Feet that stay planted: foot joints of any rig, contact detection, foot locking, the skate measure."""

from .cycle import lock_cycle
from .detect import Contacts, detect_contacts, ranges
from .feet import Foot, body_height, find_feet, up_axis
from .lock import lock_feet
from .skate import largest_leg_step, skate

__all__ = ["Contacts", "Foot", "body_height", "detect_contacts", "find_feet", "largest_leg_step", "lock_cycle",
           "lock_feet", "ranges", "skate", "up_axis"]
