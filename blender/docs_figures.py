"""The figures of docs/blender.md, in two steps (bpy cannot draw Blender's UI without a window):

    .venv-bpy50/bin/python blender/docs_figures.py record build/blender-docs.json --zip dist/mocycle-...zip
    .venv/bin/python blender/docs_figures.py draw build/blender-docs.json docs/img

``record`` installs the extension in a temporary Blender user folder, imports a synthetic walk from BVH, runs
Find Phase and Extract Cycle, then runs the panel's own ``draw()`` against a layout that records every label,
property (with its value), button and box, and samples the bone heads of the source and the cycle as Blender
evaluates them. ``draw`` (matplotlib) renders that record: ``blender-panel.png``, a drawing of the panel from
its recorded layout (not a screenshot), and ``blender-cycle.png``, stick figures of the loop.
"""

import json
import os
import sys
import tempfile
from pathlib import Path


class Recorder:
    """Stands in for ``bpy.types.UILayout``: records what a panel draws, as nested lists of items."""

    def __init__(self, kind="column"):
        self.kind, self.items, self.enabled, self.active = kind, [], True, True

    def _child(self, kind):
        child = Recorder(kind)
        self.items.append(child)
        return child

    def box(self):
        return self._child("box")

    def row(self, align=False):
        return self._child("row")

    def column(self, align=False):
        return self._child("column")

    def separator(self):
        self.items.append({"separator": True})

    def label(self, text="", icon="NONE"):
        self.items.append({"label": text})

    def prop(self, data, name, text=None, **kw):
        rna = data.bl_rna.properties[name]
        value = getattr(data, name)
        if rna.type == "POINTER":
            value = value.name if value is not None else ""
        elif rna.type == "FLOAT":
            value = f"{value:.3g}"
        self.items.append({"prop": text if text is not None else rna.name, "value": value, "type": rna.type,
                           "enabled": self.enabled})

    def operator(self, idname, text="", icon="NONE"):
        class Properties:  # the panel sets the operator's options on it (recorded under "options")
            pass
        options = Properties()
        self.items.append({"button": text or idname, "options": options})
        return options

    def template_list(self, list_type, list_id, data, prop, active_data, active_prop, rows=2):
        import bpy

        cls = getattr(bpy.types, list_type)
        rows_out = []
        for index, item in enumerate(getattr(data, prop)):
            sub = Recorder()
            cls.draw_item(None, None, sub, data, item, 0, active_data, active_prop, index)
            rows_out.append(sub.items[0]["label"])
        self.items.append({"list": rows_out, "active": getattr(active_data, active_prop)})

    def to_json(self):
        def item(i):
            if isinstance(i, Recorder):
                return i.to_json()
            if "options" in i:
                return {**i, "options": {k: v for k, v in vars(i["options"]).items() if isinstance(
                    v, (str, int, float, bool))}}
            return i
        return {"kind": self.kind, "active": self.active, "items": [item(i) for i in self.items]}


def record(out: Path, zip_path: str):
    os.environ["BLENDER_USER_RESOURCES"] = tempfile.mkdtemp(prefix="mocycle-docs-")
    import bpy

    bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
    import mocycle
    from mocycle.datasets import synthetic_walk

    addon = sys.modules["bl_ext.user_default.mocycle"]
    path = Path(tempfile.mkdtemp()) / "Walk.bvh"
    mocycle.write(synthetic_walk(n_frames=240, fps=30).motion, path)
    bpy.ops.import_anim.bvh(filepath=str(path), update_scene_fps=True, update_scene_duration=True)
    arm = bpy.context.active_object
    bpy.ops.mocycle.find_phase()
    bpy.ops.mocycle.extract_cycle()
    action = arm.animation_data.action
    start, end = (int(round(x)) for x in action.frame_range)
    heads = []
    for f in range(start, end + 1):
        bpy.context.scene.frame_set(f)
        heads.append([list(arm.matrix_world @ pb.head) for pb in arm.pose.bones])
    parents = [arm.pose.bones.find(pb.parent.name) if pb.parent else -1 for pb in arm.pose.bones]
    layout = Recorder()
    panel = addon.panel.MOCYCLE_PT_panel
    panel.draw(type("P", (), {"layout": layout})(), bpy.context)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"blender": bpy.app.version_string, "panel": layout.to_json(),
                               "action": action.name, "heads": heads, "parents": parents,
                               "message": bpy.context.scene.mocycle.last_message}))
    print(f"recorded {out}")


