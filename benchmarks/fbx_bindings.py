"""The Python bindings of ufbx on PyPI side by side: ``ufbx`` (by ufbx's author), ``pyufbx`` (also imported as
``ufbx``) and ``pufbx``.

    python benchmarks/fbx_bindings.py FILE.fbx [--mutations 300] [--seed 0] [--wheels]

Two of them install the same module name, so each is measured in a Python that has it (a venv per binding;
``pip install ufbx``, ``pip install pyufbx``, ``pip install pufbx``): the script reports the one it finds.
For it: the distribution (version, licence in its metadata, the top-level packages it puts into
site-packages), what it offers for skeletal animation, the scene settings it exposes (frame rate, unit,
up axis), the load (and bake) time of FILE (median of 5), and a short fuzz: ``--mutations`` mutated copies of
FILE (bit flips, interesting values, cuts, repeats), each loaded in a child process twice: the binding used
plainly (load, the nodes and takes as lists, bake the first take, its first node's keys, then the
garbage collector) and, for ``ufbx``, through mocycle's reader (``read_fbx``); children that die on a
signal (a crash in C; 139 is a segmentation fault) or hang (10 s) are counted; for ``ufbx``, three plain uses
that read a scene element again after dropping it (``PROBES``), each in a child.  ``--wheels`` asks pip which
wheels each binding has on PyPI for CPython 3.11 and 3.13 on Linux, macOS and Windows (``pip download
--only-binary``, nothing installed).  ``docs/formats.md`` has the figures.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import json
import random
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

BINDINGS = {"ufbx": "ufbx", "pyufbx": "ufbx", "pufbx": "pufbx"}  # distribution -> module
PLATFORMS = {"linux-x64": "manylinux2014_x86_64", "linux-arm64": "manylinux2014_aarch64",
             "macos-arm64": "macosx_11_0_arm64", "macos-x64": "macosx_10_13_x86_64", "windows-x64": "win_amd64"}
PYTHONS = ("3.11", "3.13")

PLAIN = r"""
import gc, sys
path, dist = sys.argv[1], sys.argv[2]
try:
    if dist == "pufbx":
        import pufbx
        s = pufbx.load_fbx(path)
        nodes, stacks = list(s.nodes), list(s.anim_stacks)
        if stacks:
            b = pufbx.bake_anim(s, stacks[0].anim)
            keys = [b.modified_nodes[k].rotation_keys for k in range(min(2, len(b.modified_nodes)))]
    else:
        import ufbx
        s = ufbx.load_file(path)
        nodes, stacks = list(s.nodes), list(s.anim_stacks)
        if stacks and hasattr(ufbx, "bake_anim"):
            b = ufbx.bake_anim(s, stacks[0].anim)
            keys = [list(b.nodes[k].rotation_keys) for k in range(min(2, len(b.nodes)))]
    names = [n.name for n in nodes]
    del nodes, stacks
    gc.collect()
    print("ok")
except Exception as exc:
    print("error", type(exc).__name__)
"""

#: ufbx's own API used plainly in ways that read an element a second time after dropping it (the crash the
#: issue met: "exit 139 in GC after list(bake.nodes[1].rotation_keys)"): each run on FILE in a child
PROBES = {
    "a node dropped, then read again": "n = s.nodes[3]; del n; s.nodes[3].name",
    "node names listed, then a node read": "names = [n.name for n in s.nodes]; s.nodes[1].name",
    "a take baked and its keys listed, then the take read again":
        "st = s.anim_stacks[0]; b = ufbx.bake_anim(s, st.anim); k = list(b.nodes[1].rotation_keys); del st; "
        "gc.collect(); s.anim_stacks[0].name",
}

MOCYCLE = r"""
import gc, sys, warnings
warnings.simplefilter("ignore")
from mocycle.errors import MotionFileError
from mocycle.io.fbx import read_fbx
gc.set_threshold(1, 1, 1)
try:
    read_fbx(sys.argv[1])
    print("ok")
except MotionFileError as exc:
    print("error", type(exc).__name__)
