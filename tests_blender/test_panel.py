"""The panel and the properties: built from ``tasks.schema``, drawn by the panel's own ``draw()``."""

import importlib.util
import sys

import bpy
import pytest

from conftest import REPO

_spec = importlib.util.spec_from_file_location("docs_figures", REPO / "blender" / "docs_figures.py")
docs_figures = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(docs_figures)


@pytest.mark.parametrize("op, task", [("find_phase", "phase"), ("extract_cycle", "loop"), ("blend_cycles", "blend"),
                                      ("transition", "transition"), ("stretch", "stretch")])
def test_operator_options_are_the_tasks(extension, op, task):
    """Every option of the task (bar the ones Blender fills) is an operator property with its help line and
    default; enums carry the task's choices."""
    from mocycle import tasks

    addon = sys.modules["bl_ext.user_default.mocycle"]
    schema = tasks.schema(tasks.TASKS[task].Options)["properties"]
    rna = getattr(bpy.ops.mocycle, op).get_rna_type().properties
    names = [k for k in schema if k not in addon.props.FROM_BLENDER]
    assert names and all(k in rna for k in names)
    for k in names:
        assert rna[k].description.startswith(schema[k]["description"])
        if schema[k].get("enum") and schema[k].get("type") == "string":
            assert [i.identifier for i in rna[k].enum_items] == schema[k]["enum"]
            assert rna[k].default == schema[k]["default"]


def flatten(node):
    for item in node["items"]:
        if "items" in item:
            yield from flatten(item)
        else:
            yield item


def test_panel_draws_options_buttons_and_last_result(scene, tmp_path):
    import mocycle
    from conftest import import_bvh
    from mocycle.datasets import synthetic_walk

    addon = sys.modules["bl_ext.user_default.mocycle"]
    path = tmp_path / "Walk.bvh"
    mocycle.write(synthetic_walk(n_frames=240, fps=30).motion, path)
    import_bvh(path)
    bpy.ops.mocycle.find_phase()
    bpy.ops.mocycle.extract_cycle()
    layout = docs_figures.Recorder()
    addon.panel.MOCYCLE_PT_panel.draw(type("P", (), {"layout": layout})(), bpy.context)
    items = list(flatten(layout.to_json()))
    buttons = [i["button"] for i in items if "button" in i]
    assert buttons == ["Find Phase", "Extract Cycle", "Blend Cycles", "Transition", "Stretch"]
    props = {i["prop"]: i["value"] for i in items if "prop" in i}
    assert props["Method"] == "harmonic" and props["Model"] == "M1" and props["Factor"] == "1.5"
    assert "Take" not in props  # (a file's take: the add-on reads the active action, never a file)
    labels = [i["label"] for i in items if "label" in i]
    assert any(t.startswith("Period: ") for t in labels) and any(t.startswith("Seam: ") for t in labels)
    assert any(t.startswith("Foot skate: ") for t in labels)
    lists = [i for i in items if "list" in i]
    assert lists and lists[0]["list"][0].startswith("0: ")


def test_the_user_reads_part_not_class(scene, tmp_path):
    """Labels, tooltips and what the panels draw say "part" (or "periodic motion"), never "class"; the option
    that counts the periodic motions looked for keeps its name (``classes``) and reads "Periodic motions"."""
    import mocycle
    from conftest import import_bvh
    from mocycle.datasets import synthetic_walk

    addon = sys.modules["bl_ext.user_default.mocycle"]
    texts = []
    for name in dir(bpy.ops.mocycle):
        rna = getattr(bpy.ops.mocycle, name).get_rna_type()
        texts += [rna.name, rna.description]
        texts += [t for p in rna.properties if p.identifier != "rna_type" for t in (p.name, p.description)]
    assert bpy.ops.mocycle.find_phase.get_rna_type().properties["classes"].name == "Periodic motions"
    path = tmp_path / "Walk.bvh"
    mocycle.write(synthetic_walk(n_frames=240, fps=30).motion, path)
    import_bvh(path)
    bpy.ops.mocycle.find_phase()
    for panel in (addon.panel.MOCYCLE_PT_panel, addon.panel.MOCYCLE_PT_advanced, addon.panel.MOCYCLE_PT_details):
        layout = docs_figures.Recorder()
        panel.draw(type("P", (), {"layout": layout})(), bpy.context)
        for item in flatten(layout.to_json()):
            texts += [str(item.get(k, "")) for k in ("label", "prop", "button")] + list(item.get("list", []))
    texts += [bpy.context.scene.mocycle.last_message, bpy.context.scene.mocycle.last_detail]
    assert len(texts) > 100
    assert not [t for t in texts if "class" in t.lower()]
