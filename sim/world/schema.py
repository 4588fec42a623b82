"""Declarative key schemas on pydantic: a scenario table is a model, each key a field declared
once with its type, default, valid range, unit and meaning; ``validate`` turns the first
``ValidationError`` into the project's one-line message naming the key path.

A field's type is one of the key types below (``Number``, ``Integer``, ``Flag``, ``Text``,
``Vector``, ``Tables``): each checks a raw TOML value and, when it is wrong, says what the key
must be (``must be >= 0.05, got -1``); ``validate`` puts the key path in front
(``robot.mass must be >= 0.05, got -1``). How a model refuses an unknown key is its
``unknown_key`` class method (a "did you mean" hint from the declared keys).

This module lives in ``sim`` so that the world, the port maps, the connectors and the
application's sections share it.
"""

import difflib
import math
from dataclasses import dataclass
from typing import Annotated, ClassVar

from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, ValidationError
from pydantic_core import PydanticCustomError

__all__ = [
    "Flag",
    "Integer",
    "KeyModel",
    "Number",
    "Tables",
    "Text",
    "Vector",
    "check_of",
    "checked",
    "fail",
    "key_path",
    "show",
    "validate",
]


def show(value):
    """A value as the world's messages show it: its repr and its type."""
    if isinstance(value, dict):
        return "a table"
    if isinstance(value, (list, tuple)):
        return f"{list(value)!r} (array)"
    return f"{value!r} ({type(value).__name__})"


def fail(message, sub=""):
    """Raise inside a key type: ``message`` says what the key must be (the path is put in
    front by ``validate``); ``sub`` is appended to the path (``[0][0] (t)``)."""
    raise PydanticCustomError("key", message, {"sub": sub})


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


@dataclass(frozen=True)
class _NumberCheck:
    """The range of a number and how its messages read.

    ``style``: ``"world"`` (``must be >= 0.05, got -1``; a wrong type lists the bounds),
    ``"scenario"`` (``must be >= 1e-05 s, got 1e-06``; a wrong type: ``a finite number``),
    ``"bounds"`` (every failure: ``must be a number in m >= -2 and <= 2, got 5``),
    ``"span"`` (every failure: ``must be a number in 0..1, got 2``)."""

    gt: float | None = None
    ge: float | None = None
    le: float | None = None
    unit: str = ""
    style: str = "world"
    note: str = ""  # why the upper bound (scenario and bounds styles)

    def bounds(self):
        out = [(f"> {self.gt:g}", lambda v: v > self.gt)] if self.gt is not None else []
        out += [(f">= {self.ge:g}", lambda v: v >= self.ge)] if self.ge is not None else []
        out += [(f"<= {self.le:g}", lambda v: v <= self.le)] if self.le is not None else []
        return out

    def __call__(self, value):
        finite = _is_number(value) and math.isfinite(value)
        bounds = self.bounds()
        failed = [text for text, ok in bounds if not (finite and ok(value))]
        if finite and not failed:
            return float(value)
        in_unit = f" in {self.unit}" if self.unit else ""
        texts = [text for text, _ in bounds]
        if self.style == "span":
            lo = self.ge if self.ge is not None else self.gt
            unit = f" {self.unit}" if self.unit else ""
            fail(f"must be a number in {lo:g}..{self.le:g}{unit}, got {value!r}")
        if self.style == "bounds":
            note = self.note if finite and failed[0].startswith("<") else ""
            fail(f"must be a number{in_unit} {' and '.join(texts)}{note}, got {value!r}")
        if self.style == "scenario":
            if not finite:
                span = f", {' and '.join(texts)}" if texts else ""
                fail(f"must be a finite number{in_unit}{span}, got {value!r}")
            unit = f" ({self.unit})" if " " in self.unit else f" {self.unit}" if self.unit else ""
            note = self.note if failed[0].startswith("<") else ""
            fail(f"must be {failed[0]}{unit}{note}, got {value!r}")
        if not finite:
            what = "a number" + in_unit + (" " + " and ".join(texts) if texts else "")
            fail(f"must be {what}, got {show(value)}")
        fail(f"must be {failed[0]}, got {value!r}")


