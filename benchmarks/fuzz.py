"""Long fuzzing run of every reader, to run before releases (the suite's fuzz tests are the short version).

    python benchmarks/fuzz.py [--seconds 3600] [--readers bvh,asf,amc,mck,mosw,json,glb,gltf,fbx,fbxs]
                              [--engine auto|atheris|random]
                              [--rss-mb 2048] [--timeout 10] [--max-frames 100000] [--out DIR] [--data DIR]
    python benchmarks/fuzz.py --replay DIR/json-oom-... [...]    # saved inputs, each in a fresh process

Each reader runs in its own process under a memory limit (``RLIMIT_AS`` of ``--rss-mb``) and a time limit
per input (``--timeout`` seconds).  A reader passes an input when it returns a result that goes on working
(``.mck`` decompresses, ``.mosw`` and swings JSON play back, BVH/ASF/AMC write as BVH and read back, glTF and FBX
give a finite motion) or raises one
:class:`~mocycle.errors.MotionFileError`; anything else is a crash, a run past the time limit a hang, a
``MemoryError`` a blow-up.

Engines: ``atheris`` (coverage-guided libFuzzer; ``pip install atheris``, a wheel exists for CPython 3.11 on
x86-64 Linux; the binary formats are mutated inside their zlib payload by a custom mutator) or ``random``
(mutations of the seeds, no coverage feedback); ``auto`` takes atheris when it imports.  Seeds are generated
takes and, when ``../shared/data`` is present, a few real files.  The glTF reader (``glb``) is seeded with GLBs
mocycle writes; the FBX reader (``fbx``) with binary (7.4, 7.5) and ASCII files written by
:mod:`mocycle.datasets.fbx_files` and the ``.fbx`` files under ``$MOCYCLE_FUZZ_FBX`` (a folder; e.g. the ones
Blender exports in ``tests_blender/test_formats_in.py``, or ``benchmarks/fbx_seeds.py`` run in the bpy
environment).  ``gltf`` and ``fbxs`` are the same readers fed structure-aware mutations (``fuzz_scenes.py``:
types, counts, uris, names, node chains, deflate bombs), the glTF read in a folder with a FIFO, a link out and
a secret beside it, any open outside the folder counted as a crash (``ReadOutside``).  All read from a file
(their readers take paths), written anew for each input.  ufbx is C: a crash there kills the child, reported as
``child died``.

Prints per reader: inputs tried, accepted, refused, crashes (by signature), hangs, blow-ups and peak memory
(an input libFuzzer's RSS watchdog blames is tried again alone in a fresh process: a blow-up only if it fails
there too, else counted under "fuzzer over its memory", the atheris process's own growth);
crashing inputs are kept in ``--out``.  Exit code 1 when any reader crashed, hung or blew up.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import resource
import signal
import subprocess
import sys
import tempfile
import time
import traceback
import zlib
from pathlib import Path

from mocycle.datasets.asfamc_text import TINY_AMC, TINY_ASF

READERS = ("bvh", "asf", "amc", "mck", "mosw", "json", "glb", "gltf", "fbx", "fbxs")
DEFAULT_DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"

ASF, AMC = TINY_ASF, TINY_AMC

class Hang(Exception):
    pass


# ---------------------------------------------------------------- targets (run in the child)
def _targets():
    """``{reader: (run(data), seeds, zlib magic or None)}``; run raises MotionFileError for refused input."""
    import warnings

    import numpy as np

    from mocycle.datasets import synthetic_walk
    from mocycle.io.asfamc import parse_amc, parse_asf
    from mocycle.io.bvh import format_bvh, parse_bvh
    from mocycle.io.mck import MAGIC as MCK
    from mocycle.io.mosw import MAGIC as MOSW
    from mocycle.io.swings_json import parse_swings_json, swings_document
    from mocycle.keyframes import Compressed, compress
    from mocycle.swings import decode, encode, playback, segment

    warnings.simplefilter("ignore")
    walk = synthetic_walk(n_frames=90, fps=30, seed=5).motion
    skeleton = parse_asf(ASF, "seed.asf")

    def finite(motion):
        assert np.all(np.isfinite(motion.rotations)) and np.all(np.isfinite(motion.translations))

    def bvh(data):
        m = parse_bvh(data, "fuzz.bvh")
        finite(parse_bvh(format_bvh(m), "again.bvh"))

    def asf(data):
        a = parse_asf(data.decode("utf-8", "replace"), "fuzz.asf")
        parse_bvh(format_bvh(parse_amc("1\nroot 0 0 0 0 0 0\n", a, "rest.amc")), "again.bvh")

    def amc(data):
        finite(parse_bvh(format_bvh(parse_amc(data.decode("utf-8", "replace"), skeleton, "fuzz.amc")), "again"))

    def mck(data):
        finite(Compressed.from_bytes(data, "fuzz.mck").decompress())

    def mosw(data):
        finite(playback(decode(data, "fuzz.mosw")))

    def swings_json(data):
        finite(playback(parse_swings_json(data, "fuzz.json")))

    bvh_seeds = [format_bvh(walk).encode(), format_bvh(walk[:3]).encode()]
    mck_seeds = [compress(walk, count=5, scheme=s).to_bytes() for s in ("slerp", "hermite", "rbf")]
    mck_seeds.append(compress(walk, count=5, scheme="spatial", projection="pca").to_bytes())
    data = Path(os.environ.get("MOCYCLE_FUZZ_DATA", DEFAULT_DATA))
    real_bvh = sorted(data.glob("*/*.bvh"), key=lambda p: p.stat().st_size)[:2] if data.is_dir() else []
    bvh_seeds += [p.read_bytes() for p in real_bvh]
    scratch = Path(tempfile.mkdtemp(prefix="mocycle-fuzz-files-"))

    def from_file(suffix, read):
        def run(data):
            path = scratch / f"fuzz{suffix}"
            path.write_bytes(data)
            finite(read(path))
        return run

    def glb_reader(path):
        from mocycle.io.gltf_read import read_gltf

        return read_gltf(path)

    def fbx_reader(path):
        from mocycle.io.fbx import read_fbx

        return read_fbx(path)

    glb_seeds = []
    for k, m in enumerate((walk[:30], walk[:3])):
        from mocycle.io.gltf import write_gltf

        glb_seeds.append(write_gltf(m, scratch / f"seed{k}.glb").read_bytes())
    from fuzz_scenes import join_gltf, mutate_fbx, mutate_gltf, reads_guarded, sandbox

    from mocycle.datasets.fbx_files import chain_scene, fbx_bytes
    from mocycle.datasets.gltf_files import chain_document, gltf_file

    # FBX: files written here (binary 7.4 and 7.5, ASCII), and any under $MOCYCLE_FUZZ_FBX (Blender's)
    fbx_binary = [fbx_bytes(chain_scene(4)), fbx_bytes(chain_scene(6, frames=61), version=7500)]
    fbx_dir = os.environ.get("MOCYCLE_FUZZ_FBX")
    fbx_seeds = fbx_binary + [fbx_bytes(chain_scene(4), binary=False)]
    if fbx_dir and Path(fbx_dir).is_dir():
        found = sorted(Path(fbx_dir).glob("**/*.fbx"), key=lambda p: p.stat().st_size)
        fbx_seeds += [p.read_bytes() for p in found[:4]]
    # glTF, structured: read in a folder with its buffer, a FIFO, a link out and a sub-folder; no open outside
    doc, blob = chain_document(4, times=np.arange(31) / 30)
    take_dir = sandbox(scratch / "gltf", blob)
    with_uri = json.loads(json.dumps(doc))
    with_uri["buffers"][0]["uri"] = "good.bin"
    gltf_seeds = [join_gltf(with_uri, b"", False), gltf_file(scratch / "chain.glb", doc, blob).read_bytes(),
                  gltf_file(scratch / "chain.gltf", doc, blob).read_bytes(), glb_seeds[0]]

    def gltf(data):
        path = take_dir / ("fuzz.glb" if data[:4] == b"glTF" else "fuzz.gltf")
        path.write_bytes(data)
        with reads_guarded(scratch / "gltf"):
            finite(glb_reader(path))

    return {"bvh": (bvh, bvh_seeds, None), "asf": (asf, [ASF.encode()], None), "amc": (amc, [AMC.encode()], None),
            "mck": (mck, mck_seeds, MCK), "mosw": (mosw, [encode(segment(walk))], MOSW),
            "json": (swings_json, [json.dumps(swings_document(segment(walk[:40]))).encode()], None),
            "glb": (from_file(".glb", glb_reader), glb_seeds, None),
            "gltf": (gltf, gltf_seeds, None, mutate_gltf),
            "fbx": (from_file(".fbx", fbx_reader), fbx_seeds, None),
            "fbxs": (from_file(".fbx", fbx_reader), fbx_binary, None, mutate_fbx)}


INTERESTING = [b"\x00", b"\xff", b"\x7f", b"\x80", b"\x00\x00\x00\x00", b"\xff\xff\xff\xff", b"\x00\xca\x9a\x3b",
               b"\x00\x00\x80\x7f", b"\x00\x00\xc0\x7f", b"\xff\xff\xff\x7f", b"nan", b"inf", b"1e308", b"-1",
               b"\n", b"{", b"}", b"99999999999"]


def mutate_bytes(data: bytes, rng: random.Random) -> bytes:
    out = bytearray(data)
    for _ in range(rng.randint(1, 8)):
        pos = rng.randrange(len(out) + 1)
        op = rng.choice(("flip", "value", "value", "delete", "insert", "dup", "truncate"))
        if op == "flip" and pos < len(out):
            out[pos] ^= 1 << rng.randrange(8)
        elif op == "value":
            chunk = rng.choice(INTERESTING)
            out[pos:pos + len(chunk)] = chunk
        elif op == "delete":
            del out[pos:pos + rng.randint(1, 64)]
        elif op == "insert":
            out[pos:pos] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
        elif op == "dup":
            out[pos:pos] = out[pos:pos + rng.randint(1, 256)] * rng.randint(1, 4)
        elif op == "truncate":
            del out[pos:]
    return bytes(out)


def in_payload(magic: bytes | None, data: bytes, change) -> bytes:
    """``change`` applied inside the zlib payload of a binary file (re-compressed), else to the bytes."""
    if magic is None or not data.startswith(magic):
        return change(data)
    try:
        payload = zlib.decompressobj().decompress(data[len(magic):], 1 << 24)
    except zlib.error:
        return change(data)
    return magic + zlib.compress(change(payload), 6)


def signature(exc: BaseException) -> str:
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if "mocycle" in f.filename] or \
        traceback.extract_tb(exc.__traceback__)
    where = f"{Path(frames[-1].filename).name}:{frames[-1].lineno}" if frames else "?"
    return f"{type(exc).__name__} at {where}"


def _limit_memory(rss_mb: int) -> None:
    limit = rss_mb * 2**20 + _mapped()
    resource.setrlimit(resource.RLIMIT_AS, (limit, resource.getrlimit(resource.RLIMIT_AS)[1]))


def _mapped() -> int:
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")


def _peak_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # Linux: kilobytes


# ---------------------------------------------------------------- the random engine
def child_random(reader: str, seconds: float, rss_mb: int, timeout: float, out: Path, seed: int) -> dict:
    from mocycle.errors import MotionFileError

    run, seeds, magic, *structured = _targets()[reader]
    mutate = structured[0] if structured else None
    _limit_memory(rss_mb)
    rng = random.Random(seed)
    stats = {"reader": reader, "engine": "random", "tried": 0, "accepted": 0, "refused": 0, "crashes": {},
             "hangs": 0, "blowups": 0, "slowest_s": 0.0}
    if not seeds:
        stats["skipped"] = "no seed files (set MOCYCLE_FUZZ_FBX to a folder of .fbx files)"
        stats["peak_mb"] = _peak_mb()
        return stats

    def alarm(signum, frame):
        raise Hang()

    signal.signal(signal.SIGALRM, alarm)
    corpus = list(seeds)
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        base = rng.choice(corpus)
        if mutate is not None:  # structure-aware: edits of the file's structure, at times bytes on top
            data = mutate(base, rng)
            if data is base or rng.random() < 0.15:
                data = mutate_bytes(data, rng)
        else:
            data = in_payload(magic, base, lambda d: mutate_bytes(d, rng)) if rng.random() < 0.75 else \
                mutate_bytes(base, rng)
        stats["tried"] += 1
        t0 = time.monotonic()
        signal.setitimer(signal.ITIMER_REAL, timeout)
        try:
            run(data)
            stats["accepted"] += 1
            if len(corpus) < 200 and len(data) < 1 << 20:
                corpus.append(data)  # accepted variants seed further mutations
        except MotionFileError:
            stats["refused"] += 1
        except Hang:
            stats["hangs"] += 1
            _keep(out, reader, "hang", data)
        except MemoryError:
            stats["blowups"] += 1
            _keep(out, reader, "oom", data)
        except Exception as exc:  # noqa: BLE001 - this is what the fuzzer hunts
            sig = signature(exc)
            stats["crashes"][sig] = stats["crashes"].get(sig, 0) + 1
            _keep(out, reader, "crash", data)
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        stats["slowest_s"] = max(stats["slowest_s"], time.monotonic() - t0)
    stats["peak_mb"] = _peak_mb()
    return stats


def _keep(out: Path, reader: str, kind: str, data: bytes) -> None:
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{reader}-{kind}-{zlib.crc32(data):08x}").write_bytes(data)


# ---------------------------------------------------------------- the atheris engine
def child_atheris(reader: str, seconds: float, rss_mb: int, timeout: float, out: Path, seed: int) -> None:
    import atheris
    import numpy  # noqa: F401 - third-party code is imported first so that only mocycle gets instrumented
    import scipy.interpolate  # noqa: F401
    import scipy.linalg  # noqa: F401
    import scipy.ndimage  # noqa: F401
    import scipy.sparse  # noqa: F401
    import scipy.spatial  # noqa: F401
    import scipy.spatial.transform  # noqa: F401

    with atheris.instrument_imports(include=["mocycle"]):
        import mocycle.io._nodes  # noqa: F401
        import mocycle.io.asfamc  # noqa: F401
        import mocycle.io.bvh  # noqa: F401
        import mocycle.io.fbx  # noqa: F401
        import mocycle.io.fbx_scan  # noqa: F401
        import mocycle.io.gltf_read  # noqa: F401
        import mocycle.io.inflate  # noqa: F401
        import mocycle.io.mck  # noqa: F401
        import mocycle.io.mosw  # noqa: F401
        import mocycle.io.regular  # noqa: F401
        import mocycle.io.swings_json  # noqa: F401
        import mocycle.swings.playback  # noqa: F401
        from mocycle.errors import MotionFileError
    run, seeds, magic, *structured = _targets()[reader]
    corpus = Path(tempfile.mkdtemp(prefix=f"mocycle-fuzz-{reader}-"))
    for k, s in enumerate(seeds):
        (corpus / f"seed{k}").write_bytes(s)

    def one(data: bytes) -> None:
        try:
            run(data)
        except MotionFileError:
            pass

    def mutator(data: bytes, max_size: int, mseed: int) -> bytes:
        if structured:  # the file's structure edited (fuzz_scenes), else libFuzzer's own byte mutation
            rng = random.Random(mseed)
            out = structured[0](data, rng) if rng.random() < 0.85 else data
            return out if out is not data and len(out) <= max_size else atheris.Mutate(data, max_size)
        out = in_payload(magic, data, lambda d: atheris.Mutate(d, max(len(d) * 2, 64)))
        return out if len(out) <= max_size else atheris.Mutate(data, max_size)

    out.mkdir(parents=True, exist_ok=True)
    argv = [sys.argv[0], f"-max_total_time={int(seconds)}", f"-rss_limit_mb={rss_mb}", f"-timeout={int(timeout)}",
            f"-seed={seed}", f"-artifact_prefix={out}/{reader}-", "-print_final_stats=1", "-max_len=262144",
            str(corpus)]
    atheris.Setup(argv, one, custom_mutator=mutator if magic or structured else None)
    atheris.Fuzz()


def parse_libfuzzer(text: str) -> dict:
    stats = {"tried": 0, "peak_mb": 0.0}
    for line in text.splitlines():
        words = line.split()
        if line.startswith("#") and words[0][1:].isdigit():
            stats["tried"] = max(stats["tried"], int(words[0][1:]))
        if "rss:" in words:
            stats["peak_mb"] = max(stats["peak_mb"], float(words[words.index("rss:") + 1].rstrip("Mb")))
        if line.startswith("stat::number_of_executed_units:"):
            stats["tried"] = max(stats["tried"], int(words[-1]))
        if line.startswith("stat::peak_rss_mb:"):
            stats["peak_mb"] = max(stats["peak_mb"], float(words[-1]))
    return stats


# ---------------------------------------------------------------- replaying saved inputs
def replay_one(reader: str, path: Path, rss_mb: int, timeout: float) -> dict:
    """Run the saved input ``path`` through ``reader``'s target once in this process under ``rss_mb`` of
    address space: outcome (accepted, refused, crash, hang, blow-up), seconds and peak MB."""
    from mocycle.errors import MotionFileError

    run = _targets()[reader][0]
    _limit_memory(rss_mb)

    def alarm(signum, frame):
        raise Hang()

    signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    t0 = time.monotonic()
    try:
        run(path.read_bytes())
        outcome = "accepted"
    except MotionFileError as exc:
        outcome = f"refused: {str(exc)[:100]}"
    except Hang:
        outcome = "hang"
    except MemoryError:
        outcome = "blow-up (MemoryError)"
    except Exception as exc:  # noqa: BLE001 - what a crash is
        outcome = f"crash: {signature(exc)}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
    return {"file": path.name, "outcome": outcome, "seconds": round(time.monotonic() - t0, 4),
            "peak_mb": round(_peak_mb())}


def _child_env(args) -> dict:
    """The environment of a child process: this checkout's ``src`` first, and the readers' frame limit (the
    largest take a file may claim: one that fits the memory limit when played back)."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[1] / "src") + os.pathsep
           + os.environ.get("PYTHONPATH", "")}
    if args.max_frames:
        env["MOCYCLE_MAX_FRAMES"] = str(args.max_frames)
    return env


