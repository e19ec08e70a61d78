"""Validation layer 1: pydantic errors rewritten as ``key.path: what is wrong (got X); allowed``.

Every line names the dotted key path of the bad key as written in the case file (list indices
included, discriminated-union tags such as ``box`` removed), the bad value and what is
allowed: the bounds pydantic reports, the allowed kinds of a ``kind:`` key, the allowed keys of
a section for an unknown key, and a "did you mean" for misspelt keys, kinds and names. A key
that has moved to another section (:data:`MOVED_KEYS`) is told where it goes now.
"""

from __future__ import annotations

import difflib
import re
import types
from typing import Annotated, Any, Literal, Union, get_args, get_origin

from pydantic import BaseModel, ValidationError

from thermodem.models import registry


def suggest(name: str, choices: list[str]) -> str | None:
    """The closest choice to ``name`` (the same but for capitals, spelling, or a choice
    starting with it), if any. Names stay case-sensitive: only the suggestion ignores case
    ('EPSD': did you mean 'epsd'?)."""
    name = str(name)
    same = [c for c in choices if c.casefold() == name.casefold()]
    if same:
        return same[0]
    folded = {c.casefold(): c for c in choices}
    close = difflib.get_close_matches(name.casefold(), list(folded), n=1, cutoff=0.6)
    if close:
        return folded[close[0]]
    starts = [c for c in choices if c.startswith(name) or name.startswith(c)]
    return starts[0] if len(starts) == 1 else None


def _hint(name: str, choices: list[str]) -> str:
    best = suggest(name, choices)
    if best is None and ALIASES.get(str(name).casefold()) in choices:
        best = ALIASES[str(name).casefold()]
    return f" (did you mean {best!r}?)" if best else ""


#: A number followed by a unit ('1e-5 s', '300K', '10 MPa', '25 °C'): units are not read.
_WITH_UNIT = re.compile(
    r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([^\d\s.,;:+\-*()][^;]*?)\s*$"
)


def unit_hint(value: Any) -> str:
    """'; ...' telling that a string such as '1e-5 s' is a number with a unit, which a case
    does not read (SI units throughout; °C given in kelvin), or '' for any other value."""
    m = _WITH_UNIT.match(value) if isinstance(value, str) else None
    if m is None:
        return ""
    try:  # '3e2' (YAML 1.1 reads a number without a dot as a string) is a number
        float(value)
        return ""
    except ValueError:
        pass
    number, unit = m.group(1), m.group(2).strip()
    if unit.replace(" ", "") in ("°C", "ºC", "degC", "C", "celsius", "Celsius"):
        kelvin = float(number) + 273.15
        return (
            f"; {value.strip()!r} is a temperature in °C with its unit: temperatures are "
            f"numbers in kelvin, without a unit: {kelvin:g} ({number} °C)"
        )
    return (
        f"; {value.strip()!r} is a number with a unit ({unit}): units are not read, every value "
        "is a plain number in SI units (m, s, kg, Pa, K, W), e.g. 1.0e-5 for 10 µs, 1.0e7 for "
        "10 MPa"
    )


_GAS_KEYS = "thermal_conductivity, specific_heat, dynamic_viscosity, heat_capacity_ratio, "
_GAS_KEYS += "mean_free_path or pressure, temperature, molecular_diameter"

#: Keys that moved: (where they were given, key) -> where they go now. ``model``: among the
#: parameters of any model choice (``thermal.direct_conduction: {model: ..., KEY: ...}``);
#: ``case``: at the top level of the case.
MOVED_KEYS: dict[tuple[str, str], str] = {
    ("model", "gas"): "the interstitial gas is no longer a model parameter: give it once for "
    f"the case in the section thermal.gas ({_GAS_KEYS}), which every model that needs a gas "
    "reads",
    ("model", "fluid_conductivity"): "the fluid conductivity is now that of the case's "
    "interstitial gas: give it as thermal.gas.thermal_conductivity, which every model that "
    "needs a gas reads",
    ("case", "gas"): f"the interstitial gas is the section thermal.gas ({_GAS_KEYS})",
}


