"""Every ``mocycle`` command with ``--json`` on the synthetic takes: the cases of the before/after test.

``make_before.py`` runs these cases with the code of an older commit and stores what they print in
``before.json``; ``test_before_after.py`` runs them with the current code and compares. The flags used
here exist, with the same meaning, before and after the CLI renames of issue 12 (``--fps``/``--seed``
are not used). Timing fields are dropped, temporary paths become ``<tmp>``.
"""

from __future__ import annotations

import json
from pathlib import Path

TIMING_KEYS = ("seconds", "metrics_seconds", "timings_s")

#: name -> the command line (``{tmp}`` is the folder of the takes, ``{out}`` a scratch folder).
CASES: dict[str, list[str]] = {
    "info": ["info", "{tmp}/walk.bvh", "--json"],
    "phase": ["phase", "{tmp}/walk.bvh", "--json"],
    "phase_nonperiodic": ["phase", "{tmp}/nonperiodic.bvh", "--json"],
    "loop": ["loop", "{tmp}/walk.bvh", "-o", "{out}/loop.bvh", "--json"],
    "loop_cut_motion": ["loop", "{tmp}/run.bvh", "-o", "{out}/loop2.bvh", "--method", "cut", "--root", "motion",
                        "--cycles", "2", "--json"],
    "loop_nonperiodic": ["loop", "{tmp}/nonperiodic.bvh", "-o", "{out}/loop3.bvh", "--json"],
    "blend": ["blend", "{tmp}/walk.bvh", "{tmp}/run.bvh", "-o", "{out}/blend.bvh", "--weights", "0.7,0.3", "--json"],
    "transition": ["transition", "{tmp}/walk.bvh", "{tmp}/run.bvh", "-o", "{out}/tr.bvh", "--cycles", "2",
                   "--json"],
    "stretch": ["stretch", "{tmp}/walk.bvh", "--factor", "1.5", "-o", "{out}/stretch.bvh", "--json"],
    "swings": ["swings", "{tmp}/walk.bvh", "-o", "{out}/walk.mosw", "--json"],
    "swings_mosw": ["swings", "{out}/walk.mosw", "--json"],
    "search": ["search", "{tmp}/walk.bvh", "{tmp}", "--top", "3", "--json"],
    "edit": ["edit", "{tmp}/walk.bvh", "--joint", "LeftUpLeg", "--swing", "0", "--angle-scale", "1.5",
             "-o", "{out}/edit.bvh", "--json"],
    "compress": ["compress", "{tmp}/walk.bvh", "-o", "{out}/walk.mck", "--ratio", "0.03", "--json"],
    "compress_spatial": ["compress", "{tmp}/walk.bvh", "-o", "{out}/walk2.mck", "--ratio", "0.05", "--scheme",
                         "spatial", "--projection", "pca", "--select", "scs", "--json"],
    "project": ["project", "{tmp}/walk.bvh", "--ratio", "0.03", "--json"],
    "project_optimize": ["project", "{tmp}/walk.bvh", "--ratio", "0.05", "--projection", "pca", "--optimize",
                         "--json"],
}


def write_takes(folder: Path) -> None:
    """The synthetic takes the cases read (small, so the whole run takes seconds)."""
    from mocycle.datasets import synthetic_nonperiodic, synthetic_run, synthetic_walk
    from mocycle.io import write

    folder.mkdir(parents=True, exist_ok=True)
    write(synthetic_walk(n_frames=240, fps=60, noise_deg=0.5, seed=1).motion, folder / "walk.bvh")
    write(synthetic_run(n_frames=200, fps=60, seed=2).motion, folder / "run.bvh")
    write(synthetic_nonperiodic(n_frames=200, fps=60, seed=3).motion, folder / "nonperiodic.bvh")


def clean(value):
    """Drop timing fields (recursively)."""
    if isinstance(value, dict):
        return {k: clean(v) for k, v in value.items() if k not in TIMING_KEYS}
    if isinstance(value, list):
        return [clean(v) for v in value]
    return value


def run_all(tmp: Path) -> dict[str, dict]:
    """Run every case in-process; name -> {"exit_code", "json"} with paths made relative to ``<tmp>``."""
    from typer.testing import CliRunner

    from mocycle.cli import app

    takes, out = tmp / "takes", tmp / "out"
    write_takes(takes)
    out.mkdir(parents=True, exist_ok=True)
    runner = CliRunner()
    results = {}
    for name, args in CASES.items():
        argv = [a.format(tmp=takes, out=out) for a in args]
        res = runner.invoke(app, argv)
        text = res.stdout.replace(str(out), "<out>").replace(str(takes), "<tmp>")
        try:
            facts = clean(json.loads(text)) if text.strip() else None
        except json.JSONDecodeError as exc:
            raise AssertionError(f"{name}: stdout is not JSON: {text[:300]!r}; stderr {res.stderr[:300]!r}") from exc
        results[name] = {"exit_code": res.exit_code, "json": facts}
    return results


if __name__ == "__main__":  # used by make_before.py under the old code
    import sys
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        print(json.dumps(run_all(Path(d)), indent=1, sort_keys=True))
        sys.stdout.flush()
