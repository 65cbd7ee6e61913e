"""Hostile input through the command line: bombs, deep and wide skeletons, absurd numbers, options and paths.

    python benchmarks/hostile.py [--markdown] [--cap-gb 3] [--only TEXT]

Builds each hostile file in a temporary folder, runs the ``mocycle`` command on it in a fresh process (under an
address-space limit of ``--cap-gb``, except ``batch``) and prints the exit code, the first line of the error,
the seconds and the peak memory of that process, and whether a partial or temporary file was left.
``--markdown`` prints the rows for ``docs/reliability.md``.
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
    files_that_lie(folder, walk)


def files_that_lie(folder: Path, walk) -> None:
    """glTF and FBX files that lie (issue 36), in ``scene/`` with a secret in ``secret/`` beside it, and a batch
    library ``lib/`` (a good take, a 235-letter name, a FIFO buffer, a deflate bomb)."""
    from mocycle.datasets.fbx_files import bomb_scene, chain_scene, fbx_bytes, write_fbx
    from mocycle.datasets.gltf_files import chain_document, gltf_file
    from mocycle.io import write

    scene, secret = folder / "scene", folder / "secret"
    scene.mkdir()
    secret.mkdir()
    (secret / "token.txt").write_text("TOKEN-5f1e2d3c4b5a\n" * 60)
    doc, blob = chain_document(3)
    for name, uri in (("outside", "../secret/token.txt"), ("passwd", "/etc/passwd"), ("zero", "/dev/zero")):
        d = json.loads(json.dumps(doc))
        d["buffers"][0]["byteLength"] = 10_000
        gltf_file(scene / f"{name}.gltf", d, blob, uri=uri)
    gltf_file(scene / "piped.gltf", doc, blob, uri="pipe.bin")
    (scene / "pipe.bin").unlink()
    os.mkfifo(scene / "pipe.bin")
    os.mkfifo(scene / "fifo.gltf")
    gltf_file(scene / "chain10k.gltf", *chain_document(10_000))
    gltf_file(scene / "same20k.gltf", *chain_document(20_000, names=["joint"] * 20_000))
    gltf_file(scene / "anims10k.gltf", *chain_document(3, n_animations=10_000, animation_names=["walk"] * 10_000))
    typed, _ = chain_document(3)
    typed["accessors"][1]["type"] = []
    gltf_file(scene / "typed.gltf", typed, blob)
    gltf_file(scene / "odd.gltf", *chain_document(4, names=["\ud800", "{", "}", "end"]))
    for joints in (3, 60):
        d, b = chain_document(joints, times=(0.0, 1_999_999 / 30))
        d["animations"][0]["channels"] += [{"sampler": 0, "target": {"node": k, "path": "rotation"}}
                                           for k in range(1, joints)]
        gltf_file(scene / f"frames2m_{joints}.gltf", d, b)
    write_fbx(scene / "chain10k.fbx", chain_scene(10_000))
    write_fbx(scene / "bomb.fbx", bomb_scene())
    with open(os.fsencode(scene) + b"/bad\xffname.fbx", "wb") as fh:
        fh.write(fbx_bytes(chain_scene(3)))
    write(walk, folder / "walk<!--<script>.bvh")
    lib = folder / "lib"
    lib.mkdir()
    write(walk, lib / "good.bvh")
    write(walk, lib / ("w" * 235 + ".bvh"))
    gltf_file(lib / "piped.gltf", doc, blob, uri="pipe.bin")
    (lib / "pipe.bin").unlink()
    os.mkfifo(lib / "pipe.bin")
    write_fbx(lib / "bomb.fbx", bomb_scene())


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
    ("glTF buffer `uri: ../secret/token.txt`", "convert {d}/scene/outside.gltf {d}/out/x.bvh"),
    ("glTF buffer `uri: /etc/passwd`", "info {d}/scene/passwd.gltf"),
    ("glTF buffer `uri: /dev/zero`", "info {d}/scene/zero.gltf"),
    ("glTF buffer a FIFO beside it", "info {d}/scene/piped.gltf"),
    ("glTF file a FIFO", "info {d}/scene/fifo.gltf"),
    ("glTF chain of 10,000 nodes (767 KB)", "convert {d}/scene/chain10k.gltf {d}/out/chain.bvh"),
    ("glTF 20,000 nodes of one name", "info {d}/scene/same20k.gltf"),
    ("glTF 10,000 animations of one name", "info {d}/scene/anims10k.gltf --take walk.9999"),
    ("glTF `accessors[1].type: []`", "info {d}/scene/typed.gltf"),
    ("glTF nodes `\\ud800`, `{`, `}`", "convert {d}/scene/odd.gltf {d}/out/odd.bvh"),
    ("glTF 2 keys 2,000,000 frames apart, 3 nodes", "info {d}/scene/frames2m_3.gltf"),
    ("glTF 2 keys 2,000,000 frames apart, 60 nodes", "info {d}/scene/frames2m_60.gltf"),
    ("FBX chain of 10,000 bones (4.3 MB)", "convert {d}/scene/chain10k.fbx {d}/out/fchain.bvh"),
    ("FBX deflate bomb: 300M zero doubles (2.3 MB)", "info {d}/scene/bomb.fbx"),
    ("FBX file name not UTF-8", "info {d}/scene/bad\udcffname.fbx"),
    ("take named `walk<!--<script>.bvh`", "report {d}/walk<!--<script>.bvh -o {d}/out/r.html"),
    ("`batch --json`, refused", "batch loop {d}/walk.bvh -o {d}/walk.bvh --json"),
    ("batch: good, 235-letter name, FIFO buffer, bomb", "batch loop {d}/lib -o {d}/out/lib --workers 2"),
]


def run(folder: Path, command: str, cap_gb: float = 0) -> dict:
    env = {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    before = {p for p in folder.rglob("*")}

    def cap():  # the address space of the command (not of a batch: its dask workers map more)
        import resource

        if cap_gb and not command.startswith("batch"):
            resource.setrlimit(resource.RLIMIT_AS, (int(cap_gb * 2**30), resource.RLIM_INFINITY))

    t0 = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", RUN, *command.format(d=folder).split()], capture_output=True,
                          text=True, env=env, timeout=900, preexec_fn=cap)
    seconds = time.perf_counter() - t0
    peak = next((ln.split()[1] for ln in proc.stderr.splitlines() if ln.startswith("@@peak_mb")), "?")
    lines = [ln for ln in proc.stderr.splitlines() if ln and not ln.startswith("@@")]
    out = " ".join(proc.stdout.split())
    said = [" ".join(ln.split()) for ln in proc.stdout.splitlines() if ln.strip()]
    summary = next((ln for ln in said if "takes:" in ln or ln.startswith("wrote")), " / ".join(said[:2]))
    first = next((ln for ln in lines if ln.startswith(("error", "warning"))), summary or (lines[0] if lines else out))
    left = [p.name for p in set(folder.rglob("*")) - before if p.name.endswith(".tmp")]
    return {"code": proc.returncode, "message": first.replace(str(folder) + "/", "").strip(), "seconds": seconds,
            "peak_mb": peak, "traceback": "Traceback" in proc.stderr, "tmp_left": left}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--markdown", action="store_true")
    parser.add_argument("--cap-gb", type=float, default=3.0, help="address-space limit of each command (0: none)")
    parser.add_argument("--only", help="run the cases whose family contains this text")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory(prefix="mocycle-hostile-") as tmp:
        folder = Path(tmp)
        (folder / "out").mkdir()
        build(folder)
        bad = False
        for family, command in CASES:
            if args.only and args.only not in family:
                continue
            r = run(folder, command, args.cap_gb)
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
