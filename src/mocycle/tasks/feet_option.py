"""Foot locking as the tasks that write motion use it (``feet``, ``foot_joints`` options; :mod:`mocycle.contacts`)."""

from __future__ import annotations

import time
import warnings

from ..defaults import FEET_MODES
from ..errors import MocycleError, MocycleWarning

__all__ = ["FEET_HELP", "FEET_MODES", "FOOT_JOINTS_HELP", "clean_feet", "lock_motion", "travels"]
FEET_HELP = ("lock (feet held still on the floor during each contact; in place they slide back at the treadmill "
             "speed), keep (as fitted) or auto (lock with --root motion when feet are found, else keep).")
FOOT_JOINTS_HELP = ("Name the feet when the name patterns fail: ANKLE[:TOE],ANKLE[:TOE] (e.g. "
                    "lfoot:ltoes,rfoot:rtoes).")


def clean_feet(cycle, mode: str, root: str, foot_joints: str | None, reference=None, before=None,
               skate_before: float | None = None):
    """The cycle with its feet locked (or not), and what the JSON says about it.  ``reference``: the take (or
    takes) the cycle was made from, whose swing clearance the locked feet keep.  ``before``: the cycle
    repeated twice with its root motion, and ``skate_before`` its skate on the same feet, when the caller has
    measured them (``loop_metrics`` does: its ``skate``)."""
    from ..contacts import find_feet, largest_leg_step
    from ..cycle.foot_lock import lock_cycle

    if mode == "auto":
        try:
            find_feet(cycle.space.skeleton, foot_joints)
            mode = "lock" if root == "motion" else "keep"
        except MocycleError as exc:
            if root == "motion":
                warnings.warn(f"feet not locked: {exc}", MocycleWarning, stacklevel=2)
            mode = "keep"
    facts: dict[str, object] = {"mode": mode, "contacts": None, "skate_before": None, "skate_after": None,
             "largest_leg_step_before": None, "largest_leg_step_after": None, "clearance": None, "seconds": 0.0}
    if mode == "keep":
        return cycle, facts, None
    t0 = time.perf_counter()
    cleaned, contacts = lock_cycle(cycle, foot_joints, reference=reference)
    facts["seconds"] = time.perf_counter() - t0
    facts["clearance"] = _clearance_facts(contacts, contacts.clearance, cycle.space.skeleton.names)
    before = cycle.repeat(2, root="motion") if before is None else before
    after = cleaned.repeat(2, root="motion")
    names = cycle.space.skeleton.names
    facts.update(contacts=contacts.to_dict(names, cycle.n_frames),
                 skate_before=_skate(before, contacts) if skate_before is None else float(skate_before),
                 skate_after=_skate(after, contacts),
                 largest_leg_step_before=largest_leg_step(before, contacts.feet),
                 largest_leg_step_after=largest_leg_step(after, contacts.feet))
    return cleaned, facts, contacts


def _skate(motion, contacts) -> float:
    """The skate measure of ``motion`` on the feet and vertical of ``contacts``, from the forward kinematics of
    the legs alone (its body height from some 50 frames of the whole body, as ``loop_metrics`` measures it)."""
    from ..contacts import body_height, skate
    from ..contacts.legs import chain_joints, chain_positions

    joints = [j for f in contacts.feet for j in f.contact_joints]
    W = chain_positions(motion, chain_joints(motion, joints))
    return skate(motion, contacts.feet, up=contacts.up, positions=W, body=body_height(motion, contacts.up))


def _clearance_facts(contacts, clearance, names) -> dict:
    """Joint name -> swing clearance (fraction of the body height) for the JSON."""
    return {names[j]: round(float(c), 6) for j, c in zip(contacts.joints, clearance, strict=True)}


def travels(motion) -> bool:
    """True when the take moves on: its travel joint goes farther than half the body height horizontally."""
    import numpy as np

    from ..contacts import body_height, up_axis

    up = up_axis(motion)
    path = motion.world_positions()[:, motion.travel_joint]
    step = path[-1] - path[0]
    return bool(np.linalg.norm(step - (step @ up) * up) > 0.5 * body_height(motion, up))


def lock_motion(motion, mode: str, foot_joints: str | None, moves: bool, hand_over: bool = False):
    """Any motion with its feet locked (``mode`` lock, or auto when ``moves`` and feet are found) and what the
    JSON says about it: a thin wrapper over :func:`mocycle.contacts.detect_contacts` and ``lock_feet``
    (``hand_over``: the caller gives ``motion`` up to the locked one, which is made from its arrays; emptied
    when the feet are locked)."""
    from ..contacts import detect_contacts, find_feet, largest_leg_step, lock_feet
    from ..contacts.clearance import swing_clearance

    if mode == "auto":
        try:
            find_feet(motion.skeleton, foot_joints)
            mode = "lock" if moves else "keep"
        except MocycleError as exc:
            if moves:
                warnings.warn(f"feet not locked: {exc}", MocycleWarning, stacklevel=2)
            mode = "keep"
    facts: dict[str, object] = {"mode": mode, "contacts": None, "skate_before": None, "skate_after": None,
             "largest_leg_step_before": None, "largest_leg_step_after": None, "clearance": None, "seconds": 0.0}
    if mode == "keep":
        return motion, facts
    t0 = time.perf_counter()
    contacts = detect_contacts(motion, foot_joints)
    clearance = swing_clearance(motion, contacts.feet, up=contacts.up, body=contacts.body)
    seconds = time.perf_counter() - t0
    names = motion.skeleton.names
    facts.update(skate_before=_skate(motion, contacts), largest_leg_step_before=largest_leg_step(motion, contacts.feet))
    t0 = time.perf_counter()
    locked = lock_feet(motion, contacts, clearance=clearance, hand_over=hand_over)
    facts["seconds"] = seconds + time.perf_counter() - t0
    facts["clearance"] = _clearance_facts(contacts, clearance, names)
    facts.update(contacts=contacts.to_dict(names), skate_after=_skate(locked, contacts),
                 largest_leg_step_after=largest_leg_step(locked, contacts.feet))
    return locked, facts