_MPI = (
    "a run on several MPI ranks is started by the launcher, mpiexec -n P thermodem run CASE "
    "--output DIR, and the domain is cut between the ranks automatically (docs/mpi.md): no "
    "case key sets it"
)
_THREADS = "the threads are an option of the command line, thermodem run CASE --threads N"
_OUTPUT_DIRECTORY = (
    "the output directory is given on the command line, thermodem run CASE --output DIR"
)
#: Keys of other codes and of the command line, in any section -> what to write instead
#: (the settings of a run, not of a case, and names LIGGGHTS or Lethe users bring along).
COMMAND_LINE_KEYS: dict[str, str] = {
    **dict.fromkeys(
        ("processors", "nprocs", "num_procs", "mpi", "ranks", "partitions", "decomposition"),
        _MPI,
    ),
    **dict.fromkeys(("threads", "num_threads", "nthreads", "omp_num_threads"), _THREADS),
    **dict.fromkeys(
        ("directory", "output_directory", "output_dir", "dir", "folder", "output_path"),
        _OUTPUT_DIRECTORY,
    ),
}
#: Other codes' short names of keys -> the key here (used when no spelling is close).
ALIASES: dict[str, str] = {
    "dt": "time_step",
    "delta_t": "time_step",
    "t_end": "end_time",
    "tend": "end_time",
    "kn": "stiffness",
    "k_n": "stiffness",
}


def _moved(key: str, parent: _Where | None) -> str | None:
    from thermodem.config.schema import Case
    from thermodem.geometry.walls import _WallBase
    from thermodem.state.materials import Material

    if parent is None:
        return None
    if parent.family is not None:
        if key in Material.model_fields:
            return (
                f"{key} is a material property, not a parameter of the model: give it as "
                f"materials.NAME.{key} (the model reads it from the materials of each pair)"
            )
        return MOVED_KEYS.get(("model", key))
    if parent.tp is Case:
        return MOVED_KEYS.get(("case", key))
    if key == "temperature" and isinstance(parent.tp, type) and issubclass(parent.tp, _WallBase):
        return (
            "a wall's temperature is its thermal condition: thermal: {kind: fixed, "
            "temperature: T} (T in K, a table [[t, T], ...] or an expression of t)"
        )
    return COMMAND_LINE_KEYS.get(key.casefold()) if isinstance(key, str) else None


# ---------------------------------------------------------------- types along a key path
def _unwrap(tp: Any) -> Any:
    while get_origin(tp) is Annotated:
        tp = get_args(tp)[0]
    return tp


def _is_model(tp: Any) -> bool:
    return isinstance(tp, type) and issubclass(tp, BaseModel)


def _members(tp: Any) -> list[Any]:
    """Non-None members of a union (or [tp])."""
    tp = _unwrap(tp)
    if get_origin(tp) in (Union, types.UnionType):
        out: list[Any] = []
        for arg in get_args(tp):
            if arg is type(None):
                continue
            out += _members(arg)
        return out
    return [tp]


def _kinds(model: type[BaseModel]) -> list[str]:
    field = model.model_fields.get("kind")
    if field is None:
        return []
    ann = _unwrap(field.annotation)
    return [str(a) for a in get_args(ann)] if get_origin(ann) is Literal else []


def _tagged(members: list[Any]) -> dict[str, type[BaseModel]]:
    """kind value -> model for a union of models with a ``kind`` literal."""
    table: dict[str, type[BaseModel]] = {}
    for m in members:
        if _is_model(m):
            for k in _kinds(m):
                table[k] = m
    return table


def _choice_params(family: str, value: Any) -> type[BaseModel] | None:
    name = value.get("model") if isinstance(value, dict) else value
    if not isinstance(name, str):
        return None
    try:
        return registry.get(family, name).params
    except KeyError:
        return None


