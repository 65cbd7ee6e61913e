"""``mocycle`` and ``python -m mocycle``: the command line, which needs the ``cli`` extra (typer, rich)."""

from __future__ import annotations

import sys

from .errors import MocycleError

INSTALL_HINT = "pip install 'mocycle[cli]'"


def main() -> None:
    """Run the ``mocycle`` command, or say in one line how to install it when typer or rich is missing.

    ``mocycle.cli`` is light to import; its :func:`~mocycle.cli.guarded` installs the SIGINT/SIGTERM
    handlers before typer, rich, numpy and scipy are imported, so a signal at any moment ends the run with
    one line and no traceback.  Before that, BLAS and OpenMP are set to one thread (``MOCYCLE_THREADS``,
    :mod:`mocycle.threads`) while numpy is not loaded yet, so that no worker thread starts.
    """
    from .threads import pin_environment

    try:
        pin_environment()
    except MocycleError as exc:  # a bad MOCYCLE_THREADS: a usage error
        sys.stderr.write(f"mocycle: error: {exc}\n")
        raise SystemExit(2) from None
    from .cli import guarded

    guarded(_run)


def _run() -> None:
    from importlib.util import find_spec

    try:
        import typer  # noqa: F401
        if find_spec("rich") is None:  # found, not imported: rich is loaded only when something is printed
            raise ImportError("rich is missing", name="rich")
    except ImportError as exc:
        missing = exc.name or "typer"
        sys.stderr.write(f"mocycle: the command line needs the cli extra ({missing} is not installed): "
                         f"{INSTALL_HINT}\n")
        raise SystemExit(1) from None
    from .cli import run

    run()


if __name__ == "__main__":
    main()
