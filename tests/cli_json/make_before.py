"""Record what every ``mocycle`` command prints with ``--json`` under an older commit into
``tests/cli_json/before.json`` (and the commit's hash into ``before.commit``).

    python tests/cli_json/make_before.py [COMMIT]

The default, 6e2c70a, is the code before issue 12's task layer. When other branches that change figures on
purpose are merged, the fixture is made again from the ``main`` commit merged last (it holds their changes
but not the task layer), so the test still measures only what the task layer changed.
The commit's ``src/`` is exported with ``git archive`` to a temporary folder and the cases of
``cases.py`` run there in a subprocess, so the fixture is what that code printed, not a copy of today's.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
REPO = HERE.parents[1]


def main(commit: str = "6e2c70a") -> None:
    archive = subprocess.run(["git", "-C", str(REPO), "archive", commit, "src"], check=True,
                             capture_output=True).stdout
    with tempfile.TemporaryDirectory() as d:
        with tarfile.open(fileobj=io.BytesIO(archive)) as tar:
            tar.extractall(d, filter="data")
        env = dict(os.environ, PYTHONPATH=f"{d}/src")
        code = f"import runpy; runpy.run_path({str(HERE / 'cases.py')!r}, run_name='__main__')"
        done = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True, env=env)
    full = subprocess.run(["git", "-C", str(REPO), "rev-parse", commit], check=True, capture_output=True,
                          text=True).stdout.strip()
    (HERE / "before.json").write_text(done.stdout)
    (HERE / "before.commit").write_text(full + "\n")
    print(f"wrote {HERE / 'before.json'} from commit {full}")


if __name__ == "__main__":
    main(*sys.argv[1:])
