"""One-line scenario errors: :class:`ScenarioError` and the translation of pydantic errors.

Every problem with user input is reported as ``<source>: <dotted.path>: <what is allowed>
(got <value>)``, on one line, followed by ``(and N more problems)`` when there are several.
Validators in :mod:`auvtrack.scenario.schema` raise ``ValueError("field: text")``; the leading
``field`` (dotted, possibly with list indices) is appended to the error location here.
"""
from __future__ import annotations

import re
import types
import typing
from typing import Any, Callable, Iterable

from pydantic import BaseModel, ValidationError

from ..fields import format_value, one_line

__all__ = ["ScenarioError", "format_value", "one_line", "translate"]

# "field: text" or "a.0.b: text" at the start of a validator message
_FIELD_PREFIX = re.compile(r"^((?:[A-Za-z_]\w*|\d+)(?:\.(?:[A-Za-z_]\w*|\d+))*): (.+)$", re.S)


class ScenarioError(ValueError):
    """Invalid scenario input; ``str(err)`` is a single line naming source, field and rule.

    Parameters
    ----------
    message : str
        The message; any newline is collapsed to a space.
    path : str, optional
        Dotted path of the offending field.

    Attributes
    ----------
    path : str
        Dotted path of the offending field (``""`` when the problem is not tied to a field,
        e.g. a missing file or a TOML syntax error).
    """

    def __init__(self, message: str, path: str = "") -> None:
        super().__init__(one_line(message))
        self.path = path


def _unwrap(annotation: Any) -> Any:
    """Strip ``Annotated``/``Optional`` wrappers from a field annotation."""
    while True:
        origin = typing.get_origin(annotation)
        if origin is typing.Annotated:
            annotation = typing.get_args(annotation)[0]
            continue
        if origin in (typing.Union, types.UnionType):
            args = [a for a in typing.get_args(annotation) if a is not type(None)]
            if len(args) == 1:
                annotation = args[0]
                continue
        return annotation


def _union_members(annotation: Any) -> list[type[BaseModel]]:
    origin = typing.get_origin(annotation)
    if origin in (typing.Union, types.UnionType):
        return [a for a in typing.get_args(annotation) if isinstance(a, type) and issubclass(a, BaseModel)]
    return []


def _kind_of(model: type[BaseModel]) -> str | None:
    """The tag of a discriminated union's member: its ``kind`` (controllers) or ``model`` (plants)."""
    for tag in ("kind", "model"):
        field = model.model_fields.get(tag)
        if field is not None and isinstance(field.default, str):
            return field.default
    return None


def _walk(root: type[BaseModel], loc: Iterable[Any]) -> tuple[list[str], Any]:
    """Turn a pydantic ``loc`` into a clean dotted path and the type found at its end.

    The type is a model class, a field annotation, or None when unknown.  Discriminated-union
    tags, which pydantic inserts into ``loc``, are dropped.
    """
    path: list[str] = []
    current: Any = root
    for seg in loc:
        if isinstance(current, type) and issubclass(current, BaseModel):
            path.append(str(seg))
            field = current.model_fields.get(seg) if isinstance(seg, str) else None
            current = _unwrap(field.annotation) if field is not None else None
            members = _union_members(current) if current is not None else []
            if members:
                current = ("union", members)
        elif isinstance(current, tuple) and current[0] == "union":
            match = [m for m in current[1] if _kind_of(m) == seg]
            if match:  # a tag inserted by pydantic: not part of the user's path
                current = match[0]
            else:
                path.append(str(seg))
                current = None
        else:
            path.append(str(seg))
            current = None
    if isinstance(current, tuple):
        current = None
    return path, current


def _model(annotation: Any) -> type[BaseModel] | None:
    return annotation if isinstance(annotation, type) and issubclass(annotation, BaseModel) else None


def _fixed_length(annotation: Any) -> int | None:
    """Number of items of a fixed-length ``tuple[...]`` annotation, else None."""
    if typing.get_origin(annotation) is tuple:
        args = typing.get_args(annotation)
        if Ellipsis not in args:
            return len(args)
    return None


def _other_members_with(root: type[BaseModel], loc: tuple, parent: type[BaseModel] | None) -> list:
    """For a key refused by one member of a discriminated union: [(tag field, this member's tag), (tag
    field, tag) of each other member that has the key, ...]; empty when none has it or no union."""
    if parent is None or len(loc) < 3:
        return []
    path: list = []
    current: Any = root
    for seg in loc[:-2]:  # down to the section holding the union
        if not (isinstance(current, type) and issubclass(current, BaseModel)):
            return []
        field = current.model_fields.get(seg) if isinstance(seg, str) else None
        current = _unwrap(field.annotation) if field is not None else None
        path.append(seg)
    members = _union_members(current) if current is not None else []
    key = loc[-1]
    mine = _kind_of(parent)
    if not members or mine is None:
        return []
    tag = next(t for t in ("kind", "model") if t in parent.model_fields)
    others = [(tag, _kind_of(m)) for m in members if m is not parent and key in m.model_fields and _kind_of(m)]
    return [(tag, mine)] + others if others else []


