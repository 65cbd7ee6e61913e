"""What the cut into parts costs, by the frames the cohomology looks at (``--step``).

    python benchmarks/cut_cost.py TAKE.bvh [--steps 1,auto]

For each step (``auto``: the default, :func:`mocycle.activities.phase_step` of the take's frame rate), in this
one process, one after the other: ``segment_activities(read(TAKE), step=...)`` under cProfile, and prints its
CPU seconds (profiled), the time in ``find_phase`` and in ``rips_h1`` (ripser's Rips filtration) with its calls,
the parts and the parts that loop.  The take is read once, before any step is timed.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import sys
import time
from pathlib import Path


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("take", type=Path)
    ap.add_argument("--steps", default="1,auto", help="steps to compare, e.g. 1,auto,2")
    args = ap.parse_args(argv)

    from mocycle.activities import phase_step, segment_activities
    from mocycle.io import read
    from mocycle.threads import limited

    motion = read(args.take)
    print(f"{args.take.name}: {motion.n_frames} frames at {motion.fps:g} fps, {motion.n_joints} joints; "
          f"auto step {phase_step(motion.fps)}")
    print(f"{'step':>6} {'cut CPU s':>10} {'find_phase':>10} {'rips_h1':>8} {'calls':>6} {'parts':>6} {'loop':>5}")
    with limited():
        for word in args.steps.split(","):
            step = None if word == "auto" else int(word)
            prof = cProfile.Profile()
            t0 = time.process_time()
            prof.enable()
            acts = segment_activities(motion, step=step)
            prof.disable()
            cpu = time.process_time() - t0
            stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
            rips = [v for k, v in stats.items() if k[2] == "rips_h1"]
            phase = sum(v[3] for k, v in stats.items() if k[2] == "find_phase")
            print(f"{word:>6} {cpu:10.2f} {phase:10.2f} {sum(v[3] for v in rips):8.2f} {sum(v[1] for v in rips):6d} "
                  f"{len(acts.parts):6d} {sum(p.loop for p in acts.parts):5d}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
