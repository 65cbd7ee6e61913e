"""Plot of foot contacts: each contact joint's height and horizontal speed, its contacts shaded."""

from __future__ import annotations

import os

import numpy as np

from .figure import save, subplots


def plot_contacts(motion, contacts, path: str | os.PathLike, title: str = "", before=None) -> None:
    """One row per contact joint of ``contacts`` over the frames of ``motion``: height above its floor (the
    detector's local floor) and horizontal speed (file units, units/s), the contact frames shaded;
    ``before``: the motion before clean-up, drawn dashed."""
    from ..contacts.detect import heights_and_speeds, local_floor

    def above_floor(h):
        return h - contacts.body * local_floor(h / contacts.body, motion.fps)

    names = motion.skeleton.names
    C = len(contacts.joints)
    fig, axes = subplots(C, 1, figsize=(10, 1.8 * C + 0.6), sharex=True, squeeze=False)
    frames = np.arange(motion.n_frames)
    h, v, _ = heights_and_speeds(motion, contacts.joints, contacts.up)
    h = above_floor(h)
    hb = vb = None
    if before is not None:
        hb, vb, _ = heights_and_speeds(before, contacts.joints, contacts.up)
        hb = above_floor(hb)
    for c, ax in enumerate(axes[:, 0]):
        for s, e in contacts.joint_ranges(c):
            ax.axvspan(s - 0.5, e - 0.5, color="tab:green", alpha=0.2, lw=0)
        ax.plot(frames, h[:, c], color="tab:blue", lw=1.2, label="height")
        ax2 = ax.twinx()
        ax2.plot(frames, v[:, c], color="tab:red", lw=1.0, label="speed")
        if hb is not None and vb is not None:
            ax.plot(frames, hb[:, c], color="tab:blue", lw=0.8, ls="--")
            ax2.plot(frames, vb[:, c], color="tab:red", lw=0.8, ls="--")
        ax.set_ylabel(f"{names[contacts.joints[c]]}\nheight", fontsize=8)
        ax2.set_ylabel("speed /s", fontsize=8, color="tab:red")
    axes[-1, 0].set_xlabel("frame (green: contact; dashed: before clean-up)")
    if title:
        axes[0, 0].set_title(title)
    save(fig, path)
