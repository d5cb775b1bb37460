"""Declared options of the contact models: name, type, range, default, one line of help.

Every contact model declares its options once, next to the model, as a mapping name -> :class:`Option`
(made with :func:`declare`)::

    options = declare(
        Option("nx", int, 20, "elements per strip (along x)", minimum=1, maximum=2000),
        Option("traction_bound", str, "elliptic", "traction bound", choices=("elliptic", "parabolic")),
    )

and checks what it is given with :func:`validate_options`, which returns the options merged with the
defaults. The same declaration lets a front end (the ``wheelrail`` case loader) validate a case's
``[solver]`` table before any work and list the options (``wheelrail models``). Adding an option is one
more ``Option(...)`` line in the model's declaration.

Values are checked as they come from a TOML file or Python: ``int`` accepts integers (not booleans,
not 3.0), ``float`` accepts finite integers and floats, ``str`` strings, ``bool`` booleans, ``dict`` a
mapping (checked further by ``check`` if given); ``allow_none`` accepts ``None`` too.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import types
import typing
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

_TYPE_NAMES = {
    int: "an integer",
    float: "a finite number",
    str: "a string",
    bool: "true or false",
    dict: "a table",
    tuple: "a list",
}


class OptionError(ValueError):
    """A model option is unknown or has a bad value.

    Attributes:
        model: the model's name.
        key: the option's name (dotted for nested options, e.g. ``model_options.fastsim.nx``).
        value: the value given.
        expected: what was expected, as words ("an integer >= 1", "one of 'a', 'b'").
    """

    def __init__(self, model: str, key: str, value: Any, expected: str, *, unknown: bool = False):
        self.model, self.key, self.value, self.expected, self.unknown = model, key, value, expected, unknown
        if unknown:
            super().__init__(f"unknown {model} option {key!r} = {value!r}; allowed: {expected}")
        else:
            super().__init__(f"{model} option {key!r} = {value!r}: expected {expected}")


@dataclass(frozen=True)
class Option:
    """One option of a contact model.

    Attributes:
        name: the key in the options mapping (and in a case file's ``[solver]`` table).
        type: int, float, str, bool, tuple (a list) or dict (a table).
        default: the value used when the option is not given.
        help: one line saying what it does (with its unit).
        minimum, maximum: inclusive bounds of a number (None: unbounded).
        exclusive_minimum, exclusive_maximum: the bound itself is not allowed (``> minimum``, ``< maximum``).
        choices: the allowed values of a string option.
        allow_none: ``None`` is a value (the default "not set"; a TOML file cannot give it: omit the key).
        check: for a ``dict`` option, a function ``(value, key) -> None`` raising OptionError.
    """

    name: str
    type: type
    default: Any
    help: str
    minimum: float | None = None
    maximum: float | None = None
    exclusive_minimum: bool = False
    exclusive_maximum: bool = False
    choices: tuple | None = None
    allow_none: bool = False
    check: Callable[[Mapping, str], None] | None = None

    def expected(self) -> str:
        """What a valid value is, in words (used in messages and listings)."""
        if self.choices is not None:
            text = "one of " + ", ".join(repr(c) for c in self.choices)
        else:
            text = _TYPE_NAMES[self.type]
            low = None if self.minimum is None else f"{'>' if self.exclusive_minimum else '>='} {self.minimum:g}"
            high = None if self.maximum is None else f"{'<' if self.exclusive_maximum else '<='} {self.maximum:g}"
            if low and high and not (self.exclusive_minimum or self.exclusive_maximum):
                text += f" from {self.minimum:g} to {self.maximum:g}"
            elif low and high:
                text += f" {low} and {high}"
            elif low or high:
                text += f" {low or high}"
        return text

    def validate(self, value: Any, model: str, key: str | None = None) -> Any:
        """The value converted to the option's type (an int given for a float becomes a float).

        Raises:
            OptionError: naming the model, the key, the value and what was expected.
        """
        key = key or self.name

        def bad() -> OptionError:
            return OptionError(model, key, value, self.expected())

        if value is None:
            if self.allow_none:
                return None
            raise bad()
        if self.type is bool:
            if not isinstance(value, bool):
                raise bad()
            return value
        if self.type is str:
            if not isinstance(value, str) or (self.choices is not None and value not in self.choices):
                raise bad()
            return value
        if self.type is tuple:
            if not isinstance(value, (list, tuple)):
                raise bad()
            return tuple(value)
        if self.type is dict:
            if not isinstance(value, Mapping):
                raise bad()
            if self.check is not None:
                self.check(value, key)
            return value
        if isinstance(value, bool) or not isinstance(value, numbers.Real):
            raise bad()
        if self.type is int:
            if not isinstance(value, numbers.Integral):
                raise bad()
            value = int(value)
        else:
            value = float(value)
            if not math.isfinite(value):
                raise bad()
        if self.minimum is not None and (value < self.minimum or (self.exclusive_minimum and value == self.minimum)):
            raise bad()
        if self.maximum is not None and (value > self.maximum or (self.exclusive_maximum and value == self.maximum)):
            raise bad()
        return value

    def describe(self) -> str:
        """One line for listings: ``name  type/range, default  help``."""
        if self.default is None:
            default = "not set"
        elif isinstance(self.default, bool):
            default = "true" if self.default else "false"  # as in TOML
        else:
            default = repr(self.default)
        return f"{self.name} ({self.expected()}; default {default}): {self.help}"


def declare(*options: Option) -> dict[str, Option]:
    """A model's declaration: name -> Option, in the order given (names must be unique)."""
    declared = {o.name: o for o in options}
    if len(declared) != len(options):
        raise ValueError("declare: duplicate option names")
    for option in options:
        if option.default is not None or not option.allow_none:
            option.validate(option.default, "declare", option.name)
    return declared


def declare_dataclass(cls: type, details: Mapping[str, Mapping]) -> dict[str, Option]:
    """A declaration for an options dataclass: type and default from each field, help and range from ``details``.

    For models whose options are a frozen dataclass (``fea.model.FeaOptions``), so the defaults keep one home.
    ``details`` maps every field name to the keyword arguments of :class:`Option` other than name, type and
    default (at least ``help``); a field without details raises (a new field must be declared).
    """
    hints = typing.get_type_hints(cls)
    options = []
    for f in dataclasses.fields(cls):
        if f.name not in details:
            raise ValueError(f"declare_dataclass: field {cls.__name__}.{f.name} has no declared details")
        tp, allow_none = hints[f.name], False
        if typing.get_origin(tp) in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(tp) if a is not type(None)]
            tp, allow_none = args[0], len(args) < len(typing.get_args(tp))
        options.append(Option(f.name, tp, f.default, allow_none=allow_none, **details[f.name]))
    return declare(*options)


def defaults(declared: Mapping[str, Option]) -> dict:
    """The defaults of a declaration: name -> default."""
    return {name: option.default for name, option in declared.items()}


def validate_options(declared: Mapping[str, Option], options: Mapping | None, model: str, prefix: str = "") -> dict:
    """Check ``options`` against a model's declaration and merge them with the defaults.

    Args:
        declared: the model's declaration (:func:`declare`).
        options: the options given (None or {}: all defaults).
        model: the model's name (for messages).
        prefix: dotted key prefix for nested options (messages name ``prefix + name``).

    Raises:
        OptionError: an unknown option, or a value of the wrong type or out of range.
    """
    merged = defaults(declared)
    if not options:
        return merged
    if not isinstance(options, Mapping):
        raise OptionError(model, prefix.rstrip(".") or "options", options, "a table of options")
    for name, value in options.items():
        if name not in declared:
            raise OptionError(model, f"{prefix}{name}", value, ", ".join(declared) or "none", unknown=True)
        merged[name] = declared[name].validate(value, model, f"{prefix}{name}")
    return merged
