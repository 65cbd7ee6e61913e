"""Scale: a long take through every command, each in its own process: seconds, peak memory, growth.

    python benchmarks/scale.py                        # 10k and 100k frames (a few minutes)
    python benchmarks/scale.py --frames 10000,100000,1000000 --mem-gb 14 --timeout 900
    python benchmarks/scale.py --frames 1000000 --only swings,loop --keep /tmp/scale --markdown

The take is the synthetic walk (22 joints, 69 channels, 120 fps, 0.3 deg noise) generated in chunks of
100 cycles that follow on (phase, root travel and a fresh noise seed per chunk), so a take of any length
is written without holding it whole (``--keep DIR`` keeps it for the next run).  Every command then runs
in a fresh ``python -m mocycle`` process under a memory limit (``RLIMIT_AS``) and a wall-clock timeout;
the parent reads that process's own rusage from ``os.wait4``.  Printed per command and size: exit code,
wall seconds, CPU seconds (user + system: the figure to compare on a loaded machine), peak resident MB,
peak / channel array (``frames × channels × 8`` bytes, the float64 array the BVH holds) and, between
consecutive sizes, the growth exponents of CPU time and of peak memory (1 = linear).
"""

from __future__ import annotations

import argparse
import math
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
FPS = 120.0
CHUNK_CYCLES = 100  # one chunk = 100 walk cycles of 1 s


def write_take(path: Path, n_frames: int, noise_deg: float = 0.3) -> int:
    """Write an ``n_frames`` synthetic walk to ``path`` chunk by chunk; returns its channel count."""
    import numpy as np

    from mocycle.datasets import synthetic_walk
    from mocycle.io import write
    from mocycle.motion import Motion

    chunk = int(CHUNK_CYCLES * FPS)
    done, k, offset, channels = 0, 0, np.zeros(3), 0
    with tempfile.TemporaryDirectory() as tmp, open(path, "w") as out:
        while done < n_frames:
            n = min(chunk, n_frames - done)
            take = synthetic_walk(n_frames=chunk + 1, fps=FPS, noise_deg=noise_deg, seed=k,
                                  phase0=k * CHUNK_CYCLES).motion
            trans = take.translations.copy()
            trans[:, 0] += offset
            offset = trans[chunk, 0] * np.array([1.0, 0.0, 1.0])  # the next chunk starts where this one ends
            part = Motion(take.skeleton, take.rotations[:n], trans[:n], take.frame_time)
            write(part, Path(tmp) / "part.bvh")
            text = (Path(tmp) / "part.bvh").read_text()
            head, _, rows = text.partition("Frame Time:")
            rows = rows.split("\n", 1)[1]
            if k == 0:
                channels = sum(len(c) for c in take.skeleton.channels)
                out.write(head.replace(f"Frames: {n}", f"Frames: {n_frames}") + "Frame Time:"
                          + text.partition("Frame Time:")[2].split("\n", 1)[0] + "\n")
            out.write(rows if rows.endswith("\n") else rows + "\n")
            done += n
            k += 1
    return channels


def commands(folder: Path) -> list[tuple[str, list[str]]]:
    """``(name, argv)`` of every command on ``take.bvh`` in ``folder`` (in an order where outputs feed later ones)."""
    t, o = str(folder / "take.bvh"), folder / "out"
    return [
        ("info", ["info", t, "--json"]),
        ("convert", ["convert", t, str(o / "convert.bvh")]),
        ("convert .glb", ["convert", t, str(o / "convert.glb")]),
        ("phase", ["phase", t, "--json"]),
        ("loop", ["loop", t, "-o", str(o / "loop.bvh")]),
        ("blend", ["blend", t, t, "-o", str(o / "blend.bvh")]),
        ("transition", ["transition", t, t, "-o", str(o / "transition.bvh")]),
        ("stretch", ["stretch", t, "--factor", "1.5", "-o", str(o / "stretch.bvh")]),
        ("swings", ["swings", t, "-o", str(o / "take.mosw"), "--playback", str(o / "playback.bvh")]),
        ("swings .mosw", ["swings", str(o / "take.mosw"), "--playback", str(o / "playback2.bvh")]),
        ("edit", ["edit", t, "--joint", "LeftUpLeg", "--swing", "0", "--angle-scale", "1.2",
                  "-o", str(o / "edit.bvh")]),
        ("search", ["search", t, str(folder / "library")]),
        ("compress", ["compress", t, "-o", str(o / "take.mck")]),
        ("decompress", ["decompress", str(o / "take.mck"), "-o", str(o / "decompress.bvh")]),
        ("project", ["project", t, "--projection", "pca"]),
        ("report", ["report", t, "-o", str(o / "report.html")]),
    ]


