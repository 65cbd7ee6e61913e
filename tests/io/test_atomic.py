import os
import stat

from mocycle.io.atomic import atomic_write


def test_new_file_gets_the_umask_mode_not_mkstemp_0600(tmp_path):
    old = os.umask(0o022)
    try:
        path = atomic_write(tmp_path / "a.txt", "hello")
    finally:
        os.umask(old)
    assert path.read_text() == "hello"
    assert stat.S_IMODE(path.stat().st_mode) == 0o644


def test_existing_file_keeps_its_mode(tmp_path):
    path = tmp_path / "b.bin"
    path.write_bytes(b"old")
    path.chmod(0o640)
    atomic_write(path, b"new")
    assert path.read_bytes() == b"new" and stat.S_IMODE(path.stat().st_mode) == 0o640
    assert [p.name for p in tmp_path.iterdir()] == ["b.bin"]


def test_leftovers_of_killed_writes_are_removed_live_ones_kept(tmp_path):
    target = tmp_path / "out.bvh"
    dead = tmp_path / ".out.bvh.4194399.x1y2.tmp"  # above Linux's largest pid: no such process
    old = tmp_path / ".out.bvh.k3j4l5.tmp"  # the old name, without a pid: stale once it is an hour old
    live = tmp_path / f".out.bvh.{os.getpid()}.abcd.tmp"  # a write in progress (this process)
    other = tmp_path / ".other.bvh.4194399.x1y2.tmp"  # another target's: not ours to touch
    for p in (dead, old, live, other):
        p.write_text("partial")
    os.utime(old, (1, 1))
    atomic_write(target, "new")
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([target.name, live.name, other.name])


def test_failed_write_leaves_no_temporary_file(tmp_path, monkeypatch):
    import pytest

    def boom(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", boom)
    with pytest.raises(OSError):
        atomic_write(tmp_path / "c.bvh", "data")
    assert list(tmp_path.iterdir()) == []


def test_a_folder_is_listed_once_however_many_outputs_go_there(tmp_path, monkeypatch):
    """Writing n outputs into one folder lists it once (not n times: quadratic in n), and each target's
    leftovers from that listing still go at its own first write."""
    from mocycle.io import atomic

    for k in range(3):
        (tmp_path / f".out{k}.bvh.4194399.x1y2.tmp").write_text("partial")
    listed = []
    scandir = os.scandir
    monkeypatch.setattr(atomic.os, "scandir", lambda folder: listed.append(folder) or scandir(folder))
    for k in range(50):
        atomic_write(tmp_path / f"out{k}.bvh", "new")
    assert len(listed) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(f"out{k}.bvh" for k in range(50))


def test_a_name_too_long_for_its_temporary_file_is_written(tmp_path):
    """A 245-byte name (a take of 235 letters and its record's tail) once made a temporary name of over 255
    bytes; its temporary file now stands for it by a shortened name, and killed writes' leftovers still go."""
    from mocycle.io.atomic import _temporary_prefix

    name = "w" * 235 + ".loop.json"
    prefix = _temporary_prefix(name)
    assert len(prefix.encode()) < 170 and prefix.startswith(".www")
    stale = tmp_path / (".w" + "w" * 149 + "~" + "0" * 12 + ".4194399.x1y2.tmp")  # another long name's
    stale.write_text("another long name's")
    (tmp_path / (prefix + "4194399.x1y2.tmp")).write_text("partial")  # a killed write of this name's
    path = atomic_write(tmp_path / name, "record")
    assert path.read_text() == "record"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([name, stale.name])
    odd = "é" * 120 + "\udcff.bvh"  # 245 bytes, one not UTF-8: cut within a character
    assert atomic_write(tmp_path / odd, "x").read_text() == "x"
