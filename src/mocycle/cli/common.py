"""What every ``mocycle`` sub-command shares: the typer app, consoles, exit codes, error handling.

The app loads its commands lazily (:class:`LazyGroup`): ``mocycle --help`` lists them from :data:`COMMANDS`
without importing their modules, and ``mocycle loop`` imports the loop command (and what it needs) only.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import os
import warnings
from collections.abc import Callable, Mapping
from functools import wraps
from pathlib import Path
from typing import Annotated

import typer
import typer.main
from typer.core import TyperCommand, TyperGroup

from .. import __version__
from ..errors import LoopRefused, MocycleError, MocycleWarning, NoPeriodicMotion, OptionError
from ..suffixes import MOTION_WRITE_SUFFIXES
from ..tasks.flags import as_flags, option_message
from ..tasks.options import MISSING, flag_declaration, old_flag_warning
from ..tasks.spec import SPECS
from ..text import json_text, printable

#: sub-command -> (the module of ``mocycle.cli`` that defines it, the first paragraph of its help), in the
#: order ``mocycle --help`` lists them: the tasks' from their specs, then the front end's own commands.
#: tests/test_startup.py checks both against the commands themselves.
COMMANDS = {
    "info": (SPECS["info"].cli_module, SPECS["info"].summary),
    "convert": ("convert", "Convert ASF/AMC, FBX or glTF to BVH or glTF (.glb), or rewrite a BVH (optionally a "
                           "frame range, another fps)."),
    **{name: (spec.cli_module, spec.summary) for name, spec in SPECS.items() if spec.cli and name != "info"},
    "batch": ("batch", "Run one command over many takes on dask.distributed; a row per take in "
                       "OUTDIR/results.csv and .json."),
    "studio": ("studio", "Review loops on a library of takes and author new motion on the spatial-keyframe plane, "
                         "in the browser."),
    "report": ("report", "Write one HTML file (viewer, the take beside its loop repeated with root motion, phase "
                         "strip, metrics) that opens offline in a browser: to mail or attach to a ticket."),
    "demo": ("demo", "Loop the built-in synthetic walk: write the take, its cycle (BVH) and the loop plot."),
}


def load_commands(names=None) -> None:
    """Import the modules of the named commands (all by default); importing one registers its commands."""
    for name in COMMANDS if names is None else names:
        importlib.import_module(f"{__package__}.{COMMANDS[name][0]}")


class LazyGroup(TyperGroup):
    """The ``mocycle`` group: a command's module is imported when the command runs or shows its own help.

    ``mocycle --help`` shows the first paragraph of each command's help from :data:`COMMANDS`, so it imports
    none of them (nor numpy, scipy, scikit-learn); see ``docs/performance.md``.
    """

    def list_commands(self, ctx) -> list[str]:
        return list(dict.fromkeys([*COMMANDS, *self.commands]))

    def get_command(self, ctx, cmd_name: str):
        if cmd_name not in self.commands and cmd_name in COMMANDS:
            load_commands([cmd_name])
            group = typer.main.get_command(app)
            assert isinstance(group, TyperGroup)  # the app's cls, a LazyGroup
            self.commands.update(group.commands)
        return self.commands.get(cmd_name)

    def resolve_command(self, ctx, args):
        if args and args[0] not in COMMANDS:  # a typo: with every command loaded typer suggests the near ones
            for name in COMMANDS:
                self.get_command(ctx, name)
        return super().resolve_command(ctx, args)

    def format_commands(self, ctx, formatter) -> None:
        loaded = self.commands
        self.commands = {name: loaded.get(name) or TyperCommand(name=name, help=COMMANDS[name][1])
                         for name in self.list_commands(ctx)}
        try:
            super().format_commands(ctx, formatter)
        finally:
            self.commands = loaded


app = typer.Typer(
    cls=LazyGroup,
    name="mocycle",
    help="Turn raw motion capture into reusable animation.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # plain click help: flags show as `--json`, not `--json <bool>`
)


class _Console:
    """A rich ``Console`` made on first use: importing rich takes a tenth of a second that ``--help`` does
    not need (``docs/performance.md``)."""

    def __init__(self, **kwargs):
        self._kwargs = kwargs
        self._console = None

    def __getattr__(self, name):
        if self._console is None:
            from rich.console import Console

            self._console = Console(**self._kwargs)
        return getattr(self._console, name)


def escape(text) -> str:
    """Text from a file (a joint or take name, a path, an error message quoting a file) as data for rich:
    undecodable bytes, control and bidirectional characters written as visible escapes
    (:func:`mocycle.text.printable`: ``bad\\xffname.bvh``, ``\\x1b[31m``), then rich markup escaped
    (``rich.markup.escape``: a joint named ``[/]`` or ``[link=...]`` prints as those characters).

    Every print path of the CLI passes such text through here, and only here: in a ``[bold]...[/]`` line, in
    a table cell, in an ``error:`` or ``warning:`` line."""
    from rich.markup import escape as rich_escape

    return rich_escape(printable(text))


out = _Console(highlight=False)
err = _Console(stderr=True, highlight=False)

FORCE_HELP = "Allow an output to replace one of the input files."

EXIT_ERROR = 1
EXIT_USAGE = 2  # a bad option value (typer/click use 2 for usage errors too)
EXIT_NOT_FOUND = 3  # the input is fine but holds no periodic motion, or its cycle is not a loop


def friendly(func: Callable) -> Callable:
    """Run a command: MocycleError -> one 'error:' line and exit 1 (2 for a bad option value, 3 for
    NoPeriodicMotion and LoopRefused); warnings (the command's and its reports') -> 'warning:' lines."""

    @wraps(func)
    def wrapper(*args, **kwargs):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                result = func(*args, **kwargs)
            except OptionError as exc:
                _print_warnings(caught)
                err.print(f"[bold red]error:[/] {option_message(exc, func.__name__)}", markup=True, soft_wrap=True)
                raise typer.Exit(EXIT_USAGE) from None
            except MocycleError as exc:
                _print_warnings(caught)
                message = _naming_the_input(as_flags(str(exc), func.__name__), kwargs, func.__name__)
                err.print(f"[bold red]error:[/] {escape(message)}", markup=True, soft_wrap=True)
                refused = isinstance(exc, (NoPeriodicMotion, LoopRefused))
                raise typer.Exit(EXIT_NOT_FOUND if refused else EXIT_ERROR) from None
            except MemoryError:  # an input (or options) that asks for more than this machine or its limit gives
                _print_warnings(caught)
                message = _naming_the_input("out of memory: the input or the options ask for more memory than this "
                                            "process may use (MOCYCLE_MAX_FRAMES lowers what a file may claim)",
                                            kwargs, func.__name__)
                err.print(f"[bold red]error:[/] {escape(message)}", markup=True, soft_wrap=True)
                raise typer.Exit(EXIT_ERROR) from None
        _print_warnings(caught)
        return result

    return wrapper


def _input_arguments(command: str | None) -> tuple[str, ...]:
    """The arguments of ``command`` that name its inputs: its spec's (``Spec.inputs``), else ``path``/``paths``
    (``convert``, ``report``)."""
    spec = SPECS.get(command or "")
    return tuple(a.lstrip("*") for a in spec.inputs) if spec is not None else ("path", "paths")


def _naming_the_input(message: str, kwargs: dict, command: str | None = None) -> str:
    """``message`` with the input file in front when it names none of the command's files (so that in
    ``blend`` or ``transition`` the user can tell which take is meant).  Option errors stay as they are."""
    inputs = []
    for key in _input_arguments(command):
        value = kwargs.get(key)
        inputs += [str(v) for v in value] if isinstance(value, (list, tuple)) else [str(value)] if value else []
    files = inputs + [str(v) for v in kwargs.values() if isinstance(v, Path)]
    if len(inputs) != 1 or any(f in message for f in files) or message.startswith("-") or " --" in message:
        return message
    return f"{inputs[0]}: {message}"


def _print_warnings(caught) -> None:
    said = set()
    for w in caught:
        if issubclass(w.category, (DeprecationWarning, PendingDeprecationWarning)) or str(w.message) in said:
            continue  # each said once, however often it was raised
        said.add(str(w.message))
        err.print(f"[yellow]warning:[/] {escape(as_flags(str(w.message)))}", markup=True, soft_wrap=True)


def print_feet(feet: Mapping, note: str = "", tail: str = "") -> None:
    """The line a command that writes motion prints when it locked the feet (its report's ``feet`` facts):
    ``note`` after "feet locked", ``tail`` after the skate figures."""
    if feet["mode"] == "lock":
        out.print(f"  feet locked{note}: skate {feet['skate_before']:.4g} -> {feet['skate_after']:.4g} units/s{tail}",
                  soft_wrap=True)


def print_warnings(report) -> None:
    """The warnings a task recorded in its report, as 'warning:' lines."""
    for text in report.warnings:
        err.print(f"[yellow]warning:[/] {escape(as_flags(text, report.task))}", markup=True, soft_wrap=True)


def delivered(report, write: Writer | None = None):
    """A task's report as a command goes on with it: its warnings printed as 'warning:' lines, then, given the
    command's ``write``, its ``--output`` written. Returns the report."""
    print_warnings(report)
    if write is not None:
        write(report)
    return report


def print_facts(report, **more) -> None:
    """``--json`` for a command that prints its report whole: the facts, then what the command adds (``more``:
    the output's path), then the seconds."""
    print_json({**report.facts, **more, "seconds": report.seconds})


def _version(value: bool):
    if value:
        out.print(f"mocycle {__version__}")
        raise typer.Exit()


@app.callback()
def main_options(
    version: Annotated[bool, typer.Option("--version", callback=_version, is_eager=True,
                                          help="Print the version and exit.")] = False,
):
    """mocycle: periodic motion, seamless cycles, swings and keyframes from mocap files."""



# ------------------------------------------------------------ commands made from the task specs
def _field(options_cls, name: str) -> dataclasses.Field:
    for f in dataclasses.fields(options_cls):
        if f.name == name:
            return f
    raise KeyError(f"{options_cls.__module__}.Options has no field {name!r}")


def flag(options_cls, name: str, *short: str, **kwargs) -> typer.models.OptionInfo:
    """The typer option of an Options field: its flag (plus short names) and its help line."""
    f = _field(options_cls, name)
    names = flag_declaration(f)
    check = f.metadata.get("check")
    if check is not None and check.metavar() and "metavar" not in kwargs:
        kwargs["metavar"] = check.metavar()
    return typer.Option(names, *short, help=f.metadata.get("help", ""), **kwargs)


def default(options_cls, name: str):
    """The default of an Options field (what the CLI flag defaults to); ``...`` for a required one."""
    d = _field(options_cls, name).default
    return ... if d is MISSING else d


def cli_type(f: dataclasses.Field) -> object:
    """The type the CLI parses an Options field's flag as: ``bool`` for an on/off field, ``int``/``float`` for
    a plain number, else text (words such as ``auto`` or a list of joints); the Options check the value."""
    check = f.metadata.get("check")
    kind = check.parses_as() if check is not None else str
    if kind is bool:
        return bool
    return kind | None if f.default is None else kind


#: what :func:`task_command` hands a command besides its own parameters (keyword-only in its signature)
GIVEN = ("options", "as_json", "force", "gltf_scale", "gltf_up", "closing_frame", "write")


@dataclasses.dataclass(frozen=True)
class Writer:
    """Writes a report's outputs where the command line put them, as the task's spec declares them (what
    :func:`task_command` gives a command as ``write``): ``write(report)`` writes the ``--output`` one,
    ``write(report, "--playback")`` another; each returns ``{role: (path, what was written)}``."""

    outputs: tuple  # the spec's Output declarations
    paths: Mapping[str, Path | None]  # flag -> the path given
    gltf_scale: str = "auto"
    gltf_up: str = "auto"
    closing_frame: bool | None = None

    def __call__(self, report, flag: str = "--output") -> dict[str, tuple[Path, object]]:
        output = next(o for o in self.outputs if o.flag == flag)
        path = self.paths.get(flag)
        if path is None:
            return {}
        if output.writes == "motion":
            return {role: (target, write_motion(report, role, target, self.gltf_scale, self.gltf_up,
                                                self.closing_frame if output.loop else None))
                    for role, target in output.targets(report, path).items()}
        thing = report.result
        if output.writes == "compressed":
            thing.save(path)
        elif path.suffix.lower() == ".json":  # swings: the JSON document or the compact file
            from ..io.swings_json import swings_document

            write_text(path, json_text(swings_document(thing), indent=1), "swings")
        else:
            from ..swings import encode

            write_text(path, encode(thing), "swings file")
        return {output.role: (path, thing)}


def _parameter(name: str, annotation, default=inspect.Parameter.empty) -> inspect.Parameter:
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation)