def run(argv: list[str], mem_bytes: int, timeout: float) -> tuple[int, float, float, float, str]:
    """Run ``mocycle argv`` in a fresh process: exit code, seconds, CPU seconds, peak RSS (MB), last stderr line."""
    env = dict(os.environ, PYTHONPATH=f"{SRC}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")

    def limit() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))

    with tempfile.TemporaryFile() as err:
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-m", "mocycle", *argv], stdout=subprocess.DEVNULL, stderr=err,
                                env=env, preexec_fn=limit)
        while True:
            pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
            if pid:
                break
            if time.perf_counter() - t0 > timeout:
                proc.kill()
                pid, status, usage = os.wait4(proc.pid, 0)
                status = -9 << 8
                break
            time.sleep(0.05)
        secs = time.perf_counter() - t0
        proc.returncode = 0  # reaped here; keep Popen from waiting again
        err.seek(0)
        lines = [x for x in err.read().decode(errors="replace").splitlines() if x.strip()]
    code = os.waitstatus_to_exitcode(status) if status != -9 << 8 else -9
    last = "timeout" if code == -9 and secs > timeout else (lines[-1][:110] if lines else "")
    return code, secs, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024, last


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--frames", default="10000,100000", help="comma-separated take lengths")
    ap.add_argument("--only", default="", help="comma-separated command names (as printed) to run")
    ap.add_argument("--mem-gb", type=float, default=12.0, help="address-space limit per command, GiB")
    ap.add_argument("--timeout", type=float, default=900.0, help="seconds per command")
    ap.add_argument("--markdown", action="store_true", help="print the table as Markdown rows")
    ap.add_argument("--keep", type=Path, default=None, help="work in this folder and keep it")
    a = ap.parse_args()
    sizes = [int(float(x)) for x in a.frames.split(",") if x]
    only = {x.strip() for x in a.only.split(",") if x.strip()}
    results: dict[str, list] = {}
    print(f"# scale: {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; memory limit {a.mem_gb:g} GiB, "
          f"timeout {a.timeout:g} s per command", flush=True)
    for n in sizes:
        folder = Path(tempfile.mkdtemp(prefix="mocycle-scale-")) if a.keep is None else a.keep / f"n{n}"
        try:
            (folder / "out").mkdir(parents=True, exist_ok=True)
            (folder / "library").mkdir(exist_ok=True)
            t0 = time.perf_counter()
            marker = folder / f"take.{n}.channels"
            if a.keep is not None and marker.exists() and (folder / "take.bvh").exists():
                channels = int(marker.read_text())  # the kept take of this length
            else:
                channels = write_take(folder / "take.bvh", n)
                marker.write_text(str(channels))
            (folder / "library" / "take.bvh").unlink(missing_ok=True)
            os.symlink(folder / "take.bvh", folder / "library" / "take.bvh")
            array_mb = n * channels * 8 / 2**20
            file_mb = (folder / "take.bvh").stat().st_size / 2**20
            print(f"\n## {n:,} frames × {channels} channels: file {file_mb:,.0f} MB, channel array {array_mb:,.0f} MB"
                  f" (written in {time.perf_counter() - t0:.0f} s, load {os.getloadavg()[0]:.1f})", flush=True)
            print(f"{'command':14s} {'exit':>4s} {'s':>8s} {'cpu s':>8s} {'peak MB':>8s} {'/array':>7s}  note",
                  flush=True)
            for name, argv in commands(folder):
                if only and name not in only:
                    continue
                code, secs, cpu, peak, last = run(argv, int(a.mem_gb * 2**30), a.timeout)
                ratio = peak / array_mb
                results.setdefault(name, []).append((n, code, cpu, peak, ratio, secs))
                note = last if code else ""
                print(f"{name:14s} {code:4d} {secs:8.1f} {cpu:8.1f} {peak:8.0f} {ratio:7.2f}  {note}", flush=True)
        finally:
            if a.keep is None:
                shutil.rmtree(folder, ignore_errors=True)
    if len(sizes) > 1:
        print("\n## growth exponents between consecutive sizes (CPU time, peak memory; 1 = linear)")
        for name, rows in results.items():
            parts = []
            for (n0, _, s0, p0, *_), (n1, _, s1, p1, *_) in zip(rows, rows[1:], strict=False):
                e = math.log(n1 / n0)
                parts.append(f"{n0:,}→{n1:,}: {math.log(s1 / s0) / e:.2f}, {math.log(p1 / p0) / e:.2f}")
            print(f"{name:14s} " + "; ".join(parts))
    if a.markdown:
        print("\n| command | frames | exit | wall s | CPU s | peak MB | peak / channel array |\n"
              "|---|---|---|---|---|---|---|")
        for name, rows in results.items():
            for n, code, cpu, peak, ratio, secs in rows:
                print(f"| `{name}` | {n:,} | {code} | {secs:.0f} | {cpu:.0f} | {peak:,.0f} | {ratio:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
