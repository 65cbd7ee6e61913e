"""The two PyPI bindings of ufbx side by side: ``pyufbx`` (imported as ``ufbx``) and ``pufbx``.

    python benchmarks/fbx_bindings.py FILE.fbx [--mutations 300] [--seed 0]

For each binding: what it offers for baked skeletal animation, the scene settings it exposes (frame rate,
unit), the load time of FILE (median of 5), and a short fuzz: ``--mutations`` mutated copies of FILE (bit flips,
interesting values, cuts, repeats) loaded in a child process (and, for pufbx, baked), counting the children that
die on a signal (a crash in C) or hang (10 s).  ``docs/formats.md`` has the figures.
"""

from __future__ import annotations

import argparse
import json
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CHILD = r"""
import sys
path, binding = sys.argv[1], sys.argv[2]
try:
    if binding == "pufbx":
        import pufbx
        s = pufbx.load_fbx(path)
        for stack in list(s.anim_stacks)[:1]:
            pufbx.bake_anim(s, stack.anim)
        names = [n.name for n in s.nodes]
    else:
        import ufbx
        s = ufbx.load_file(path)
        names = [n.name for n in s.nodes]
    print("ok")
except Exception as exc:
    print("error", type(exc).__name__)
"""


def mutate(data: bytes, rng: random.Random) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        pos = rng.randrange(len(out) + 1)
        op = rng.choice(("flip", "value", "cut", "dup"))
        if op == "flip" and pos < len(out):
            out[pos] ^= 1 << rng.randrange(8)
        elif op == "value":
            chunk = rng.choice([b"\xff\xff\xff\x7f", b"\x00\x00\x00\x00", b"\xff\xff\xff\xff", b"\x00\x00\x80\x7f"])
            out[pos:pos + len(chunk)] = chunk
        elif op == "cut" and rng.random() < 0.2:
            del out[pos:]
        elif op == "dup":
            out[pos:pos] = out[pos:pos + rng.randint(1, 256)]
    return bytes(out)


def fuzz(binding: str, data: bytes, n: int, seed: int) -> dict:
    rng = random.Random(seed)
    folder = Path(tempfile.mkdtemp(prefix=f"fbx-{binding}-"))
    counts = {"ok": 0, "error": 0, "crash": 0, "hang": 0}
    for k in range(n):
        path = folder / "m.fbx"
        path.write_bytes(mutate(data, rng))
        try:
            proc = subprocess.run([sys.executable, "-c", CHILD, str(path), binding], capture_output=True, text=True,
                                  timeout=10)
        except subprocess.TimeoutExpired:
            counts["hang"] += 1
            path.rename(folder / f"hang{k}.fbx")
            continue
        if proc.returncode < 0 or proc.returncode > 1 or not proc.stdout.strip():
            counts["crash"] += 1
            path.rename(folder / f"crash{k}.fbx")
        else:
            counts["ok" if proc.stdout.strip() == "ok" else "error"] += 1
    counts["kept_in"] = str(folder)
    return counts


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", type=Path)
    ap.add_argument("--mutations", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    data = args.file.read_bytes()
    rows = {}
    for binding, module in (("pyufbx", "ufbx"), ("pufbx", "pufbx")):
        try:
            mod = __import__(module)
        except ImportError:
            rows[binding] = {"installed": False}
            continue
        row = {"installed": True, "version": getattr(mod, "__version__", "?")}
        times = []
        for _ in range(5):
            t = time.perf_counter()
            scene = mod.load_fbx(str(args.file)) if module == "pufbx" else mod.load_file(str(args.file))
            if module == "pufbx":
                mod.bake_anim(scene, scene.anim_stacks[0].anim)
            times.append(time.perf_counter() - t)
        row["load_s" if module == "ufbx" else "load_and_bake_s"] = round(statistics.median(times), 4)
        row["bakes_animation"] = hasattr(mod, "bake_anim")
        row["evaluates_animation"] = any(hasattr(mod, a) for a in ("evaluate_scene", "bake_anim", "evaluate_curve"))
        try:
            settings = scene.settings
            row["frame_rate"] = settings.frames_per_second
            row["unit_metres"] = settings.unit_meters
        except (NotImplementedError, AttributeError) as exc:
            row["settings"] = f"{type(exc).__name__}: {exc}"
        row["fuzz"] = fuzz(binding, data, args.mutations, args.seed)
        rows[binding] = row
    print(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
