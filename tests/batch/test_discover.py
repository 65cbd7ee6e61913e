"""Which takes a batch finds, and where their outputs go."""

from pathlib import Path

import pytest

from mocycle.batch import find_takes
from mocycle.datasets.asfamc_text import TINY_AMC, TINY_ASF
from mocycle.errors import MocycleError


def _tree(root: Path) -> Path:
    for name in ("a/walk.bvh", "a/deep/run.BVH", "b/02_01.amc", "b/02.asf", "b/notes.txt", "a/.hidden.bvh",
                 ".git/x.bvh", "top.bvh"):
        p = root / name
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text(TINY_ASF if p.suffix == ".asf" else TINY_AMC if p.suffix == ".amc" else "x")
    return root


def rels(takes):
    return [str(t.rel) for t in takes]


def test_a_folder_is_searched_recursively_for_bvh_and_amc(tmp_path):
    root = _tree(tmp_path / "in")
    takes = find_takes([root])
    assert rels(takes) == ["a/deep/run.BVH", "a/walk.bvh", "b/02_01.amc", "top.bvh"]  # no .txt, .asf, hidden
    assert all(t.source.is_absolute() and t.source.exists() for t in takes)
    amc = takes[2]
    assert [p.name for p in amc.inputs()] == ["02_01.amc", "02.asf"]  # its skeleton counts for --resume


def test_outputs_mirror_the_tree_with_their_own_suffix(tmp_path):
    root = _tree(tmp_path / "in")
    out = tmp_path / "out"
    take = [t for t in find_takes([root]) if t.rel.name == "02_01.amc"][0]
    assert take.output(out, ".bvh") == out / "b" / "02_01.bvh"


def test_several_inputs_keep_their_folder_names(tmp_path):
    root = _tree(tmp_path / "in")
    takes = find_takes([root / "a", root / "b", root / "top.bvh"])
    assert rels(takes) == ["a/deep/run.BVH", "a/walk.bvh", "b/02_01.amc", "top.bvh"]
    assert rels(find_takes([root / "a" / "walk.bvh"])) == ["walk.bvh"]


def test_glob_patterns_are_relative_to_their_folder_before_the_wildcard(tmp_path):
    root = _tree(tmp_path / "in")
    assert rels(find_takes([str(root / "a" / "**" / "*.BVH")])) == ["deep/run.BVH"]
    assert rels(find_takes([str(root / "*" / "*.bvh")])) == ["a/walk.bvh"]


def test_the_output_folder_is_not_read_back_and_duplicates_count_once(tmp_path):
    root = _tree(tmp_path / "in")
    (root / "out" / "a").mkdir(parents=True)
    (root / "out" / "a" / "walk.bvh").write_text("an earlier output")
    takes = find_takes([root, root / "top.bvh"], outdir=root / "out")
    assert "out/a/walk.bvh" not in rels(takes) and rels(takes).count("top.bvh") == 1


@pytest.mark.parametrize("make, match", [
    (lambda r: [r / "missing"], "no such file or folder"),
    (lambda r: [r / "a" / "notes.txt"], "not a take"),
    (lambda r: [r / "empty"], "no .bvh, .amc, .fbx, .glb, .gltf files"),
    (lambda r: [str(r / "*.fbx")], "matches no"),
    (lambda r: [], "no inputs"),
])
def test_bad_inputs_are_one_clear_error(tmp_path, make, match):
    root = tmp_path / "in"
    (root / "a").mkdir(parents=True)
    (root / "empty").mkdir()
    (root / "a" / "notes.txt").write_text("x")
    with pytest.raises(MocycleError, match=match):
        find_takes(make(root))


def test_two_takes_with_the_same_outputs_are_refused(tmp_path):
    (tmp_path / "walk.bvh").write_text("x")
    (tmp_path / "walk.amc").write_text("x")
    with pytest.raises(MocycleError, match="would write the same outputs"):
        find_takes([tmp_path])


def test_linked_takes_keep_the_name_they_are_given(tmp_path):
    root = _tree(tmp_path / "in")
    links = tmp_path / "links"
    links.mkdir()
    (links / "mine.bvh").symlink_to(root / "a" / "walk.bvh")
    assert rels(find_takes([links])) == ["mine.bvh"]
    assert rels(find_takes([str(links / "*.bvh")])) == ["mine.bvh"]
    both = find_takes([links / "mine.bvh", root / "a" / "walk.bvh"])  # another name: a take with its own output
    assert rels(both) == ["in/a/walk.bvh", "links/mine.bvh"]
    assert rels(find_takes([links, links / "mine.bvh"])) == ["mine.bvh"]  # one path named twice is one take
