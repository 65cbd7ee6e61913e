"""Hostile input through the command line: bombs, deep and wide skeletons, absurd numbers, options and paths.

    python benchmarks/hostile.py [--markdown]

Builds each hostile file in a temporary folder, runs the ``mocycle`` command on it in a fresh process and
prints the exit code, the first line of the error, the seconds and the peak memory of that process, and
whether a partial or temporary file was left.  ``--markdown`` prints the rows for ``docs/reliability.md``.
"""

from __future__ import annotations

import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
RUN = """
import atexit, resource, sys
atexit.register(lambda: print(f"@@peak_mb {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f}",
                              file=sys.stderr))
sys.argv = ["mocycle"] + sys.argv[1:]
from mocycle.cli import main
main()
"""


def build(folder: Path) -> None:
    """The hostile files."""
    import numpy as np

    from mocycle.datasets import synthetic_walk
    from mocycle.io import write
    from mocycle.io.bvh import skeleton_text
    from mocycle.io.mck import MAGIC as MCK
    from mocycle.io.mosw import MAGIC as MOSW
    from mocycle.keyframes import compress
    from mocycle.motion import Skeleton

    walk = synthetic_walk(n_frames=300, fps=60, seed=1).motion
    write(walk, folder / "walk.bvh")
    one = Skeleton(("a",), [-1], [[0, 0, 0]], [("Zrotation", "Xrotation", "Yrotation")])
    # BVH: a claimed frame count with no channels
    (folder / "frames1e9.bvh").write_text("HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\nCHANNELS 0\nEnd Site\n{\nOFFSET 0 1 0\n"
                                          "}\n}\nMOTION\nFrames: 1000000000\nFrame Time: 0.01\n")
    # BVH: a 1000-deep chain and a 30,000-joint star
    n = 1000
    chain = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    for i in range(1, n):
        chain += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    chain += ["End Site", "{", "OFFSET 0 1 0", "}"] + ["}"] * n
    chain += ["MOTION", "Frames: 2", "Frame Time: 0.01"] + [" ".join(["1"] * (3 * n))] * 2
    (folder / "deep1000.bvh").write_text("\n".join(chain) + "\n")
    w = 30000
    star = ["HIERARCHY", "ROOT j0", "{", "OFFSET 0 0 0", "CHANNELS 3 Zrotation Xrotation Yrotation"]
    for i in range(1, w):
        star += [f"JOINT j{i}", "{", "OFFSET 0 1 0", "CHANNELS 3 Zrotation Xrotation Yrotation", "End Site", "{",
                 "OFFSET 0 1 0", "}", "}"]
    star += ["}", "MOTION", "Frames: 2", "Frame Time: 0.01"] + [" ".join(["1"] * (3 * w))] * 2
    (folder / "wide30k.bvh").write_text("\n".join(star) + "\n")
    # BVH: coordinates near 1e308, a denormal frame time
    text = (folder / "walk.bvh").read_text()
    head, rows = text.split("Frame Time:")
    lines = rows.split("\n")
    lines[1] = " ".join(["1e306"] + lines[1].split()[1:])
    (folder / "huge.bvh").write_text(head + "Frame Time:" + "\n".join(lines))
    (folder / "denormal.bvh").write_text(head + "Frame Time: 5e-324\n" + "\n".join(lines[1:]))
    # ASF/AMC: a chain of 2000 bones
    asf = [":units", "  angle deg", ":root", "   order TX TY TZ RX RY RZ", "   axis XYZ", "   position 0 0 0",
           "   orientation 0 0 0", ":bonedata"]
    for i in range(2000):
        asf += ["  begin", f"     name b{i}", "     direction 0 1 0", "     length 1", "     dof rx", "  end"]
    asf += [":hierarchy", "  begin", "    root b0", *(f"    b{i} b{i + 1}" for i in range(1999)), "  end"]
    (folder / "chain.asf").write_text("\n".join(asf) + "\n")
    (folder / "chain.amc").write_text("1\nroot 0 0 0 0 0 0\n" + "".join(f"b{i} 1\n" for i in range(2000)))
    # .mck: a header that claims 1e9 frames; a zlib bomb (a true header, then 1 GiB of zeros)
    packed = compress(walk, count=9)
    payload = zlib.decompress(packed.to_bytes()[len(MCK):])
    (k,) = struct.unpack("<I", payload[:4])
    header = json.loads(payload[4:4 + k])
    header["n_frames"] = 10**9
    for entry in header["arrays"]:
        if entry[0] == "track":
            entry[2][0] = 10**9
    text = json.dumps(header).encode()
    (folder / "frames1e9.mck").write_bytes(MCK + zlib.compress(struct.pack("<I", len(text)) + text + payload[4 + k:]))
    z = zlib.compressobj(9)
    parts = [MCK, z.compress(payload)]
    zeros = bytes(1 << 24)
    parts += [z.compress(zeros) for _ in range(64)]
    (folder / "zbomb.mck").write_bytes(b"".join(parts) + z.flush())
    # .mosw: 4e9 frames; a swing count of 1e9 followed by 1 GiB of zeros
    sk = skeleton_text(one).encode()
    body = struct.pack("<I", len(sk)) + sk + struct.pack("<Idff", 4_000_000_000, 0.01, 0.4, 0.16)
    (folder / "frames4e9.mosw").write_bytes(MOSW + zlib.compress(body + struct.pack("<I", 0) * 20))
    body = struct.pack("<I", len(sk)) + sk + struct.pack("<Idff", 1000, 0.01, 0.4, 0.16) + struct.pack("<II", 0, 10**9)
    z = zlib.compressobj(9)
    parts = [MOSW, z.compress(body)] + [z.compress(zeros) for _ in range(64)]
    (folder / "zbomb.mosw").write_bytes(b"".join(parts) + z.flush())
    np.save(folder / "unused.npy", np.zeros(1))