class _Where:
    """What the walk knows at one point of the key path."""

    def __init__(self, tp: Any, value: Any, family: str | None = None) -> None:
        self.tp = tp
        self.value = value
        self.family = family  # set when tp is a model choice of this registry family


def walk(loc: tuple[Any, ...], data: Any) -> tuple[list[str], _Where | None]:
    """(display path, type information at the end of ``loc``) for an error location.

    Drops pydantic's union tags and ``function-...`` entries from the path. The type
    information is None where the walk cannot follow (then only the path is used).
    """
    from thermodem.config.schema import Case, ModelChoice

    path: list[str] = []
    where: _Where | None = _Where(Case, data)
    for elem in loc:
        if isinstance(elem, str) and elem.startswith("function-"):
            continue
        if where is None:
            path.append(str(elem))
            continue
        tp, value = where.tp, where.value
        members = _members(tp)
        tags = _tagged(members)
        if len(tags) > 1:
            is_dict = isinstance(value, dict)
            if (
                isinstance(elem, str)
                and elem in tags
                and (not (is_dict and elem in value) or (is_dict and value.get("kind") == elem))
            ):
                where = _Where(tags[elem], value)  # a union tag: not part of the case file
                continue
            kind = value.get("kind") if isinstance(value, dict) else None
            tp = tags.get(kind) if isinstance(kind, str) else None
        elif members:
            tp = members[0]
        path.append(str(elem))
        child = None
        if isinstance(value, dict):
            child = value.get(elem)
        elif isinstance(value, list | tuple) and isinstance(elem, int) and elem < len(value):
            child = value[elem]
        if where.family is not None:
            params = _choice_params(where.family, value)
            field = params.model_fields.get(elem) if params is not None else None
            where = _Where(field.annotation, child) if field is not None else None
            continue
        if tp is ModelChoice or (isinstance(elem, str) and elem in registry.FAMILIES):
            where = _Where(None, child, family=str(elem))
            continue
        if _is_model(tp):
            field = tp.model_fields.get(str(elem))
            where = _Where(field.annotation, child) if field is not None else None
            if field is not None and str(elem) in registry.FAMILIES:
                where.family = str(elem)
            continue
        origin = get_origin(_unwrap(tp))
        args = get_args(_unwrap(tp))
        if origin is dict and len(args) == 2:
            where = _Where(args[1], child)
        elif origin is list and args:
            where = _Where(args[0], child)
        elif origin is tuple and args:
            if len(args) == 2 and args[1] is Ellipsis:
                where = _Where(args[0], child)
            elif isinstance(elem, int) and elem < len(args):
                where = _Where(args[elem], child)
            else:
                where = None
        else:
            where = None
    return path, where


def _allowed_keys(where: _Where | None) -> list[str] | None:
    if where is None:
        return None
    if where.family is not None:
        params = _choice_params(where.family, where.value)
        return None if params is None else ["model", *params.model_fields]
    members = _members(where.tp)
    tags = _tagged(members)
    if len(tags) > 1 and isinstance(where.value, dict):
        model = tags.get(where.value.get("kind"))
        return list(model.model_fields) if model else None
    if len(members) == 1 and _is_model(members[0]):
        return list(members[0].model_fields)
    return None


def _kinds_at(where: _Where | None) -> list[str]:
    if where is None:
        return []
    return list(_tagged(_members(where.tp)))


# ------------------------------------------------------------------------------ messages
def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 80 else text[:77] + "..."


_UNKNOWN_NAME = re.compile(
    r"unknown (?:[\w ]+ )?'([^']*)'(?:; did you mean '[^']*'\?)?[;,]? allowed: (.*)$"
)


def _improve_named(msg: str) -> str:
    """'unknown X 'n' allowed: a, b' -> '...; allowed: a, b' plus a did-you-mean when missing."""
    msg = re.sub(r"'( allowed: )", r"';\1", msg)
    m = _UNKNOWN_NAME.search(msg)
    if m and "did you mean" not in msg:
        choices = [c.strip() for c in m.group(2).split(",")]
        best = suggest(m.group(1), choices)
        if best:
            msg += f" (did you mean {best!r}?)"
    return msg