def draw(src: Path, folder: Path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    data = json.loads(src.read_text())
    folder.mkdir(parents=True, exist_ok=True)
    lines = []  # (depth, kind, text, value)

    def walk(node, depth):
        for item in node["items"]:
            if "kind" in item:
                if item["kind"] == "box":
                    lines.append((depth, "box", "", ""))
                walk(item, depth + (1 if item["kind"] == "box" else 0))
            elif "label" in item:
                lines.append((depth, "label", item["label"], ""))
            elif "prop" in item:
                lines.append((depth, "prop", item["prop"], item["value"]))
            elif "button" in item:
                lines.append((depth, "button", item["button"], ""))
            elif "list" in item:
                for k, row in enumerate(item["list"]):
                    lines.append((depth, "listrow" if k != item["active"] else "listactive", row, ""))
    walk(data["panel"], 0)
    h = 0.26 * len(lines) + 0.6
    fig = plt.figure(figsize=(4.6, h), facecolor="#303030")
    ax = fig.add_axes([0, 0, 1, 1])
    ax.set_xlim(0, 1)
    ax.set_ylim(-len(lines) - 1, 1)
    ax.axis("off")
    ax.text(0.03, 0.2, f"mocycle  (Blender {data['blender']}, sidebar tab \u201cmocycle\u201d)", color="#e6e6e6",
            fontsize=9, weight="bold", va="center")
    for i, (depth, kind, text, value) in enumerate(lines):
        y, x = -i - 0.5, 0.04 + 0.03 * depth
        if kind == "box":
            ax.plot([0.02, 0.98], [y + 0.2, y + 0.2], color="#4a4a4a", lw=6, solid_capstyle="butt")
            continue
        if kind == "button":
            ax.add_patch(plt.Rectangle((x, y - 0.38), 0.94 - x, 0.76, color="#545454"))
            ax.text(0.5, y, text, color="#ffffff", fontsize=8, ha="center", va="center")
        elif kind == "prop":
            ax.text(x, y, text, color="#c8c8c8", fontsize=7.5, va="center")
            ax.add_patch(plt.Rectangle((0.5, y - 0.36), 0.44, 0.72, color="#1d1d1d"))
            ax.text(0.52, y, str(value), color="#e6e6e6", fontsize=7.5, va="center")
        elif kind.startswith("list"):
            if kind == "listactive":
                ax.add_patch(plt.Rectangle((x, y - 0.38), 0.94 - x, 0.76, color="#334d80"))
            ax.text(x + 0.01, y, text, color="#e6e6e6", fontsize=7, va="center")
        else:
            ax.text(x, y, text, color="#e6e6e6", fontsize=8, va="center")
    fig.savefig(folder / "blender-panel.png", dpi=110, facecolor=fig.get_facecolor())
    plt.close(fig)

    heads, parents = np.array(data["heads"]), data["parents"]
    n = heads.shape[0]
    picks = np.linspace(0, n - 1, 8).round().astype(int)
    fig, axes = plt.subplots(1, len(picks), figsize=(2 * len(picks), 3.2), sharey=True)
    for ax, f in zip(axes, picks, strict=True):
        p = heads[f]
        for j, q in enumerate(parents):
            if q >= 0:
                ax.plot(p[[q, j], 1], p[[q, j], 2], color="tab:blue", lw=2)
        ax.set_title(f"frame {f + 1}{' = 1' if f == n - 1 else ''}", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlim(p[:, 1].mean() - 60, p[:, 1].mean() + 60)
    fig.suptitle(data["message"] + " (bone heads as Blender evaluates them)", fontsize=8)
    fig.savefig(folder / "blender-cycle.png", dpi=90)
    plt.close(fig)
    print(f"wrote {folder / 'blender-panel.png'} and {folder / 'blender-cycle.png'}")


if __name__ == "__main__":
    mode, target = sys.argv[1], Path(sys.argv[2])
    if mode == "record":
        record(target, sys.argv[sys.argv.index("--zip") + 1])
    else:
        draw(target, Path(sys.argv[3]))