CASES = [
    # (family, command line; {d} is the folder)
    ("BVH `Frames: 1e9`, no channels (114 B)", "info {d}/frames1e9.bvh"),
    ("BVH 1000-deep hierarchy", "convert {d}/deep1000.bvh {d}/out/deep.bvh"),
    ("BVH 30,000 joints", "convert {d}/wide30k.bvh {d}/out/wide.bvh"),
    ("BVH coordinate 1e306", "loop {d}/huge.bvh -o {d}/out/l.bvh"),
    ("BVH frame time 5e-324", "info {d}/denormal.bvh --json"),
    ("ASF/AMC chain of 2000 bones", "convert {d}/chain.asf {d}/chain.amc {d}/out/chain.bvh"),
    (".mck header claims 1e9 frames", "decompress {d}/frames1e9.mck -o {d}/out/x.bvh"),
    (".mck zlib bomb (1 GiB of zeros)", "decompress {d}/zbomb.mck -o {d}/out/x.bvh"),
    (".mosw claims 4e9 frames", "swings {d}/frames4e9.mosw"),
    (".mosw count 1e9 + zlib bomb", "swings {d}/zbomb.mosw"),
    ("`convert --fps 1e9`", "convert {d}/walk.bvh {d}/out/c.bvh --fps 1e9"),
    ("`convert --fps 9e5`", "convert {d}/walk.bvh {d}/out/c.bvh --fps 9e5"),
    ("`loop --cycles 100000`", "loop {d}/walk.bvh -o {d}/out/l.bvh --cycles 100000"),
    ("`stretch --factor 1e6`", "stretch {d}/walk.bvh --factor 1e6 -o {d}/out/s.bvh"),
    ("`search --window inf`", "search {d}/walk.bvh {d} --window inf"),
    ("`demo --seed -1`", "demo --seed -1 --out {d}/out/demo"),
    ("`-o` in a missing folder", "loop {d}/walk.bvh -o {d}/missing/l.bvh"),
    ("`swings -o` in a missing folder", "swings {d}/walk.bvh -o {d}/missing/s.mosw"),
    ("`-o` equal to the input", "convert {d}/walk.bvh {d}/walk.bvh"),
]


def run(folder: Path, command: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    before = {p for p in folder.rglob("*")}
    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", RUN, *command.format(d=folder).split()], capture_output=True,
                          text=True, env=env, timeout=900)
    seconds = time.perf_counter() - t0
    peak = next((ln.split()[1] for ln in proc.stderr.splitlines() if ln.startswith("@@peak_mb")), "?")
    lines = [ln for ln in proc.stderr.splitlines() if ln and not ln.startswith("@@")]
    out = " ".join(proc.stdout.split())
    first = next((ln for ln in lines if ln.startswith("error")), lines[0] if lines else out[-160:])
    left = [p.name for p in set(folder.rglob("*")) - before if p.name.endswith(".tmp")]
    return {"code": proc.returncode, "message": first.replace(str(folder) + "/", "").strip(), "seconds": seconds,
            "peak_mb": peak, "traceback": "Traceback" in proc.stderr, "tmp_left": left}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="mocycle-hostile-") as tmp:
        folder = Path(tmp)
        (folder / "out").mkdir()
        build(folder)
        bad = False
        for family, command in CASES:
            r = run(folder, command)
            bad |= r["traceback"] or bool(r["tmp_left"])
            if args.markdown:
                print(f"| {family} | `mocycle {command.replace('{d}/', '').replace('{d}', '.')}` | {r['code']} | "
                      f"{r['message'][:150].replace('|', '/')} | {r['seconds']:.1f} | {r['peak_mb']} |")
            else:
                flags = (", TRACEBACK" if r["traceback"] else "") + (f", left {r['tmp_left']}" if r["tmp_left"] else "")
                print(f"{family}: exit {r['code']}, {r['seconds']:.1f} s, peak {r['peak_mb']} MB{flags}"
                      f"\n    {r['message'][:200]}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
