"""How a batch shows its progress: a rich bar (done, failed, rate, ETA) on a terminal, plain lines otherwise."""

from __future__ import annotations

import time

from ..text import printable

__all__ = ["BarProgress", "LineProgress", "progress_for"]


def _figures_text(row: dict) -> str:
    shown = [f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row["figures"].items()
             if v is not None][:4]
    return ", ".join(shown)


class LineProgress:
    """One line per take: ``[3/40] a/walk.bvh: ok (period_frames 32.1, ...) 0.41 s``; the failed count
    (statuses other than ok) and the rate of the takes run so far."""

    def __init__(self, console, total: int, resumed: int = 0):
        self.console, self.total, self.done, self.failed = console, total, resumed, 0
        self.t0, self.run = time.perf_counter(), 0
        if resumed:
            console.print(f"{resumed} take(s) kept from the earlier run (--resume)")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False

    def advance(self, row: dict, ran: bool = True) -> None:
        """Count ``row``; ``ran``: it was run now (a path that could not be read as a take was not, and does
        not count in the rate)."""
        self.done += 1
        self.run += ran
        self.failed += row["status"] != "ok"
        rate = self.run / max(time.perf_counter() - self.t0, 1e-9)
        what = row["status"] + (f": {row['message']}" if row["message"] else "")
        figures = _figures_text(row) if row["status"] == "ok" else ""
        rate_text = f", {rate:.2f} takes/s" if self.run else ""
        self.console.print(printable(f"[{self.done}/{self.total}] {row['rel']}: {what}")
                           + (f" ({figures})" if figures else "") + f"; not ok {self.failed}{rate_text}",
                           markup=False, highlight=False, soft_wrap=True)


class BarProgress:
    """A rich progress bar: takes done of total, how many were not ok, takes per second and the time left."""

    def __init__(self, console, total: int, resumed: int = 0):
        from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

        self.progress = Progress(TextColumn("batch"), BarColumn(), MofNCompleteColumn(),
                                 TextColumn("not ok {task.fields[failed]}"),
                                 TextColumn("{task.fields[rate]} takes/s"), TextColumn("ETA"), TimeRemainingColumn(),
                                 console=console, transient=False)
        self.task = self.progress.add_task("batch", total=total, completed=resumed, failed=0, rate="-")
        self.failed, self.run, self.t0 = 0, 0, time.perf_counter()

    def __enter__(self):
        self.progress.__enter__()
        return self

    def __exit__(self, *exc):
        return self.progress.__exit__(*exc)

    def advance(self, row: dict, ran: bool = True) -> None:
        self.failed += row["status"] != "ok"
        self.run += ran
        rate = self.run / max(time.perf_counter() - self.t0, 1e-9)
        self.progress.update(self.task, advance=1, failed=self.failed, rate=f"{rate:.2f}")


def progress_for(console, total: int, resumed: int = 0):
    """A bar when ``console`` is a terminal, else plain lines."""
    return (BarProgress if console.is_terminal else LineProgress)(console, total, resumed)
