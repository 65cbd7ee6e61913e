"""The CPU of looping parts, without the read and the cut (issue 38): what each part costs in the workers.

    python benchmarks/part_work.py SESSION.bvh [--frames 40000] [--rounds 3] [--pieces FILE] [--out DIR]

Reads the take's first ``--frames`` frames, cuts them into parts (``segment_activities``) and pickles every part
that loops as the workers receive it (``cycle.parts.PartPiece``) to ``--pieces`` (reused when it exists, so
that two codes are timed on the same pieces); then, ``--rounds`` times in this process, loops each piece as
``mocycle loop --part all --root motion`` does (``tasks.loop._loop_one``) and writes it as BVH into a fresh
temporary folder, and prints the CPU seconds (``time.process_time``) of each stage summed over the pieces, and
the best round.  ``--out``: the loops are written there instead (to compare two codes' files).  BLAS runs one
thread, as in the CLI (set before numpy loads).
"""

from __future__ import annotations

import os

for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import collections  # noqa: E402
import contextlib  # noqa: E402
import pickle  # noqa: E402
import tempfile  # noqa: E402
import time  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("session")
    parser.add_argument("--frames", type=int, default=40_000)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--pieces", default=None, help="pickle of the pieces (default: beside the session)")
    parser.add_argument("--out", default=None, help="folder the loops are written to (default: a temporary one)")
    args = parser.parse_args()

    from mocycle.io import write
    from mocycle.tasks.loop import Options, _loop_one

    path = args.pieces or f"{args.session}.{args.frames}.pieces.pkl"
    if not os.path.exists(path):
        from mocycle.activities import segment_activities
        from mocycle.cycle.parts import part_piece, parts_to_try
        from mocycle.io import read_motion

        motion = read_motion(args.session)[:args.frames]
        acts = segment_activities(motion)
        with open(path, "wb") as f:
            pickle.dump([part_piece(motion, acts, k) for k in parts_to_try(acts, "all")], f)
    with open(path, "rb") as f:
        pieces = pickle.load(f)
    print(f"{len(pieces)} pieces, {sum(p.motion.n_frames for p in pieces)} frames ({path})")
    options = Options(which="all", root="motion")
    best: dict | None = None
    for _ in range(args.rounds):
        spent: dict[str, float] = collections.defaultdict(float)

        @contextlib.contextmanager
        def timer(name, spent=spent):
            t = time.process_time()
            yield
            spent[name] += time.process_time() - t

        t0 = time.process_time()
        if args.out:
            os.makedirs(args.out, exist_ok=True)
        with (contextlib.nullcontext(args.out) if args.out else tempfile.TemporaryDirectory()) as folder:
            for i, piece in enumerate(pieces):
                try:
                    _, result, _, _ = _loop_one(piece, options, "part", timer)
                except Exception:  # a part refused or without a loop: its work until then is counted
                    continue
                with timer("write"):
                    write(result, os.path.join(folder, f"{i}.bvh"))
        row = {k: round(v, 3) for k, v in spent.items()} | {"total": round(time.process_time() - t0, 3)}
        print(row, flush=True)
        if best is None or row["total"] < best["total"]:
            best = row
    print("best", best)


if __name__ == "__main__":
    main()