gc.collect()
"""


def installed() -> tuple[str, str] | None:
    """(distribution, module) of the binding this Python has, or ``None``."""
    for dist, module in BINDINGS.items():
        try:
            importlib.metadata.distribution(dist)
        except importlib.metadata.PackageNotFoundError:
            continue
        return dist, module
    return None


def distribution_facts(dist: str) -> dict:
    """Version, licence metadata and the top-level names the distribution installs into site-packages."""
    d = importlib.metadata.distribution(dist)
    meta = d.metadata
    tops = sorted({Path(f).parts[0] for f in (d.files or []) if not Path(f).parts[0].endswith(
        (".dist-info", ".data")) and Path(f).parts[0] not in ("..", "bin")})
    tops = sorted({t[:-3] if t.endswith(".py") else t for t in tops})
    licence = meta.get("License-Expression") or meta.get("License") or ", ".join(
        c for c in meta.get_all("Classifier") or [] if c.startswith("License")) or None
    return {"version": d.version, "licence_in_metadata": licence, "top_level_installed": tops}


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


def run_child(script: str, path: Path, dist: str) -> tuple[str, int]:
    try:
        proc = subprocess.run([sys.executable, "-c", script, str(path), dist], capture_output=True, text=True,
                              timeout=10)
    except subprocess.TimeoutExpired:
        return "hang", 0
    out = proc.stdout.strip()
    if proc.returncode != 0 or not out:
        return "crash", proc.returncode
    return ("ok" if out == "ok" else "error"), 0


def fuzz(dist: str, data: bytes, n: int, seed: int, scripts: dict[str, str]) -> dict:
    """The original file, then ``n`` mutations, through each script; crashing inputs are kept."""
    rng = random.Random(seed)
    folder = Path(tempfile.mkdtemp(prefix=f"fbx-{dist}-"))
    counts = {name: {"ok": 0, "error": 0, "crash": 0, "hang": 0, "exit_codes": {}} for name in scripts}
    for k in range(n + 1):
        path = folder / "m.fbx"
        path.write_bytes(data if k == 0 else mutate(data, rng))
        for name, script in scripts.items():
            what, code = run_child(script, path, dist)
            row = counts[name]
            row[what] += 1
            if what == "crash":
                row["exit_codes"][str(code)] = row["exit_codes"].get(str(code), 0) + 1
                (folder / f"{name}-crash{k}.fbx").write_bytes(path.read_bytes())
            if k == 0:
                row["original_file"] = what
    for row in counts.values():
        row["kept_in"] = str(folder)
    return counts


def wheels() -> dict:
    """``{distribution: {python: {platform: wheel file or None}}}`` on PyPI (pip download, no install)."""
    out: dict = {}
    for dist in BINDINGS:
        out[dist] = {}
        for py in PYTHONS:
            out[dist][py] = {}
            for platform, tag in PLATFORMS.items():
                with tempfile.TemporaryDirectory() as folder:
                    done = subprocess.run([sys.executable, "-m", "pip", "download", "--quiet", "--no-deps",
                                           "--only-binary=:all:", "--python-version", py, "--platform", tag,
                                           "-d", folder, dist], capture_output=True, text=True)
                    files = [p.name for p in Path(folder).glob("*.whl")]
                out[dist][py][platform] = files[0] if done.returncode == 0 and files else None
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", type=Path)
    ap.add_argument("--mutations", type=int, default=300)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--wheels", action="store_true", help="ask PyPI which wheels each binding has")
    args = ap.parse_args(argv)
    data = args.file.read_bytes()
    report: dict = {"python": sys.version.split()[0]}
    found = installed()
    if found is None:
        report["installed"] = None
    else:
        dist, module = found
        mod = __import__(module)
        row = {"distribution": dist, **distribution_facts(dist)}
        row["bakes_animation"] = hasattr(mod, "bake_anim")
        times = []
        for _ in range(5):
            t = time.perf_counter()
            scene = mod.load_fbx(str(args.file)) if module == "pufbx" else mod.load_file(str(args.file))
            if row["bakes_animation"]:
                stack = scene.anim_stacks[0]
                mod.bake_anim(scene, stack.anim)
            times.append(time.perf_counter() - t)
            if module == "ufbx" and row["bakes_animation"]:
                del stack
                scene.free()  # ufbx 0.0.5: freed at once, not by the collector (see mocycle/io/fbx.py)
            del scene
        row["load_and_bake_s" if row["bakes_animation"] else "load_s"] = round(statistics.median(times), 4)
        try:
            scene = mod.load_fbx(str(args.file)) if module == "pufbx" else mod.load_file(str(args.file))
            settings = scene.settings
            row["frame_rate"] = settings.frames_per_second
            row["unit_metres"] = settings.unit_meters
            row["up_axis"] = getattr(settings.axes.up, "name", str(settings.axes.up))
        except (NotImplementedError, AttributeError) as exc:
            row["settings"] = f"{type(exc).__name__}: {exc}"
        scripts = {"plain": PLAIN}
        if dist == "ufbx":
            scripts["mocycle"] = MOCYCLE
            row["plain_use_probes"] = {}
            for label, code in PROBES.items():
                done = subprocess.run([sys.executable, "-c", f"import gc, ufbx\ns = ufbx.load_file({str(args.file)!r})"
                                       f"\n{code}\nprint('ok')"], capture_output=True, text=True, timeout=60)
                row["plain_use_probes"][label] = "ok" if done.returncode == 0 else f"exit {done.returncode}"
        row["fuzz"] = fuzz(dist, data, args.mutations, args.seed, scripts)
        report["installed"] = row
    if args.wheels:
        report["wheels"] = wheels()
    print(json.dumps(report, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