def _bounds(gt=None, ge=None, le=None):
    """The bounds as pydantic's (they are also in the model's JSON schema)."""
    return {k: v for k, v in (("gt", gt), ("ge", ge), ("le", le)) if v is not None}


def Number(*, gt=None, ge=None, le=None, unit="", doc="", style="world", note=""):
    """A finite number (an int is taken as a float) within the bounds."""
    check = _NumberCheck(gt, ge, le, unit, style, note)
    return Annotated[
        float,
        BeforeValidator(check),
        Field(description=doc, json_schema_extra={"unit": unit}, **_bounds(gt, ge, le)),
    ]


def Integer(*, ge, le, unit="", doc="", message=None):
    """An integer (not a bool) within ``ge..le``; ``message`` overrides the text of a failure
    (formatted with ``lo``, ``hi``, ``unit`` and ``value``)."""

    def check(value):
        if _is_int(value) and ge <= value <= le:
            return value
        text = message or "must be an integer in {lo}..{hi}, got {value!r}"
        fail(text.format(lo=ge, hi=le, unit=unit, value=value))

    return Annotated[
        int,
        BeforeValidator(check),
        Field(description=doc, json_schema_extra={"unit": unit}, **_bounds(ge=ge, le=le)),
    ]


def Flag(*, doc="", style="world"):
    """``true`` or ``false``."""

    def check(value):
        if isinstance(value, bool):
            return value
        fail(f"must be true or false, got {show(value) if style == 'world' else repr(value)}")

    return Annotated[bool, BeforeValidator(check), Field(description=doc)]


def Text(*, choices=None, doc="", style="world"):
    """A non-empty string, one of ``choices`` when given."""

    def check(value):
        if style == "world" and (not isinstance(value, str) or not value):
            fail(f"must be a non-empty string, got {show(value)}")
        if choices is not None and value not in choices:
            fail(f"must be one of {', '.join(map(repr, choices))}, got {value!r}")
        if not isinstance(value, str):
            fail(f"must be a string, got {value!r}")
        return value

    extra = {"enum": list(choices)} if choices is not None else None
    return Annotated[str, BeforeValidator(check), Field(description=doc, json_schema_extra=extra)]


def Vector(n, what, *, doc="", style="world", **bounds):
    """An array of ``n`` numbers (``what`` says what it is: ``a point [x, y] in m``), each
    checked as a ``Number(**bounds)``."""
    item = _NumberCheck(**bounds, style=style)

    def check(value):
        if not isinstance(value, (list, tuple)) or len(value) != n:
            fail(f"must be {what}, got {show(value) if style == 'world' else repr(value)}")
        return tuple(checked(item, v, f"[{i}]") for i, v in enumerate(value))

    return Annotated[
        tuple[(float,) * n],
        BeforeValidator(check),
        Field(description=doc, json_schema_extra={"unit": bounds.get("unit", "")}),
    ]


def check_of(key_type):
    """The check of a key type (``Number(...)``, ``Vector(...)``): raw value → value."""
    return next(m.func for m in key_type.__metadata__ if isinstance(m, BeforeValidator))


def checked(check, value, sub):
    """``check(value)``, a failure's path extended by ``sub`` (an item's index)."""
    try:
        return check(value)
    except PydanticCustomError as exc:
        fail(exc.message(), sub=sub + (exc.context or {}).get("sub", ""))


def Tables(message, *, doc=""):
    """An array of tables (``[[room.furniture]]``), each validated by the annotated model;
    ``message`` is what the key must be when it is no array."""

    def check(value):
        if not isinstance(value, list):
            fail(f"must be {message}, got {show(value)}")
        return value

    return BeforeValidator(check), Field(description=doc)


