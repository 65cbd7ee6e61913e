"""Record what every ``mocycle`` command prints with ``--json`` under an older commit (default 6e2c70a,
the code before issue 12's task layer) into ``tests/cli_json/before.json``.

    python tests/cli_json/make_before.py [COMMIT]

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
    (HERE / "before.json").write_text(done.stdout)
    print(f"wrote {HERE / 'before.json'} from commit {commit}")


if __name__ == "__main__":
    main(*sys.argv[1:])