def task_command(name: str, into: typer.Typer | None = None) -> Callable:
    """Register ``mocycle <name>`` made from the task's spec (:data:`mocycle.tasks.spec.SPECS`).

    The command function declares what is its own: its input arguments and its plots. This adds one option
    per field of the task's ``Options`` (flag, help, type and default from the field; its ``old_flags`` as
    hidden options read with a deprecation warning), one per output of the spec (``-o/--output`` ...; its
    suffixes checked before any work),
    ``--json``, ``--force`` (when the Options have none) and, for a task that writes motion, ``--gltf-scale``,
    ``--gltf-up`` and for a loop ``--closing-frame``. The function's keyword-only parameters name what of
    these it wants (:data:`GIVEN`, and its outputs by flag: ``output``, ``playback``): ``options`` is the
    task's Options, checked; ``force`` the Options' own when they have one; ``write`` a :class:`Writer` that
    writes the report's outputs as the spec declares them. ``into``: the typer app
    (``mocycle``'s by default)."""
    spec = SPECS[name]

    def decorate(func: Callable) -> Callable:
        summary = " ".join(inspect.cleandoc(func.__doc__ or "").split("\n\n")[0].split())
        if summary != spec.summary:  # the help's first paragraph is the spec's (``mocycle --help`` lists it)
            raise TypeError(f"{name}: the help begins {summary!r}, the spec says {spec.summary!r}")
        own = inspect.signature(func, eval_str=True).parameters
        wanted = [p.name for p in own.values() if p.kind is inspect.Parameter.KEYWORD_ONLY]
        unknown = set(wanted) - {*GIVEN, *(_name(o.flag) for o in spec.outputs)}
        if unknown:
            raise TypeError(f"{func.__name__}: keyword-only parameters {sorted(unknown)} are not given by "
                            f"task_command")
        params = [p.replace(kind=inspect.Parameter.KEYWORD_ONLY) for p in own.values() if p.name not in wanted]
        options_cls = spec.options
        fields = dataclasses.fields(options_cls)
        for o in spec.outputs:
            decls = (o.flag, "-o") if o.flag == "--output" else (o.flag,)
            params.append(_parameter(_name(o.flag), Annotated[Path if o.required else Path | None,
                                                           typer.Option(*decls, help=o.help)],
                                     inspect.Parameter.empty if o.required else None))
        params += [_parameter(f.name, Annotated[cli_type(f), flag(options_cls, f.name)], default(options_cls, f.name))
                   for f in fields]
        olds = [(f, old, f"{f.name}__{old.strip('-').replace('-', '_')}") for f in fields
                for old in f.metadata.get("old_flags", ())]
        params += [_parameter(key, Annotated[str | None, typer.Option(old, hidden=True)], None) for _, old, key in olds]
        params.append(_parameter("as_json", Annotated[bool, typer.Option("--json", help="Print JSON.")], False))
        own_force = "force" not in {f.name for f in fields}
        if own_force and (spec.outputs or any("plot" in p for p in own)):
            params.append(_parameter("force", Annotated[bool, typer.Option("--force", help=FORCE_HELP)], False))
        if spec.writes_motion():
            if any(o.loop for o in spec.outputs):
                params.append(_parameter("closing_frame", Annotated[bool | None, CLOSING_FRAME], None))
            params += [_parameter("gltf_scale", Annotated[str, GLTF_SCALE], "auto"),
                       _parameter("gltf_up", Annotated[str, GLTF_UP], "auto")]
        params.sort(key=lambda p: p.default is not inspect.Parameter.empty)  # typer lists the required first

        @wraps(func)
        def command(**kwargs):
            for f, old, key in olds:
                value = kwargs.pop(key)
                if value is not None:
                    warnings.warn(old_flag_warning(f, old), MocycleWarning, stacklevel=2)
                    if kwargs[f.name] == default(options_cls, f.name):
                        kwargs[f.name] = value
            options = options_cls(**{f.name: kwargs.pop(f.name) for f in fields})
            force = kwargs.get("force", False) if own_force else options.force
            inputs = [v for key in spec.inputs for v in _listed(kwargs.get(key.lstrip("*")))]
            for o in spec.outputs:
                path = kwargs.get(_name(o.flag))
                if o.writes == "motion":
                    check_motion_output(path, inputs, force, o.flag, kwargs["gltf_scale"], kwargs["gltf_up"])
                else:
                    check_output(path, inputs, force, o.suffixes, o.flag)
            write = Writer(spec.outputs, {o.flag: kwargs.get(_name(o.flag)) for o in spec.outputs},
                           kwargs.get("gltf_scale", "auto"), kwargs.get("gltf_up", "auto"), kwargs.get("closing_frame"))
            given = {"options": options, "force": force, "write": write, **kwargs}
            return func(**{k: v for k, v in given.items() if k in own})

        # typer reads a command's parameters from its signature only (docs/architecture.md says why not click's)
        # a function's __signature__ is what inspect (and so typer) reads
        command.__signature__ = inspect.Signature(params)  # type: ignore[attr-defined]  # not on Callable
        command.__annotations__ = {p.name: p.annotation for p in params}
        del command.__wrapped__  # typer reads the signature made here, not the function's
        return (into or app).command(name)(friendly(command))

    return decorate


