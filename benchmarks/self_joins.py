"""Joins a segmentation cannot see by tempo or style: every shared Bandai walk, run and dash joined to itself.

    python benchmarks/self_joins.py [--data DIR] [--fps FPS] [--offsets 7,15] [--keep DIR]

Each take is joined (``mocycle.datasets.join_takes``, the 10-frame cross-fade of ``benchmarks/sessions.py``) to
itself started ``offset`` frames on: one performer, one tempo, one posture, the second copy at another phase.
``mocycle loop --part all --root motion`` runs on each pair, and ``sessions.py``'s measures judge it: a loop
reaching more than half its period over the join, a stretch of 1.5 strides or more without a loop of its own,
a loop off the ruler's stride.  Printed: the pairs with a failure, then the counts.  A join near one phase is
seamless (nothing tells it, nothing a loop across it spoils): some loops over the join are left for that.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import sessions as S  # noqa: E402  (the session builder and the measures of benchmarks/sessions.py)

import mocycle  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=Path(__file__).resolve().parents[1].parent / "shared" / "data")
    ap.add_argument("--fps", type=float, default=None, help="resample the joined pairs (default: the takes' own)")
    ap.add_argument("--offsets", default="7,15", help="frames the second copy starts on, comma-separated")
    ap.add_argument("--keep", type=Path, default=None, help="keep the pairs and their loops here")
    args = ap.parse_args(argv)
    files = sorted(p for sub in ("bandai", "bandai2") for p in (args.data / sub).glob("*.bvh")
                   if any(k in p.stem for k in ("_run_", "_dash_", "_walk_")))
    if not files:
        print(f"no Bandai walks or runs under {args.data}")
        return 1
    offsets = [int(x) for x in args.offsets.split(",")]
    with tempfile.TemporaryDirectory() as tmp:
        folder = args.keep or Path(tmp)
        folder.mkdir(parents=True, exist_ok=True)
        pairs = []
        for p in files:
            take = mocycle.read(p)
            for o in offsets:
                if take.n_frames - o > 3 * S.CROSSFADE:
                    label = S._label(p.stem)
                    pairs.append(S._write(folder, f"{p.stem}_o{o}", [(label, take), (label, take[o:])], args.fps))

        def one(session):
            r = S.run(session, folder / "loops")
            S.measure(r)
            return r

        with ThreadPoolExecutor(2) as pool:
            results = list(pool.map(one, pairs))
    for r in results:
        rows = r.rows
        if rows["spans"] or rows["missed"] or rows["off_period"] or r.code != 0:
            print(f"{r.session.name}: exit {r.code}, {rows['loops']} loops; over the join: {rows['spans']}; "
                  f"without a loop: {rows['missed']}; off the ruler: {rows['off_period']}")
    print(f"\n{len(results)} pairs: with a loop over the join {sum(bool(r.rows['spans']) for r in results)}; "
          f"stretches looped {sum(r.rows['got'] for r in results)} of {sum(r.rows['wanted'] for r in results)}; "
          f"loops off the ruler {sum(len(r.rows['off_period']) for r in results)}; "
          f"exit other than 0 {sum(r.code != 0 for r in results)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