def format_error(err: dict[str, Any], data: Any) -> str:
    """One line for one pydantic error."""
    loc = tuple(err["loc"])
    kind = err["type"]
    msg = err["msg"].removeprefix("Value error, ").removeprefix("Assertion failed, ")
    value = err.get("input")
    ctx = err.get("ctx") or {}
    path, where = walk(loc, data)
    dotted = ".".join(path)
    if kind == "extra_forbidden":
        key = path[-1] if path else "?"
        parent_path, parent = walk(loc[:-1], data)
        allowed = _allowed_keys(parent)
        text = f"{dotted}: unknown key"
        moved = _moved(key, parent)
        if moved:
            text += f" (got {_shown(value)}): {moved}"
        if allowed:
            text += f"{_hint(key, allowed)}; allowed keys: {', '.join(allowed)}"
        return text
    if kind == "union_tag_invalid":
        expected = re.findall(r"'([^']*)'", str(ctx.get("expected_tags", "")))
        tag = str(ctx.get("tag", ""))
        return (
            f"{dotted}.kind: unknown kind {tag!r}{_hint(tag, expected)}; allowed: "
            f"{', '.join(expected)}"
        )
    if kind == "union_tag_not_found":
        allowed = _kinds_at(walk(loc, data)[1])
        extra = f"; allowed: {', '.join(allowed)}" if allowed else ""
        return f"{dotted}.kind: missing (it selects the type of this entry){extra}"
    if kind == "missing":
        if path and path[-1].isdigit():
            parent = ".".join(path[:-1])
            return f"{parent}: too few values, item {path[-1]} is missing (got {_shown(value)})"
        return f"{dotted}: required key is missing"
    if kind == "literal_error":
        expected = re.findall(r"'([^']*)'", str(ctx.get("expected", "")))
        best = suggest(str(value), expected) if expected else None
        hint = f"; did you mean {best!r}?" if best else ""
        return f"{dotted}: {msg} (got {_shown(value)}{hint})"
    if kind == "too_long" and "max_length" in ctx:
        return f"{dotted}: at most {ctx['max_length']} values allowed (got {_shown(value)})"
    if kind == "too_short" and "min_length" in ctx:
        return f"{dotted}: at least {ctx['min_length']} values needed (got {_shown(value)})"
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        # 'Input should be a valid dictionary or instance of SimulationSettings': the class
        # name means nothing in a case file; say what the key holds instead
        keys = _allowed_keys(where)
        kinds = _kinds_at(where)
        allowed = f"; allowed keys: {', '.join(keys)}" if keys else ""
        if not keys and kinds:
            allowed = f" with a kind: {', '.join(kinds)}"
        return f"{dotted}: should be a mapping of keys (key: value){allowed} (got {_shown(value)})"
    if kind == "union_type":  # (from _collapse_unions: the value fits no member)
        return f"{dotted}: {msg} (got {_shown(value)})"
    if err.get("or_list"):  # a number out of bounds where a list of such numbers also fits
        msg = re.sub(r"^Input should be ", "must be ", msg)
        return f"{dotted}: {msg} (got {_shown(value)}), or {err['or_list']}"
    if kind == "tuple_type":
        # 'Input should be a valid tuple': a case file has lists
        tp = _unwrap(where.tp) if where is not None else None
        args = [a for a in get_args(tp) if a is not Ellipsis] if tp is not None else []
        fixed = tp is not None and get_origin(tp) is tuple and Ellipsis not in get_args(tp)
        count = f"{len(args)} " if fixed and args else ""
        numbers = all(_unwrap(a) is float for a in args)
        example = ", e.g. [0.0, 0.0, 1.0]" if fixed and len(args) == 3 and numbers else ""
        return f"{dotted}: should be a list of {count}values{example} (got {_shown(value)})"
    if kind == "list_type":
        if isinstance(value, dict):
            return (
                f"{dotted}: should be a list, one entry per item (lines starting with '- ', or "
                f"[...]); got a mapping {_shown(value)}: put '- ' before its first key"
            )
        return f"{dotted}: should be a list [...] (got {_shown(value)})"
    msg = _improve_named(msg)
    # messages raised by model validators carry their own key path ('walls.0.material: ...')
    own = re.match(r"^([A-Za-z_][\w]*(?:\.[\w]+)*): ", msg)
    if own and "." in own.group(1) and (not dotted or own.group(1).startswith(dotted)):
        return msg
    # ... or the key of the section they check ('radii: 3 values for 4 positions')
    keys = _allowed_keys(where) or []
    if own and dotted and own.group(1).split(".")[0] in keys:
        return f"{dotted}.{msg}"
    # the value, unless the message already quotes it ('..., got -1.0'; a bare 'greater than
    # 0' does not: that 0 is the bound)
    quoted = re.search(r"\bgot\b", msg) is not None and repr(value) in msg
    shown = "" if isinstance(value, dict | list) or quoted else f" (got {_shown(value)})"
    if isinstance(value, list) and kind in ("float_type", "int_type"):
        shown = f" (got the list {_shown(value)}: one number is expected here)"
    if kind in ("float_parsing", "int_parsing"):
        shown += unit_hint(value)
    return f"{dotted}: {msg}{shown}" if dotted else f"{msg}{shown}"