def _replay_outcome(path: Path, args) -> str:
    """What the saved input ``path`` does alone in a fresh process under ``args``' limits (:func:`replay_one`)."""
    env = _child_env(args)
    code = ("import json, sys; from pathlib import Path; sys.path.insert(0, sys.argv[1]); import fuzz; "
            "print(json.dumps(fuzz.replay_one(sys.argv[2], Path(sys.argv[3]), int(sys.argv[4]), "
            "float(sys.argv[5]))))")
    proc = subprocess.run([sys.executable, "-c", code, str(Path(__file__).resolve().parent),
                           path.name.split("-")[0], str(path), str(args.rss_mb), str(args.timeout)],
                          capture_output=True, text=True, env=env)
    lines = proc.stdout.strip().splitlines()
    return json.loads(lines[-1])["outcome"] if proc.returncode == 0 and lines else \
        f"process ended with {proc.returncode}: {proc.stderr[-200:]}"


def replay(args) -> int:
    """``--replay``: each file in a fresh process (a long fuzzing process's memory is not the input's)."""
    bad = False
    for path in args.replay:
        if path.name.split("-")[0] not in READERS:
            print(f"{path}: the name does not start with a reader ({', '.join(READERS)})")
            bad = True
            continue
        outcome = _replay_outcome(path, args)
        bad |= not outcome.startswith(("accepted", "refused"))
        print(f"{path.name}: {outcome}")
    return 1 if bad else 0