class KeyModel(BaseModel):
    """A table of a scenario: its keys are the fields; anything else is an unknown key."""

    # defer_build: a table's validator is built when a scenario first has the table, so a
    # start-up pays only for the tables its scenario uses.
    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True, defer_build=True)

    #: What a path of this table is called in the unknown-key message.
    label: ClassVar[str] = ""
    #: Report an unknown key before a wrong value (else after: a typo is the likelier
    #: mistake when a value is also wrong, but a wrong value names its key exactly).
    unknown_first: ClassVar[bool] = False

    @classmethod
    def key_names(cls):
        """The table's keys, in declared order (a field's alias where it has one)."""
        return [f.alias or name for name, f in cls.model_fields.items()]

    @classmethod
    def unknown_key(cls, path, key):
        """The message for a key the table does not declare."""
        known = cls.key_names()
        close = difflib.get_close_matches(str(key), known, n=1)
        hint = f" (did you mean {close[0]!r}?)" if close else ""
        return f"{path} is not a known key{hint}; known keys: {', '.join(known)}"

    @classmethod
    def missing_key(cls, path, key, doc):
        """The message for a required key that is not given (``doc``: its description)."""
        return f"{path} is required" + (f": {doc}" if doc else "")


def key_path(prefix, loc):
    """``"room"``, ``("furniture", 0, "size")`` → ``"room.furniture[0].size"``."""
    path = prefix
    for part in loc:
        if isinstance(part, int):
            path += f"[{part}]"
        else:
            path = f"{path}.{part}" if path else str(part)
    return path


def _model_at(model, loc):
    """The model class that holds the last key of ``loc`` (for an unknown key's message)."""
    for part in loc[:-1]:
        if isinstance(part, int):
            continue
        field = model.model_fields.get(part)
        if field is None:
            for f in model.model_fields.values():
                if f.alias == part:
                    field = f
        inner = _inner_model(field.annotation) if field is not None else None
        if inner is None:
            return model
        model = inner
    return model


def _inner_model(annotation):
    if isinstance(annotation, type) and issubclass(annotation, KeyModel):
        return annotation
    for arg in getattr(annotation, "__args__", ()):
        found = _inner_model(arg)
        if found is not None:
            return found
    return None


def message_of(exc, model, prefix):
    """The one-line message of the first error of a ``ValidationError``: key errors in their
    declared order, unknown keys after them (before them with ``model.unknown_first``)."""
    errors = exc.errors(include_url=False)
    errors.sort(key=lambda e: (e["type"] == "extra_forbidden") != model.unknown_first)
    err = errors[0]
    loc = tuple(err["loc"])
    path = key_path(prefix, loc)
    kind = err["type"]
    if kind == "key":
        return f"{path}{err['ctx'].get('sub', '')} {err['msg']}"
    if kind == "extra_forbidden":
        return _model_at(model, loc).unknown_key(path, loc[-1])
    if kind == "missing":
        holder = _model_at(model, loc)
        field = holder.model_fields.get(loc[-1])
        doc = field.description if field is not None else ""
        return holder.missing_key(path, loc[-1], doc)
    if kind in ("model_type", "dict_type", "model_attributes_type"):
        return f"{path or 'the document'} must be a table, got {show(err['input'])}"
    if kind == "value_error":
        # A model validator's relation between keys: its message names the keys.
        text = str(err["ctx"].get("error", err["msg"]))
        return f"{path}.{text}" if path and text[:1].isalpha() else text
    return f"{path}: {err['msg']}, got {err['input']!r}"


def validate(model, table, prefix, error):
    """``model`` validated from ``table`` (None: an empty table); ``error(message)`` raised
    with the path of the first wrong key otherwise."""
    if table is None:
        table = {}
    try:
        return model.model_validate(table)
    except ValidationError as exc:
        raise error(message_of(exc, model, prefix)) from None