def _name(flag: str) -> str:
    """The parameter a flag fills (``--input-copy`` -> ``input_copy``)."""
    return flag.lstrip("-").replace("-", "_")


def _listed(value) -> list:
    return [] if value is None else list(value) if isinstance(value, (list, tuple)) else [value]


def print_closing(report, *written: object) -> None:
    """A command's last lines: ``wrote X`` for each file it wrote besides its outputs (its plots; ``None``, one
    not asked for, is passed over), then ``time 2.42 s`` (with the labelled parts when there are several)."""
    for thing in written:
        if thing is not None:
            out.print(f"wrote {escape(thing)}", soft_wrap=True)
    parts = [f"{k} {v:.2f} s" for k, v in report.timings_s.items() if k != "total"]
    out.print(f"  time {report.seconds:.2f} s" + (f" ({', '.join(parts)})" if parts else ""))


def print_json(facts: Mapping, indent: int | None = 2) -> None:
    """Strict JSON on stdout (:func:`json_text`: non-finite numbers as null, and the JSON says which)."""
    print(json_text(facts, indent=indent))


# ------------------------------------------------------------ option parsing
def check_output(path: Path | None, inputs=(), force: bool = False, suffix: str | tuple[str, ...] | None = None,
                 option: str = "-o") -> None:
    """Refuse an output before any work is done: wrong suffix, a folder that is missing or not writable,
    a folder in its place, or one of the ``inputs`` (unless ``force``).  Nothing gets written here."""
    if path is None:
        return
    if suffix is not None:
        suffixes = (suffix,) if isinstance(suffix, str) else tuple(suffix)
        if path.suffix.lower() not in suffixes:
            raise MocycleError(f"{path}: {option} must name a {' or '.join(suffixes)} file")
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        raise MocycleError(f"{path}: {option}: the folder {folder} does not exist")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise MocycleError(f"{path}: {option}: the folder {folder} is not writable")
    if path.is_dir():
        raise MocycleError(f"{path}: {option} names a folder; expected a file")
    for source in inputs:
        if source is not None and _same_file(path, Path(source)):
            if not force:
                raise MocycleError(f"{path}: {option} is the input {source}; pass --force to replace it")