_MEMBER_TAG = re.compile(r"^(float|int|str|bool|none|constrained-\w+|[\w.]+\[.*\])$")
_TYPE_ERRORS = re.compile(r"_(type|parsing)$")
_SCALAR_TAGS = {"float": "a number", "int": "an integer", "str": "a string",
                "bool": "true or false", "none": "null"}  # fmt: skip
_COUNTS = {2: "two", 3: "three", 4: "four", 6: "six"}


def _tag_base(tag: str) -> str:
    """'float' of 'constrained-float'; 'tuple' of 'tuple[float, float]'."""
    return tag.removeprefix("constrained-").split("[", 1)[0]


def _tag_items(tag: str) -> list[str]:
    """The top-level member types of 'tuple[a, b, c]' or 'list[a]'."""
    inner = tag[tag.index("[") + 1 : -1] if "[" in tag else ""
    items, depth, start = [], 0, 0
    for i, ch in enumerate(inner):
        depth += ch == "["
        depth -= ch == "]"
        if ch == "," and depth == 0:
            items.append(inner[start:i].strip())
            start = i + 1
    if inner:
        items.append(inner[start:].strip())
    return items


def _describe_tag(tag: str) -> str:
    """What a member of a union of plain types takes, in case-file words: 'a number', 'a
    list of three numbers', 'a list of rows of two numbers'."""
    base = _tag_base(tag)
    if base in _SCALAR_TAGS:
        return _SCALAR_TAGS[base]
    items = _tag_items(tag)
    numbers = bool(items) and all(_tag_base(i) in ("float", "int") for i in items)
    if base == "tuple" and items and "..." not in items:
        count = _COUNTS.get(len(items), str(len(items)))
        return f"a list of {count} {'numbers' if numbers else 'values'}"
    if base in ("list", "tuple") and len(items) == 1 and _tag_base(items[0]) == "tuple":
        row = _tag_items(items[0])
        if row and all(_tag_base(i) in ("float", "int") for i in row):
            return f"a list of rows of {_COUNTS.get(len(row), str(len(row)))} numbers"
    if base in ("list", "tuple"):
        return "a list of numbers" if numbers else "a list"
    return "a mapping" if base == "dict" else base


def _or_list(tag: str, others: list[str]) -> str | None:
    """', or a list of three such values' for a number refused by its bounds when the union
    also takes a list of such numbers (spacing: 0.001 or [0.001, 0.001, 0.002])."""
    if _tag_base(tag) not in ("float", "int"):
        return None
    for other in others:
        items = _tag_items(other)
        if _tag_base(other) in ("tuple", "list") and items and items[0] == tag:
            count = len(items) if "..." not in items and _tag_base(other) == "tuple" else 0
            return f"a list of {_COUNTS.get(count, str(count)) + ' ' if count else ''}such values"
    return None