def _allowed_keys(model: type[BaseModel] | None) -> str:
    if model is None:
        return ""
    return f" (allowed: {', '.join(model.model_fields)})"


def _describe(err: dict, root: type[BaseModel]) -> tuple[str, str]:
    """Return (dotted path, one-line explanation) for one pydantic error dict."""
    etype, ctx, value = err["type"], err.get("ctx") or {}, err.get("input")
    path, _ = _walk(root, err["loc"])
    got = f" (got {format_value(value)})"
    if etype == "extra_forbidden":
        _, parent = _walk(root, err["loc"][:-1])
        owners = _other_members_with(root, err["loc"], _model(parent))
        if owners:  # a key of another kind of the same section (a 6-DOF key with the 5-DOF plant)
            tag, mine = owners[0]
            where = " or ".join(f'{".".join(path[:-1] + [tag])} = "{kind}"' for _, kind in owners[1:])
            return ".".join(path), f"only for {where} (got {format_value(value)} with {tag} \"{mine}\")"
        return ".".join(path), "unknown key" + _allowed_keys(_model(parent))
    if etype == "missing" and err["loc"] and isinstance(err["loc"][-1], int):  # short tuple
        parent_path, ann = _walk(root, err["loc"][:-1])
        n = _fixed_length(ann)
        size = f"{n} items" if n is not None else "more items"
        return ".".join(parent_path), f"must have {size} (got {len(value)})" if hasattr(value, "__len__") \
            else f"must have {size}"
    if etype == "missing":
        return ".".join(path), "required key is missing"
    if etype in ("value_error", "assertion_error"):
        text = one_line(str(ctx.get("error", err.get("msg", ""))))
        m = _FIELD_PREFIX.match(text)
        if m:
            path = path + m.group(1).split(".")
            text = m.group(2)
        return ".".join(path), text
    if etype in ("union_tag_invalid", "union_tag_not_found"):
        tag = str(ctx.get("discriminator", "kind")).strip("'\"") or "kind"  # "kind", or "dist" of a sweep
        if etype == "union_tag_not_found":
            return ".".join(path + [tag]), "required key is missing"
        tags = ctx.get("expected_tags", "")
        return ".".join(path + [tag]), f"unknown {tag} (allowed: {tags}) (got {format_value(ctx.get('tag'))})"
    bounds = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}
    if etype in bounds:
        limit = next(v for k, v in ctx.items() if k in ("gt", "ge", "lt", "le"))
        shown = str(limit) if isinstance(limit, int) else f"{limit:g}" if isinstance(limit, float) else str(limit)
        return ".".join(path), f"must be {bounds[etype]} {shown}" + got
    simple = {
        "finite_number": "must be a finite number",
        "float_type": "must be a number", "float_parsing": "must be a number",
        "int_type": "must be an integer", "int_parsing": "must be an integer",
        "int_from_float": "must be an integer",
        "bool_type": "must be true or false", "bool_parsing": "must be true or false",
        "string_type": "must be a string",
        "tuple_type": "must be an array", "list_type": "must be an array",
        "model_type": "must be a table", "model_attributes_type": "must be a table",
        "dict_type": "must be a table", "is_instance_of": "has the wrong type",
    }
    if etype in simple:
        return ".".join(path), simple[etype] + got
    if etype == "literal_error":
        return ".".join(path), f"must be one of {ctx.get('expected')}" + got
    if etype in ("too_short", "too_long"):
        n = ctx.get("min_length") if etype == "too_short" else ctx.get("max_length")
        actual = ctx.get("actual_length")
        _, ann = _walk(root, err["loc"])
        items = f"{n} item{'' if n == 1 else 's'}"
        if _fixed_length(ann) is not None:  # a fixed-length array: the exact count
            return ".".join(path), f"must have {items} (got {actual})"
        bound = "at least" if etype == "too_short" else "at most"
        return ".".join(path), f"must have {bound} {items} (got {actual})"
    return ".".join(path), one_line(err.get("msg", etype)) + got


def translate(exc: ValidationError, root: type[BaseModel], source: str = "",
              hint: Callable[[str], str] | None = None) -> ScenarioError:
    """Turn a pydantic ``ValidationError`` on ``root`` into a one-line :class:`ScenarioError`.

    Parameters
    ----------
    exc : pydantic.ValidationError
        The validation error.
    root : type of BaseModel
        The model that was validated (used to list allowed keys and drop union tags).
    source : str, optional
        Label of the input (file name, ``<dict>``) put in front of the message.
    hint : callable, optional
        ``hint(path)`` returns a suffix for the message (e.g. the override that set the field).

    Returns
    -------
    ScenarioError
        The first problem, plus ``(and N more problems)`` when there are several.
    """
    errors = exc.errors(include_url=False)
    path, text = _describe(errors[0], root)
    msg = f"{path}: {text}" if path else text
    if hint is not None:
        msg += hint(path)
    if len(errors) > 1:
        n = len(errors) - 1
        msg += f" (and {n} more problem{'s' if n > 1 else ''})"
    return ScenarioError(f"{source}: {msg}" if source else msg, path)
