"""``OUTDIR/results.csv`` and ``OUTDIR/results.json``: a row per take (``loop``: a CSV line per part looped),
written atomically at the end."""

from __future__ import annotations

import csv
import io
from collections import Counter
from pathlib import Path

from ..io.atomic import atomic_write
from ..text import json_text, printable
from .commands import COMMANDS

__all__ = ["CSV_HEAD", "summary", "write_results"]

#: the columns every command's CSV starts with; its figures follow, then these
CSV_HEAD = ("file", "status", "message")
CSV_TAIL = ("seconds", "outputs", "warnings", "resumed")


def _cell(value) -> str:
    """A CSV cell as printable text (:func:`mocycle.text.printable`: control characters and bytes that are not
    UTF-8 as ``\\xNN``), so the file is valid UTF-8 and safe to show in a terminal."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return " ".join(map(printable, value))
    return printable(value)


def csv_text(command: str, rows: list[dict]) -> str:
    """The CSV: file, status, message, the command's figures, seconds, outputs (space separated), warnings
    (``; `` separated) and whether ``--resume`` kept the take's earlier result."""
    figures = list(COMMANDS[command].figures)
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow([*CSV_HEAD, *figures, *CSV_TAIL])
    for r in rows:
        for part in r.get("parts") or [r["figures"]]:  # a take cut into parts (loop): a line per part
            writer.writerow([_cell(r["file"]), r["status"], _cell(r["message"]),
                             *(_cell(part.get(k)) for k in figures),
                             _cell(r["seconds"]), _cell(r["outputs"]), _cell("; ".join(r["warnings"])),
                             "yes" if r.get("resumed") else ""])
    return buffer.getvalue()


def summary(rows: list[dict]) -> dict:
    """How many takes got each status, and the task seconds of the takes run now (not the resumed ones)."""
    counts = Counter(r["status"] for r in rows)
    run = [r for r in rows if not r.get("resumed")]
    return {"takes": len(rows), **{s: counts.get(s, 0) for s in ("ok", "no-periodic-motion", "refused", "error")},
            "resumed": len(rows) - len(run), "task_seconds": sum(r["seconds"] or 0.0 for r in run)}


def write_results(outdir: Path, command: str, options: dict, rows: list[dict], run: dict) -> tuple[Path, Path]:
    """Write both files atomically; ``run``: how the batch ran (engine, workers, wall seconds)."""
    data = {"command": command, "options": options, "summary": summary(rows), "run": run, "takes": rows}
    return (atomic_write(outdir / "results.csv", csv_text(command, rows)),
            atomic_write(outdir / "results.json", json_text(data, indent=1)))
