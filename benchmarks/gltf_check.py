"""glTF output over every shared take: the Khronos validator's verdict and three.js against mocycle's FK.

    python benchmarks/gltf_check.py [--data DIR] [--loops] [--times N]

For each .bvh and .amc file under ../shared/data: write it as .glb (``mocycle.write``), run
``tests/js/check_glb.mjs`` (``make js`` installs it), and compare the world positions three.js plays at N
times spread over the take with ``Motion.world_positions()`` (relative to the body's size).  ``--loops`` also
runs ``mocycle loop --root motion -o X.glb`` on each take and checks its clip (closing frame included).
Prints one row per file and the worst figures.  Not a test: the tests do the same on a few takes.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DEFAULT_DATA = ROOT.parent / "shared" / "data"
SCRIPT = ROOT / "tests" / "js" / "check_glb.mjs"


def check(path: Path, motion, frames) -> tuple[dict, float]:
    """The validator's issue counts and the largest FK distance / body size at ``frames``."""
    from mocycle.io.gltf import gltf_frame

    times = [k * motion.frame_time for k in frames]
    out = subprocess.run(["node", str(SCRIPT), str(path), *map(repr, times)], capture_output=True, text=True,
                         check=True)
    report = json.loads(out.stdout)
    frame = gltf_frame(motion)
    fk = frame.point(motion.world_positions(end_sites=True))
    worst = max(float(np.abs(np.array([p[str(i)] for i in range(fk.shape[1])]) - fk[k]).max())
                for p, k in zip(report["positions"], frames, strict=True))
    return report, worst / (frame.body_size * frame.scale)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    parser.add_argument("--loops", action="store_true", help="also loop each take (root motion) to .glb")
    parser.add_argument("--times", type=int, default=6, help="times compared per file")
    args = parser.parse_args()
    if not (SCRIPT.parent / "node_modules").is_dir():
        print(f"{SCRIPT.parent}/node_modules is missing: run `make js` first", file=sys.stderr)
        return 2
    import mocycle
    from mocycle.errors import MocycleError
    from mocycle.io.gltf import gltf_frame
    from mocycle.tasks import loop
    from mocycle.tasks.clips import closed_loop

    files = sorted(args.data.glob("*/*.bvh")) + sorted(args.data.glob("*/*.amc"))
    rows, worst, issues = [], 0.0, 0
    with tempfile.TemporaryDirectory() as tmp:
        for f in files:
            motion = mocycle.read(f)
            out = Path(tmp) / f"{f.stem}.glb"
            t0 = time.perf_counter()
            mocycle.write(motion, out)
            seconds = time.perf_counter() - t0
            frames = np.linspace(0, motion.n_frames - 1, args.times).round().astype(int).tolist()
            report, error = check(out, motion, frames)
            v = report["validator"]
            issues += v["numErrors"] + v["numWarnings"]
            worst = max(worst, error)
            frame = gltf_frame(motion)
            row = (f"{f.parent.name + '/' + f.name:<48} {motion.n_joints:>3} joints {motion.n_frames:>5} frames "
                   f"{frame.unit:>3} {out.stat().st_size / 1e3:8.0f} kB {seconds:5.2f} s  validator "
                   f"{v['numErrors']}/{v['numWarnings']}/{v['numInfos']}/{v['numHints']}  FK {error:.1e}")
            if args.loops:
                try:
                    rep = loop.run(f, loop.Options(root="motion"))
                    closed = closed_loop(rep.result, 1, "motion")
                    lout = mocycle.write(closed, Path(tmp) / f"{f.stem}_loop.glb", clip=f"{f.stem}_loop")
                    n = closed.n_frames
                    lreport, lerror = check(lout, closed, [0, n // 2, n - 1])
                    lv = lreport["validator"]
                    issues += lv["numErrors"] + lv["numWarnings"]
                    worst = max(worst, lerror)
                    row += (f"  | loop {n - 1}+1 frames, validator {lv['numErrors']}/{lv['numWarnings']}, "
                            f"FK {lerror:.1e}")
                except MocycleError as exc:
                    row += f"  | loop: {type(exc).__name__}"
            print(row, flush=True)
            rows.append(row)
    print(f"{len(rows)} files; validator errors + warnings: {issues}; largest FK error / body size: {worst:.2e}")
    return 0 if issues == 0 and worst <= 1e-4 else 1


if __name__ == "__main__":
    sys.exit(main())