def _member_tag_at(loc: tuple[Any, ...], data: Any) -> int:
    """Index in ``loc`` of the tag pydantic adds for a member of a union of plain types
    (``float``, ``list[tuple[float, float]]``, ``str``), -1 if none: a string element that is
    not a key of the data at that point."""
    value = data
    for k, elem in enumerate(loc):
        if isinstance(elem, str) and _MEMBER_TAG.match(elem):
            if not (isinstance(value, dict) and elem in value):
                return k
        if isinstance(value, dict):
            value = value.get(elem)
        elif isinstance(value, list | tuple) and isinstance(elem, int) and elem < len(value):
            value = value[elem]
        else:
            value = None
    return -1


def _collapse_unions(errors: list[dict[str, Any]], data: Any) -> list[dict[str, Any]]:
    """One error per value given to a union of plain types (``temperature: 300``, a table or
    an expression): the member that accepted the value's type and refused its content
    (``temperature: .inf`` -> 'should be a finite number'), without the member tags; when
    every member refused the type, all of them (the value fits none)."""
    groups: dict[tuple[Any, ...], list[tuple[int, dict[str, Any]]]] = {}
    out: list[dict[str, Any]] = []
    for err in errors:
        loc = tuple(err["loc"])
        k = _member_tag_at(loc, data)
        if k < 0:
            out.append(err)
            continue
        groups.setdefault(loc[:k], []).append((k, err))
    for members in groups.values():
        content = [(k, e) for k, e in members if not _TYPE_ERRORS.search(e["type"])]
        tags = list(dict.fromkeys(str(e["loc"][k]) for k, e in members))
        if not content:  # the value fits no member: one line saying what each takes
            k, err = members[0]
            taken = list(dict.fromkeys(_describe_tag(t) for t in tags))
            alternatives = ", ".join(taken[:-1]) + f" or {taken[-1]}" if len(taken) > 1 else ""
            msg = f"should be {alternatives or taken[0]}"
            out.append({**err, "loc": tuple(err["loc"])[:k], "type": "union_type", "msg": msg})
            continue
        if isinstance(members[0][1].get("input"), int | float) and len(content) > 1:
            # a number refused by a number member and by a name member (substeps: 2.5, an
            # integer or 'auto'): the number member's line, with the names as alternatives
            names = [e for _, e in content if e["type"] == "literal_error"]
            numbers = [(k, e) for k, e in content if e["type"] != "literal_error"]
            if names and numbers:
                expected = re.findall(r"'([^']*)'", str((names[0].get("ctx") or {}).get(
                    "expected", "")))  # fmt: skip
                k, err = numbers[0]
                loc = tuple(err["loc"])
                alternatives = " or ".join(repr(x) for x in expected)
                out.append({**err, "loc": loc[:k] + loc[k + 1 :], "or_list": alternatives})
                continue
        for k, err in content:
            loc = tuple(err["loc"])
            tag = str(loc[k])
            others = [t for t in tags if t != tag]
            extra = _or_list(tag, others)
            if err["type"] == "literal_error" and any(
                _tag_base(t) in ("float", "int") for t in others
            ):  # a name refused where a number fits too (cylinder_radius: 2.0 or 'dai2019')
                err = {**err, "msg": err["msg"].replace("Input should be ", "should be a "
                                                        "number or one of ", 1)}  # fmt: skip
            out.append({**err, "loc": loc[:k] + loc[k + 1 :], "or_list": extra})
    return out


def format_validation_error(exc: ValidationError, data: Any = None) -> str:
    """All errors of ``exc``, one line each (``data``: the input, for exact key paths)."""
    lines = [format_error(err, data) for err in _collapse_unions(exc.errors(), data)]
    return "\n".join(dict.fromkeys(lines))
