"""Build the mocycle Blender extension zip(s) with Blender's own extension tooling.

    python blender/build_extension.py [--platform linux-x64 ...] [--out dist]

Run it with a Python that has the ``bpy`` wheel (``make blender-extension`` uses ``.venv-bpy52``): Blender's
``extension build`` command lives in the bundled ``addons_core/bl_pkg/cli/blender_ext.py``, which runs
without the ``blender`` binary. Steps: copy the add-on (``blender/mocycle_blender``) to a staging folder,
build mocycle itself as a wheel, download from PyPI the binary wheels of its dependencies for each platform
and each Python that Blender ships (3.11 in 4.2-5.0, resolved against numpy 1.26.4; 3.13 in 5.1+, resolved
against numpy 2.2.6, the oldest numpy the 5.1+ ``bpy`` wheels accept; numpy itself is left out of the
bundle), write ``blender_manifest.toml`` listing them, and call ``blender_ext.py build --split-platforms``:
one zip per platform, ``dist/mocycle-<version>-<platform>.zip``, holding the cp311 and the cp313 wheels side
by side. Blender installs only the wheels that match its own Python and platform, and lists the extension as
compatible with the Python versions its wheels name (3.11 and 3.13).

Pure-Python dependencies (joblib, threadpoolctl, ...) are pinned to the versions resolved for 3.11 when the
3.13 wheels are resolved, so the zip holds one version of each (Blender installs the newest of duplicates,
which could be one that no longer runs on 3.11).
"""

from __future__ import annotations

import argparse
import glob
import importlib.util
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "blender" / "mocycle_blender"

#: Blender platform -> pip --platform tags (the first that has a wheel wins)
PLATFORMS = {
    "linux-x64": ["manylinux_2_28_x86_64", "manylinux_2_17_x86_64", "manylinux2014_x86_64"],
    "windows-x64": ["win_amd64"],
    "macos-arm64": ["macosx_12_0_arm64", "macosx_11_0_arm64"],  # not 14_0: scipy's Accelerate build needs macOS 14
}
#: what the core imports at run time (ripser's own requirements, persim and Cython, are not: persim only
#: draws diagrams, Cython only builds); numpy comes with Blender
RESOLVED = ["scipy", "scikit-learn", "threadpoolctl"]
NO_DEPS = ["ripser"]
#: the Pythons Blender ships -> the numpy their wheels are resolved against (so they need no newer one): 3.11 in
#: Blender 4.2 LTS to 5.0 (which bring numpy 1.26.4), 3.13 in 5.1 and 5.2 LTS (numpy 2; the bpy 5.1+ wheels on
#: PyPI ask numpy>=2.2, so 2.2.6, the last 2.2)
PYTHONS = {"3.11": "numpy==1.26.4", "3.13": "numpy==2.2.6"}
LEFT_OUT = ("numpy-",)


def blender_ext() -> Path:
    """Blender's extension command line (``bl_pkg/cli/blender_ext.py``) inside the installed ``bpy`` wheel."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        sys.exit("error: the bpy module is not installed in this Python (make blender-extension uses .venv-bpy52)")
    base = Path(list(spec.submodule_search_locations)[0])
    hits = sorted(glob.glob(str(base / "*" / "scripts" / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py")))
    if not hits:
        sys.exit(f"error: no addons_core/bl_pkg/cli/blender_ext.py under {base}")
    return Path(hits[-1])


def pip(*args: str) -> None:
    subprocess.run([sys.executable, "-m", "pip", *args, "--quiet", "--disable-pip-version-check"], check=True)


def _pure(wheel: Path) -> bool:
    return wheel.name.endswith("-none-any.whl")


def _pin(wheel: Path) -> str:
    name, version = wheel.name.split("-")[:2]
    return f"{name}=={version}"


def download(platform: str, cache: Path) -> list[Path]:
    """The dependency wheels for one Blender platform, every Python in :data:`PYTHONS` (downloaded afresh into
    ``cache/<platform>/<python>``, so nothing from an earlier resolution slips in; pip's own HTTP cache makes a
    second build quick)."""
    tags = [a for t in PLATFORMS[platform] for a in ("--platform", t)]
    found: dict[str, Path] = {}
    pins: list[str] = []
    for python, numpy in PYTHONS.items():
        dest = cache / platform / python
        shutil.rmtree(dest, ignore_errors=True)
        dest.mkdir(parents=True)
        abi = "cp" + python.replace(".", "")
        common = ["download", "--only-binary=:all:", "--python-version", python, "--implementation", "cp",
                  "--abi", abi, *tags, "-d", str(dest)]
        constraints = []
        if pins:  # the pure-Python wheels resolved for the first Python, for every other
            pin_file = dest / "pure-pins.txt"
            pin_file.write_text("\n".join(pins) + "\n")
            constraints = ["-c", str(pin_file)]
        pip(*common, *constraints, *RESOLVED, numpy)
        pip(*common, "--no-deps", *NO_DEPS)
        wheels = [p for p in dest.glob("*.whl") if not p.name.startswith(LEFT_OUT)]
        for whl in wheels:
            found.setdefault(whl.name, whl)
        if not pins:
            pins = [_pin(w) for w in wheels if _pure(w)]
    return sorted(found.values(), key=lambda p: p.name)


def manifest(version: str, wheels: list[str], platforms: list[str]) -> str:
    lines = [
        'schema_version = "1.0.0"',
        'id = "mocycle"',
        f'version = "{version}"',
        'name = "mocycle"',
        'tagline = "Seamless cycles from motion capture: phase, loop, blend, stretch"',
        'maintainer = "mocycle developers"',
        'type = "add-on"',
        'blender_version_min = "4.2.0"',
        'license = ["SPDX:MIT"]',
        'tags = ["Animation"]',
        f"platforms = [{', '.join(repr(p).replace(chr(39), chr(34)) for p in platforms)}]",
        "wheels = [",
        *[f'  "./wheels/{w}",' for w in wheels],
        "]",
    ]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--platform", action="append", choices=sorted(PLATFORMS),
                    help="build for these platforms only (repeatable; default all three)")
    ap.add_argument("--out", default=str(ROOT / "dist"), help="output folder of the zips")
    ap.add_argument("--cache", default=str(ROOT / "build" / "wheel-cache"), help="downloaded wheels")
    args = ap.parse_args(argv)
    platforms = args.platform or list(PLATFORMS)
    version = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    stage = ROOT / "build" / "blender-extension"
    shutil.rmtree(stage, ignore_errors=True)
    (stage / "wheels").mkdir(parents=True)
    for src in ADDON.glob("*.py"):
        shutil.copy2(src, stage / src.name)
    pip("wheel", "--no-deps", "--no-build-isolation", "-w", str(stage / "wheels"), str(ROOT))
    for platform in platforms:
        for whl in download(platform, Path(args.cache)):
            shutil.copy2(whl, stage / "wheels" / whl.name)
    wheels = sorted(p.name for p in (stage / "wheels").glob("*.whl"))
    (stage / "blender_manifest.toml").write_text(manifest(version, wheels, platforms))
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    subprocess.run([sys.executable, str(blender_ext()), "build", "--source-dir", str(stage), "--output-dir",
                    str(out), "--split-platforms"], check=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
