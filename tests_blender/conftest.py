"""Blender test session: build the extension zip, install it as a user extension into a temporary Blender user
folder, and give each test an empty scene.

Run by ``make test-blender`` in ``.venv-bpy52`` (bpy 5.2 LTS, Python 3.13, slotted actions) and ``.venv-bpy42``
(bpy 4.2 LTS, Python 3.11, legacy ``action.fcurves``). ``MOCYCLE_BLENDER_ZIP`` names a zip already built (the
Makefile passes the one ``make blender-extension`` built; else the linux-x64 one is built here with
``blender/build_extension.py``). mocycle and its dependencies come from the installed extension's
wheels, not from the repository: the tests check the bundle too.
"""

import importlib.util
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
USER = Path(tempfile.mkdtemp(prefix="mocycle-blender-user-"))
os.environ["BLENDER_USER_RESOURCES"] = str(USER)  # read when bpy starts: set before the import
import bpy  # noqa: E402

_spec = importlib.util.spec_from_file_location("mocycle_test_shared", REPO / "tests" / "conftest.py")
shared = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(shared)
shared_path = shared.shared_path


def _build_zip(out: Path) -> Path:
    given = os.environ.get("MOCYCLE_BLENDER_ZIP")
    if given:
        return Path(given)
    done = subprocess.run([sys.executable, str(REPO / "blender" / "build_extension.py"), "--platform", "linux-x64",
                           "--out", str(out)], capture_output=True, text=True)
    assert done.returncode == 0, f"building the extension failed:\n{done.stdout}\n{done.stderr}"
    (zip_path,) = out.glob("mocycle-*-linux_x64.zip")
    return zip_path


@pytest.fixture(scope="session")
def extension(tmp_path_factory):
    """The installed extension: (zip path, install seconds). Afterwards ``import mocycle`` is the bundled one."""
    zip_path = _build_zip(tmp_path_factory.mktemp("dist"))
    t = time.perf_counter()
    result = bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo="user_default",
                                                      enable_on_install=True)
    seconds = time.perf_counter() - t
    assert result == {"FINISHED"}
    assert hasattr(bpy.ops.mocycle, "extract_cycle")
    # the library and its compiled dependencies come from the wheels Blender picked for its own Python
    import ripser
    import scipy
    import sklearn

    import mocycle

    tag = f"cp{sys.version_info[0]}{sys.version_info[1]}"
    for module in (mocycle, scipy, sklearn, ripser):
        assert Path(module.__file__).resolve().is_relative_to(USER.resolve()), (
            f"{module.__name__} imported from {module.__file__}, not from the installed extension")
    print(f"\nbpy {bpy.app.version_string} (Python {sys.version.split()[0]}, {tag}): installed {zip_path.name} "
          f"({zip_path.stat().st_size / 1e6:.1f} MB) in {seconds:.1f} s; scipy {scipy.__version__}, "
          f"scikit-learn {sklearn.__version__}")
    return zip_path, seconds


@pytest.fixture
def scene(extension):
    """An empty scene (objects, armatures and actions removed), 30 fps, frame 1, metres (a test that sets the
    scene's unit, as the Mixamo-style FBX test does, would otherwise scale what the next one imports)."""
    for ob in list(bpy.data.objects):
        bpy.data.objects.remove(ob)
    for coll in (bpy.data.armatures, bpy.data.actions):
        for item in list(coll):
            coll.remove(item)
    sc = bpy.context.scene
    sc.render.fps, sc.render.fps_base = 30, 1.0
    sc.unit_settings.system, sc.unit_settings.scale_length, sc.unit_settings.length_unit = "METRIC", 1.0, "METERS"
    sc.frame_set(1)
    sc.mocycle.parts.clear()
    sc.mocycle.last_task = ""
    return sc


@pytest.fixture(scope="session")
def addon(extension):
    """The installed add-on package (``bl_ext.user_default.mocycle``)."""
    return sys.modules["bl_ext.user_default.mocycle"]


def import_bvh(path) -> "bpy.types.Object":
    """``bpy.ops.import_anim.bvh`` with the scene's frame rate and length set from the file."""
    assert bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=True, update_scene_duration=True) == {
        "FINISHED"}
    return bpy.context.active_object


# bpy 4.2's own teardown at interpreter exit can crash (a segmentation fault after every test passed, once its FBX
# and glTF exporters have run: test_formats_in.py), which would turn a green run red. There the process
# leaves with pytest's own status once pytest has printed its summary, without that teardown.
_STATUS: dict[str, int] = {}


def pytest_sessionfinish(session, exitstatus):
    _STATUS["code"] = int(exitstatus)


def pytest_unconfigure(config):
    if bpy.app.version < (4, 3, 0) and "code" in _STATUS:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_STATUS["code"])
