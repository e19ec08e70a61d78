"""Reading a case file, with errors that name the key path, the bad value and what is allowed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from thermodem.config.messages import format_validation_error
from thermodem.config.planar import validation_context
from thermodem.config.schema import Case
from thermodem.errors import ConfigError
from thermodem.state.materials import STORED_CASE_KEY


def _format_validation_error(exc: ValidationError, data: Any = None) -> str:
    return format_validation_error(exc, data)


class _UniqueKeyLoader(yaml.SafeLoader):
    """A safe loader that refuses duplicate keys (PyYAML would keep the last one silently).
    Merge keys (``<<: *name``) are YAML's own: the merged keys may be given again (the value
    written beside ``<<`` wins), only a key written twice in the same mapping is refused."""


MERGE_TAG = "tag:yaml.org,2002:merge"


def _kind_of(key: Any) -> str:
    if key is None:
        return "null (no name)"
    return f"the {'boolean' if isinstance(key, bool) else 'number'} {key!r}"


def _construct_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False):  # noqa: ANN202
    seen: dict[Any, Any] = {}
    for key_node, _ in node.value:
        if key_node.tag == MERGE_TAG:  # '<<' (no constructor of its own: merged below)
            continue
        key = loader.construct_object(key_node, deep=deep)
        try:
            hash(key)
        except TypeError:  # ('? [a, b]': a list as a key ended in a TypeError traceback)
            shape = "list" if isinstance(key_node, yaml.SequenceNode) else "mapping"
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"a key that is a {shape} ('? [...]' or '? {{...}}'); allowed: keys that are names",
                key_node.start_mark,
            ) from None
        if (key is None or isinstance(key, bool | int | float)) and isinstance(
            key_node, yaml.ScalarNode
        ):
            # (a material named on, yes, no or 1: YAML 1.1 reads the key as a boolean or a
            # number, and the message said "materials.1.[key]: ... (got True)")
            raise yaml.constructor.ConstructorError(
                None,
                None,
                f"the key {key_node.value!r} is read by YAML as "
                f"{_kind_of(key)}, not a name; "
                f"allowed: a name, quoted: '{key_node.value}':",
                key_node.start_mark,
            )
        if key in seen:
            mark = key_node.start_mark
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r} (first at line {seen[key] + 1})", mark
            )
        seen[key] = key_node.start_mark.line
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def _number_of_yaml_11(loader: _UniqueKeyLoader, node: yaml.ScalarNode, kind: str) -> Any:
    """YAML 1.1's sexagesimal (``1:30`` = 90) and octal (``010`` = 8) numbers are refused:
    ``end_time: 1:30`` ran 90 s and ``count: [010, 10, 10]`` made 8 layers, silently. The
    decimal, exponent, hexadecimal (``0x``) and ``_`` forms are read as before."""
    text = str(node.value).replace("_", "")
    digits = text.lstrip("+-")
    if ":" in text:
        value = (
            loader.construct_yaml_int(node) if kind == "int" else loader.construct_yaml_float(node)
        )
        raise yaml.constructor.ConstructorError(
            None,
            None,
            f"{node.value!r} is read by YAML as the base-60 number {value:g} (a clock time "
            "h:m:s or m:s); allowed: a plain number in SI units (seconds for a time), e.g. "
            f"{value:g}, or quote it if it is a name",
            node.start_mark,
        )
    if kind == "int" and len(digits) > 1 and digits[0] == "0" and digits[1:].isdigit():
        value = loader.construct_yaml_int(node)
        raise yaml.constructor.ConstructorError(
            None,
            None,
            f"{node.value!r} is read by YAML as the octal number {value} (a leading zero); "
            f"allowed: the number without its leading zero, {int(digits):d}",
            node.start_mark,
        )
    return loader.construct_yaml_int(node) if kind == "int" else loader.construct_yaml_float(node)


_UniqueKeyLoader.add_constructor(
    "tag:yaml.org,2002:int", lambda loader, node: _number_of_yaml_11(loader, node, "int")
)
_UniqueKeyLoader.add_constructor(
    "tag:yaml.org,2002:float", lambda loader, node: _number_of_yaml_11(loader, node, "float")
)

#: Largest case file read [bytes]: a case is a few kilobytes; particles beyond a few
#: thousand belong in a particle file (``insertion: kind: file``), which has no such limit.
MAX_CASE_BYTES = 5_000_000
#: Most YAML nodes a case may expand to once aliases are followed (``*name`` repeats the
#: node it names; nested aliases grow exponentially: the "billion laughs" file).
MAX_CASE_NODES = 1_000_000


def _expanded_nodes(root: yaml.Node, limit: int) -> int:
    """Number of nodes of the document with every alias expanded (linear time: each distinct
    node is visited once); raises ConfigError-worthy ValueError above ``limit`` or for a
    recursive alias."""
    sizes: dict[int, int] = {}
    active: set[int] = set()

    def size(node: yaml.Node) -> int:
        key = id(node)
        if key in sizes:
            return sizes[key]
        if key in active:
            raise ValueError("an alias refers to a node that contains it (a recursive alias)")
        active.add(key)
        total = 1
        if isinstance(node, yaml.SequenceNode):
            total += sum(size(child) for child in node.value)
        elif isinstance(node, yaml.MappingNode):
            total += sum(size(k) + size(v) for k, v in node.value)
        active.discard(key)
        if total > limit:
            raise ValueError(
                f"it expands to more than {limit} values once its aliases (*name) are "
                "followed (nested aliases grow exponentially)"
            )
        sizes[key] = total
        return total

    return size(root)


def _parse_yaml(text: str) -> Any:
    """The YAML document, refusing one that expands beyond :data:`MAX_CASE_NODES`."""
    loader = _UniqueKeyLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _expanded_nodes(node, MAX_CASE_NODES)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def case_from_dict(data: Any, source: str = "<case>", *, stored: bool = False) -> Case:
    """Validate a mapping into a Case, raising ConfigError with key paths. ``stored``: the
    case of a checkpoint, read as it was written (state/materials.py: STORED_CASE_KEY)."""
    if not isinstance(data, dict):
        raise ConfigError(
            f"{source}: the case must be a mapping of sections, got {type(data).__name__}"
        )
    context = validation_context(data)
    if stored:
        context = {**(context or {}), STORED_CASE_KEY: True}
    try:  # a 2D case is validated in the context {"dimension": 2} (config/planar.py)
        return Case.model_validate(data, context=context)
    except ValidationError as exc:
        raise ConfigError(
            f"{source}: invalid case\n{_format_validation_error(exc, data)}"
        ) from None


def load_case(path: str | Path) -> Case:
    """Read and validate a YAML case file."""
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"case file {str(path)!r} does not exist")
    if path.is_dir():
        raise ConfigError(f"case file {str(path)!r} is a directory, expected a YAML file")
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise ConfigError(f"case file {str(path)!r} cannot be read: {exc.strerror}") from None
    if size > MAX_CASE_BYTES:
        raise ConfigError(
            f"case file {str(path)!r} is {size / 1e6:.3g} MB; a case file may have at most "
            f"{MAX_CASE_BYTES / 1e6:g} MB (refused before reading it): put many particles in a "
            "particle file (insertion: kind: file)"
        )
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"case file {str(path)!r} is not UTF-8 text ({exc.reason})") from None
    except OSError as exc:
        raise ConfigError(f"case file {str(path)!r} cannot be read: {exc.strerror}") from None
    if not text.strip():
        raise ConfigError(f"case file {str(path)!r} is empty")
    try:
        data = _parse_yaml(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown place"
        raise ConfigError(f"{path}: YAML syntax error at {where}: {exc.problem}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: YAML error: {exc}") from None
    except ValueError as exc:
        raise ConfigError(f"case file {str(path)!r} refused: {exc}") from None
    except RecursionError:
        raise ConfigError(f"case file {str(path)!r} refused: it is nested too deeply") from None
    if data is None:
        raise ConfigError(f"case file {str(path)!r} is empty (only comments or blank lines)")
    case = case_from_dict(data, str(path))
    # relative file paths in the case are relative to the case file
    for entry in case.insertion:
        if getattr(entry, "kind", None) == "file" and not Path(entry.path).is_absolute():
            entry.path = str(path.parent / entry.path)
    fluid = case.thermal.fluid if case.thermal is not None else None
    for source in (fluid.temperature, fluid.velocity) if fluid is not None else ():
        if getattr(source, "kind", None) == "grid" and not Path(source.file).is_absolute():
            source.file = str(path.parent / source.file)
    return case