def _same_file(a: Path, b: Path) -> bool:
    try:
        return a.exists() and b.exists() and os.path.samefile(a, b)
    except OSError:
        return False


def check_folder(folder: Path, option: str = "--out") -> None:
    """Refuse an output folder that cannot be made or written, before any work is done."""
    probe = folder
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    if probe.exists() and not probe.is_dir():
        raise MocycleError(f"{folder}: {option}: {probe} is a file, not a folder")
    if not os.access(probe, os.W_OK | os.X_OK):
        raise MocycleError(f"{folder}: {option}: {probe} is not writable")


def write(item, path: Path, **kwargs):
    """:func:`mocycle.io.write`, imported on first use: the command modules stay light for ``--help``."""
    from ..io import write as io_write

    return io_write(item, path, **kwargs)


def read(path, **kwargs):
    """:func:`mocycle.io.read_motion`, imported on first use (see :func:`write`)."""
    from ..io import read_motion

    return read_motion(path, **kwargs)


def write_text(path: Path, text: str | bytes, what: str = "file") -> Path:
    """Write an output through the atomic writer; an OS error becomes one clear MocycleError."""
    from ..io.atomic import atomic_write

    try:
        return atomic_write(path, text)
    except OSError as exc:
        raise MocycleError(f"{path}: cannot write the {what} ({exc.strerror or exc})") from None


