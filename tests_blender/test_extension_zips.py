"""Blender's own extension code judges the zips: for each platform's zip beside the installed one (``make
test-blender`` builds all three into ``dist/``), the checks Blender runs before it installs an extension
(``repository_filter_skip`` in ``bl_pkg/cli/blender_ext.py``: Blender version, platform, and the Python versions
named by the zip's wheels) pass for every supported Blender with its Python, and refuse a Python that has no
wheels in the zip. The zip built for Linux is also installed and run by every other test here; this one covers
the Blender versions and platforms this environment is not."""

import importlib.util
import sys
from pathlib import Path

import bpy
import pytest

#: supported Blender -> the Python it ships (major, minor, micro)
SUPPORTED = {(4, 2, 0): (3, 11, 7), (4, 5, 0): (3, 11, 11), (5, 0, 0): (3, 11, 13), (5, 1, 0): (3, 13, 5),
             (5, 2, 0): (3, 13, 5)}


@pytest.fixture(scope="module")
def blender_ext():
    path = Path(bpy.utils.system_resource("SCRIPTS")) / "addons_core" / "bl_pkg" / "cli" / "blender_ext.py"
    spec = importlib.util.spec_from_file_location("mocycle_test_blender_ext", path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # dataclasses and typing look the module up by name
    spec.loader.exec_module(module)
    return module


def zips(extension) -> list[Path]:
    installed, _ = extension
    found = sorted(installed.parent.glob(installed.name.replace("linux_x64", "*")))
    assert installed in found
    return found


def listing(blender_ext, path: Path) -> dict:
    """The zip's manifest as Blender lists it (``server-generate``: ``python_versions`` from the wheels)."""
    manifest = blender_ext.pkg_manifest_from_archive_and_validate(str(path), strict=False)
    assert not isinstance(manifest, str), f"{path.name}: {manifest}"
    item = {k: v for k, v in manifest._asdict().items() if v is not None}
    versions = blender_ext.python_versions_from_wheels(item.pop("wheels"))
    assert not isinstance(versions, str), versions
    item["python_versions"] = [".".join(map(str, v)) for v in sorted(versions)]
    return item


def skipped(blender_ext, item, blender, platform, python) -> list[str]:
    why: list[str] = []

    def error(exc):
        raise exc

    if blender_ext.repository_filter_skip(item, filter_blender_version=blender, filter_platform=platform,
                                          filter_python_version=python, skip_message_fn=why.append,
                                          error_fn=error):
        return why or ["skipped"]
    return []


def test_every_supported_blender_accepts_each_zip(blender_ext, extension):
    for path in zips(extension):
        platform = path.stem.rsplit("-", 1)[1].replace("_", "-")
        item = listing(blender_ext, path)
        print(f"\n{path.name}: Blender {item['blender_version_min']}+, {item.get('platforms')}, "
              f"Python {item['python_versions']}")
        assert item["python_versions"] == ["3.11", "3.13"]
        for blender, python in SUPPORTED.items():
            assert skipped(blender_ext, item, blender, platform, python) == [], (path.name, blender, python)
        # refused: a Python without wheels here, a Blender before 4.2, another platform
        for python in ((3, 12, 0), (3, 14, 0)):
            (why,) = skipped(blender_ext, item, (5, 2, 0), platform, python)
            assert "isn't compatible with (3.11, 3.13)" in why
        assert skipped(blender_ext, item, (4, 1, 0), platform, (3, 11, 7))
        other = "linux-x64" if platform != "linux-x64" else "windows-x64"
        assert skipped(blender_ext, item, (5, 2, 0), other, (3, 13, 5))