# ---------------------------------------------------------------- the parent
def run_reader(reader: str, engine: str, args) -> dict:
    env = {**_child_env(args), "MOCYCLE_FUZZ_DATA": str(args.data)}
    cmd = [sys.executable, __file__, "--child", reader, "--engine", engine, "--seconds", str(args.seconds),
           "--rss-mb", str(args.rss_mb), "--timeout", str(args.timeout), "--out", str(args.out)]
    if engine == "random":
        cmd += ["--seed", str(args.seed)]  # another seed, other mutations
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
        try:
            return json.loads(proc.stdout.strip().splitlines()[-1])
        except (IndexError, json.JSONDecodeError):
            return {"reader": reader, "engine": engine, "tried": 0, "crashes": {f"child died: {proc.stderr[-300:]}": 1},
                    "hangs": 0, "blowups": 0, "peak_mb": 0.0}
    # atheris stops at its first finding: restart until the time is used, counting findings
    stats = {"reader": reader, "engine": "atheris", "tried": 0, "crashes": {}, "hangs": 0, "blowups": 0,
             "peak_mb": 0.0}
    end = time.monotonic() + args.seconds
    restarts = 0
    while (left := end - time.monotonic()) > 1 and restarts < 50:
        cmd[cmd.index("--seconds") + 1] = str(max(int(left), 1))
        cmd += ["--seed", str(restarts + 1)]
        before = set(args.out.glob(f"{reader}-*")) if args.out.exists() else set()
        proc = subprocess.run(cmd, capture_output=True, text=True, env=env)
        found = parse_libfuzzer(proc.stderr)
        stats["tried"] += found["tried"]
        stats["peak_mb"] = max(stats["peak_mb"], found["peak_mb"])
        new = set(args.out.glob(f"{reader}-*")) - before if args.out.exists() else set()
        for p in new:
            kind = p.name.split("-")[1]
            if kind == "timeout":
                stats["hangs"] += 1
            elif kind in ("oom", "leak"):
                # libFuzzer's RSS watchdog blames the input running when the process passes the limit; the
                # atheris process itself grows by some 170 bytes per input, so the input is tried alone
                if _replay_outcome(p, args).startswith(("accepted", "refused")):
                    stats["process_oom"] = stats.get("process_oom", 0) + 1
                else:
                    stats["blowups"] += 1
            else:
                lines = [ln for ln in proc.stderr.splitlines() if "Error" in ln or "Exception" in ln]
                sig = lines[-1].strip()[:120] if lines else p.name
                stats["crashes"][sig] = stats["crashes"].get(sig, 0) + 1
        if proc.returncode == 0 or not new:
            break
        restarts += 1
    return stats


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="per reader")
    parser.add_argument("--readers", default=",".join(READERS))
    parser.add_argument("--engine", choices=("auto", "atheris", "random"), default="auto")
    parser.add_argument("--rss-mb", type=int, default=2048)
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds per input")
    parser.add_argument("--max-frames", type=int, default=100_000,
                        help="MOCYCLE_MAX_FRAMES of the readers (0: as set): a compressed file (.mck, .mosw, swings "
                             "JSON) may describe a long take in a few bytes, which is legitimate up to this limit; "
                             "the default keeps the largest such take within --rss-mb, so that a run past the "
                             "memory limit is an allocation the limit does not bound")
    parser.add_argument("--out", type=Path, default=Path(tempfile.gettempdir()) / "mocycle-fuzz")
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    parser.add_argument("--child", choices=READERS)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--replay", type=Path, nargs="+", metavar="FILE",
                        help="run saved inputs (named READER-KIND-..., as --out keeps them) once each in a fresh "
                             "process under the same limits, and print what each does there")
    args = parser.parse_args(argv)
    if args.replay:
        return replay(args)
    if args.child:
        if args.engine == "atheris":
            child_atheris(args.child, args.seconds, args.rss_mb, args.timeout, args.out, args.seed)
            return 0
        print(json.dumps(child_random(args.child, args.seconds, args.rss_mb, args.timeout, args.out, args.seed)))
        return 0
    engine = args.engine
    if engine == "auto":
        try:
            import atheris  # noqa: F401

            engine = "atheris"
        except ImportError:
            engine = "random"
    from rich.console import Console
    from rich.table import Table

    table = Table(title=f"fuzzing, {engine} engine, {args.seconds:g} s per reader, {args.rss_mb} MB, "
                        f"{args.timeout:g} s per input")
    for col in ("reader", "inputs tried", "crashes", "hangs", "blow-ups", "fuzzer over its memory", "peak MB",
                "crash signatures"):
        table.add_column(col, justify="left" if col in ("reader", "crash signatures") else "right")
    bad = False
    for reader in args.readers.split(","):
        s = run_reader(reader, engine, args)
        if s.get("skipped"):
            table.add_row(reader, "skipped", "", "", "", "", "", s["skipped"])
            continue
        n_crash = sum(s["crashes"].values())
        bad |= bool(n_crash or s["hangs"] or s["blowups"])
        table.add_row(reader, f"{s['tried']:,}", str(n_crash), str(s["hangs"]), str(s["blowups"]),
                      str(s.get("process_oom", 0)), f"{s['peak_mb']:.0f}",
                      "; ".join(f"{k} ×{v}" for k, v in s["crashes"].items()) or "-")
    Console().print(table)
    print(f"inputs that failed are kept in {args.out}" if bad else "no crash, hang or blow-up")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
