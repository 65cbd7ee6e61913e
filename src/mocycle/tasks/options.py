"""Task options: frozen dataclasses whose fields carry their help, their allowed values and their default.

Every field is declared with :func:`option`; the dataclass checks every field in ``__post_init__`` (one
place) with the constraint attached to it and stores the value in its normal form (``"3"`` -> ``3``).
:func:`schema` turns an Options class into a JSON-schema-like dict, so a front end (CLI flags, Blender
properties, a web form, a batch runner) can be derived from the same declaration.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Mapping
from dataclasses import MISSING, dataclass, field

from .. import _validate
from ..errors import OptionError

__all__ = ["Choice", "Flag", "Integer", "Options", "Real", "Text", "option", "schema"]


# -- constraints (what a field accepts; each normalises and can describe itself) ------------------------------
class Constraint:
    """What a field accepts, declared once for every front end: called as ``check(name, value)`` it returns the
    value normalised or raises :class:`~mocycle.errors.OptionError`; ``schema()`` describes it (the studio's
    forms, Blender's properties); ``parses_as()`` is the type a text front end (the CLI) reads the value as
    before the check, and ``metavar()`` how it shows the value in help (``None``: its default)."""

    def parses_as(self) -> type:
        return str

    def __call__(self, name: str, value) -> object:
        raise NotImplementedError

    def schema(self) -> dict:
        return {}  # nothing said beyond the field's type and default

    def metavar(self) -> str | None:
        return None


@dataclass(frozen=True)
class Choice(Constraint):
    """One of a few words."""

    choices: tuple[str, ...]

    def metavar(self) -> str | None:
        return f"<{'|'.join(self.choices)}>"  # --method <harmonic|centroid|cut>

    def __call__(self, name: str, value):
        return _validate.choice(name, value, self.choices)

    def schema(self) -> dict:
        return {"type": "string", "enum": list(self.choices)}


@dataclass(frozen=True)
class Integer(Constraint):
    """An integer in ``[low, high]``, or one of ``words`` (mapped to what they stand for)."""

    low: int | None = None
    high: int | None = None
    words: Mapping[str, object] = field(default_factory=dict)
    optional: bool = False  # None is allowed (no value)

    def parses_as(self) -> type:
        return str if self.words else int  # words such as 'auto' are text

    def __call__(self, name: str, value):
        if value is None and self.optional:
            return None
        return _validate.integer(name, value, self.low, self.high, words=self.words)

    def schema(self) -> dict:
        out: dict = {"type": "integer"}
        if self.low is not None:
            out["minimum"] = self.low
        if self.high is not None:
            out["maximum"] = self.high
        if self.words or self.optional:
            alts = [out] + ([{"type": "string", "enum": list(self.words)}] if self.words else [])
            alts += [{"type": "null"}] if self.optional or None in self.words.values() else []
            return {"anyOf": alts}
        return out


@dataclass(frozen=True)
class Real(Constraint):
    """A finite number in an interval (``low_open``/``high_open``: the end is excluded), or one of ``words``."""

    low: float | None = None
    high: float | None = None
    low_open: bool = False
    high_open: bool = False
    words: tuple[str, ...] = ()

    def parses_as(self) -> type:
        return str if self.words else float

    def __call__(self, name: str, value):
        if isinstance(value, str) and value in self.words:
            return value
        try:
            return _validate.real(name, value, self.low, self.high, low_open=self.low_open,
                                  high_open=self.high_open)
        except OptionError as exc:
            if not self.words:
                raise
            words = " or ".join(repr(w) for w in self.words)
            raise OptionError(name, f"must be {words} or {exc.reason.removeprefix('must be ')}") from None

    def schema(self) -> dict:
        out: dict = {"type": "number"}
        if self.low is not None:
            out["exclusiveMinimum" if self.low_open else "minimum"] = self.low
        if self.high is not None:
            out["exclusiveMaximum" if self.high_open else "maximum"] = self.high
        return {"anyOf": [out, {"type": "string", "enum": list(self.words)}]} if self.words else out


@dataclass(frozen=True)
class Flag(Constraint):
    """True or False."""

    def parses_as(self) -> type:
        return bool

    def __call__(self, name: str, value) -> bool:
        if isinstance(value, bool):
            return value
        raise OptionError(name, f"must be True or False; got {value!r}")

    def schema(self) -> dict:
        return {"type": "boolean"}


@dataclass(frozen=True)
class Text(Constraint):
    """Free text (e.g. joint names, a file pattern); ``optional``: None allowed."""

    optional: bool = True

    def __call__(self, name: str, value):
        if value is None and self.optional:
            return None
        if isinstance(value, str) and value.strip():
            return value
        raise OptionError(name, f"must be a non-empty text; got {value!r}")

    def schema(self) -> dict:
        return {"anyOf": [{"type": "string"}, {"type": "null"}]} if self.optional else {"type": "string"}


def option(default=MISSING, help: str = "", check: Constraint | None = None, *, flag: str | None = None,
           old_flags: tuple[str, ...] = ()):
    """A dataclass field of an Options class.

    ``help``: one line for ``--help``, tooltips and forms; ``check``: the constraint (:class:`Choice`,
    :class:`Integer`, :class:`Real`, :class:`Flag`, :class:`Text` or any ``f(name, value) -> value``);
    ``flag``: the CLI flag when it is not ``--`` + the field name with dashes; ``old_flags``: former names of
    the flag, still read, each with a warning that it is deprecated (:func:`old_flag_warning`).
    """
    return field(default=default, metadata={"help": help, "check": check, "flag": flag, "old_flags": old_flags})


def old_flag_warning(f: dataclasses.Field, old: str) -> str:
    """What a front end says when a field is set by one of its ``old_flags``."""
    return f"{old} is deprecated: it is read as {flag_of(f)}, which says the same (use {flag_of(f)})"


@dataclass(frozen=True)
class Options:
    """Base of every task's options: checks every field with its constraint, then :meth:`_check`."""

    def __post_init__(self):
        for f in dataclasses.fields(self):
            check = f.metadata.get("check")
            if check is not None:
                object.__setattr__(self, f.name, check(f.name, getattr(self, f.name)))
        self._check()

    def _check(self) -> None:
        """Checks that involve several fields (override)."""

    def to_dict(self) -> dict:
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping):
        names = {f.name for f in dataclasses.fields(cls)}
        unknown = sorted(set(data) - names)
        if unknown:
            raise OptionError(unknown[0], f"is not an option of {cls.__name__} (options: {', '.join(sorted(names))})")
        return cls(**{k: (tuple(v) if isinstance(v, list) else v) for k, v in data.items()})