# ------------------------------------------------------------ motion outputs (.bvh or .glb)
GLTF_SCALE = typer.Option(
    "--gltf-scale", metavar="<auto|m|cm|mm|in|cmu|METRES>",
    help=".glb outputs: metres per motion unit, a unit name, or auto (the unit that makes the body about 1.7 m).")
GLTF_UP = typer.Option("--gltf-up", metavar="<auto|y|z|-z|...>",
                       help=".glb outputs: the motion's vertical, turned onto glTF's +Y (auto: detected).")
CLOSING_FRAME = typer.Option(
    "--closing-frame/--no-closing-frame",
    help="End the loop with a copy of its first frame (moved on by a cycle with --root motion), as players that "
         "loop over the keys need; default: on for .glb, off for .bvh.")


def check_motion_output(path: Path | None, inputs=(), force: bool = False, option: str = "--output",
                        gltf_scale: str = "auto", gltf_up: str = "auto") -> None:
    """:func:`check_output` for a motion output (.bvh or .glb) and its glTF options, before any work."""
    import importlib.util

    from ..io.gltf import check_options

    check_output(path, inputs, force, MOTION_WRITE_SUFFIXES, option)
    check_options(gltf_scale, gltf_up)
    if path is not None and path.suffix.lower() == ".glb" and importlib.util.find_spec("pygltflib") is None:
        raise MocycleError(f"{path}: writing .glb files needs pygltflib: pip install 'mocycle[gltf]'")


def write_motion(report, role: str, path: Path, gltf_scale: str = "auto", gltf_up: str = "auto",
                 closing_frame: bool | None = None):
    """Write ``report.motions[role]`` to ``path`` (.bvh or .glb) as :func:`mocycle.tasks.clips.for_output`
    says (a .glb loop: clip ``<stem>_loop`` with its closing frame); returns the motion written."""
    from ..io import write
    from ..tasks.clips import for_output

    motion, clip = for_output(report, role, path, closing_frame)
    write(motion, path, clip=clip, gltf_scale=gltf_scale, gltf_up=gltf_up)
    return motion
