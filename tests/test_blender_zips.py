"""The Blender extension zips (``make blender-extension``, ``dist/mocycle-<version>-<platform>.zip``): each holds,
for every Python that Blender ships (3.11 in 4.2 LTS to 5.0, 3.13 in 5.1 and 5.2 LTS), a wheel of every bundled
package built for that Python and that platform, and its manifest lists exactly the wheels in the zip.

Pure Python: the zips are opened with ``zipfile``, no Blender needed. They are read from ``MOCYCLE_BLENDER_DIST``
(``make test-blender`` sets it, and then a missing zip fails) or ``dist/`` (skipped with a message when no zip is
there: ``make blender-extension`` builds them).
"""

from __future__ import annotations

import email.parser
import importlib.util
import os
import re
import tomllib
import zipfile
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.specifiers import SpecifierSet
from packaging.utils import canonicalize_name, parse_wheel_filename
from packaging.version import Version

REPO = Path(__file__).resolve().parents[1]
_spec = importlib.util.spec_from_file_location("mocycle_build_extension", REPO / "blender" / "build_extension.py")
build = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(build)

VERSION = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]["version"]
GIVEN = os.environ.get("MOCYCLE_BLENDER_DIST")
DIST = Path(GIVEN) if GIVEN else REPO / "dist"
#: Blender platform -> what a wheel's platform tag must say for it
PLATFORM_TAG = {"linux-x64": r"^(manylinux|linux)\w*_x86_64$", "windows-x64": r"^win_amd64$",
                "macos-arm64": r"^macosx_\d+_\d+_(arm64|universal2)$"}
#: every package the add-on imports at run time (mocycle's own dependencies and theirs), numpy excepted
NEEDED = {"mocycle", "scipy", "scikit-learn", "ripser", "threadpoolctl", "joblib"}


def _zip(platform: str) -> Path:
    path = DIST / f"mocycle-{VERSION}-{platform.replace('-', '_')}.zip"
    if not path.exists():
        if GIVEN:
            pytest.fail(f"{path} is missing: make blender-extension builds it")
        pytest.skip(f"{path.name} not built (make blender-extension builds the zips)")
    return path


def _wheel_metadata(zf: zipfile.ZipFile, member: str, tmp_path: Path):
    """The METADATA of a wheel inside the extension zip (read without unpacking the whole wheel to disk)."""
    local = tmp_path / Path(member).name
    local.write_bytes(zf.read(member))
    with zipfile.ZipFile(local) as wheel:
        (meta,) = [n for n in wheel.namelist() if re.fullmatch(r"[^/]+\.dist-info/METADATA", n)]
        return email.parser.Parser().parsestr(wheel.read(meta).decode())


def test_the_pythons_are_the_ones_blender_ships():
    assert set(build.PYTHONS) == {"3.11", "3.13"}
    assert set(build.PLATFORMS) == set(PLATFORM_TAG)


@pytest.mark.parametrize("platform", sorted(PLATFORM_TAG))
def test_zip_has_a_wheel_per_python_and_the_manifest_lists_them(platform, tmp_path):
    with zipfile.ZipFile(_zip(platform)) as zf:
        in_zip = sorted(n for n in zf.namelist() if n.endswith(".whl"))
        manifest = tomllib.loads(zf.read("blender_manifest.toml").decode())
        assert in_zip and all(n.startswith("wheels/") for n in in_zip)
        # the manifest lists exactly the wheels in the zip (the source list was cut to this platform's by
        # Blender's --split-platforms; the generated block is what Blender installs from)
        generated = manifest["build"]["generated"]
        assert generated["platforms"] == [platform]
        assert sorted(w.removeprefix("./") for w in generated["wheels"]) == in_zip
        assert {w.removeprefix("./") for w in manifest["wheels"]} >= set(in_zip)
        assert manifest["blender_version_min"] == "4.2.0" and platform in manifest["platforms"]

        tags = {f"cp{p.replace('.', '')}": p for p in build.PYTHONS}
        packages: dict[str, dict[str, str]] = {}  # package -> python tag ("py3" for pure) -> wheel
        for member in in_zip:
            name, version, _, wheel_tags = parse_wheel_filename(Path(member).name)
            assert name != "numpy", "numpy comes with Blender and must not be bundled"
            keys = set()
            for tag in wheel_tags:  # one file may carry several tags (manylinux_2_24 and _2_28)
                if tag.platform == "any":
                    assert tag.abi == "none" and tag.interpreter.startswith("py3"), member
                    keys.add("py3")
                else:
                    assert re.match(PLATFORM_TAG[platform], tag.platform), f"{member}: not a {platform} wheel"
                    assert tag.interpreter == tag.abi and tag.interpreter in tags, f"{member}: not for {set(tags)}"
                    keys.add(tag.interpreter)
            for key in keys:
                assert key not in packages.get(name, {}), f"two {name} wheels for {key}: Blender would pick one"
                packages.setdefault(name, {})[key] = member

        assert NEEDED <= set(packages), f"missing {NEEDED - set(packages)}"
        # the Pythons the zip claims (Blender derives them from the wheels' tags, as here): both, and every
        # binary package has a wheel for each
        claimed = {key for by_tag in packages.values() for key in by_tag} - {"py3"}
        assert claimed == set(tags)
        for name, by_tag in packages.items():
            if "py3" in by_tag:
                assert set(by_tag) == {"py3"}, f"{name}: a pure wheel beside binary ones"
            else:
                assert set(by_tag) == set(tags), f"{name}: wheels for {sorted(by_tag)}, not {sorted(tags)}"

        # each Python's set of wheels installs: Requires-Python holds, and every requirement of a bundled
        # wheel is bundled too (numpy: Blender's, at the version the wheels were resolved against)
        for tag, python in tags.items():
            chosen = {name: by_tag.get(tag, by_tag.get("py3")) for name, by_tag in packages.items()}
            versions = {name: parse_wheel_filename(Path(m).name)[1] for name, m in chosen.items()}
            versions["numpy"] = Version(build.PYTHONS[python].split("==")[1])
            env = {"python_version": python, "python_full_version": f"{python}.0", "extra": "",
                   "sys_platform": {"linux-x64": "linux", "windows-x64": "win32", "macos-arm64": "darwin"}[platform],
                   "platform_system": {"linux-x64": "Linux", "windows-x64": "Windows",
                                       "macos-arm64": "Darwin"}[platform]}
            for name, member in chosen.items():
                meta = _wheel_metadata(zf, member, tmp_path)
                requires_python = meta.get("Requires-Python")
                if requires_python:
                    assert SpecifierSet(requires_python).contains(f"{python}.0"), f"{member}: {requires_python}"
                for line in meta.get_all("Requires-Dist") or []:
                    req = Requirement(line)
                    if req.marker is not None and not req.marker.evaluate(env):
                        continue
                    dep = canonicalize_name(req.name)
                    if name == "ripser" and dep in {"persim", "cython"}:
                        continue  # plotting and building only (build_extension.py: NO_DEPS)
                    assert dep in versions, f"{member} needs {line}, not bundled for Python {python}"
                    assert req.specifier.contains(versions[dep], prereleases=True), (
                        f"{member} needs {line}, bundled {dep} {versions[dep]} for Python {python}")