def flag_of(f: dataclasses.Field) -> str:
    """The CLI flag of an Options field (``--`` + name with dashes unless the field says otherwise)."""
    return f.metadata.get("flag") or "--" + f.name.replace("_", "-")


def flag_declaration(f: dataclasses.Field) -> str:
    """The CLI declaration of a field's flag: :func:`flag_of`, with its ``--no-`` form for an on/off field that
    is on by default (``--align/--no-align``)."""
    name = flag_of(f)
    return f"{name}/--no-{name[2:]}" if f.default is True else name


def _json_default(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return list(value) if isinstance(value, tuple) else value


def schema(options_cls: type[Options]) -> dict:
    """A JSON-schema-like description of an Options class: one property per field (type, allowed values,
    default, help as ``description``, the CLI flag as ``x-flag``), and the fields without default as
    ``required``."""
    hints = typing.get_type_hints(options_cls)
    props, required = {}, []
    for f in dataclasses.fields(options_cls):
        check = f.metadata.get("check")
        prop = dict(check.schema()) if check is not None and hasattr(check, "schema") else {}
        prop["description"] = f.metadata.get("help", "")
        prop["x-flag"] = flag_of(f)
        hint = hints.get(f.name, "")
        prop["x-python-type"] = hint.__name__ if isinstance(hint, type) else str(hint).replace("typing.", "")
        if f.default is not MISSING:
            prop["default"] = _json_default(f.default)
        else:
            required.append(f.name)
        props[f.name] = prop
    doc = (options_cls.__doc__ or "").strip().splitlines()
    title = f"{options_cls.__module__.rsplit('.', 1)[-1]}.{options_cls.__name__}"
    return {"title": title, "description": doc[0] if doc else "", "type": "object",
            "properties": props, "required": required, "additionalProperties": False}
