"""Reading a case file, with errors that name the key path, the bad value and what is allowed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from thermodem.config.messages import format_validation_error
from thermodem.config.schema import Case
from thermodem.errors import ConfigError


def _format_validation_error(exc: ValidationError, data: Any = None) -> str:
    return format_validation_error(exc, data)


class _UniqueKeyLoader(yaml.SafeLoader):
    """A safe loader that refuses duplicate keys (PyYAML would keep the last one silently)."""


def _construct_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False):  # noqa: ANN202
    seen: dict[Any, Any] = {}
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            mark = key_node.start_mark
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r} (first at line {seen[key] + 1})", mark
            )
        seen[key] = key_node.start_mark.line
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_mapping)


def case_from_dict(data: Any, source: str = "<case>") -> Case:
    """Validate a mapping into a Case, raising ConfigError with key paths."""
    if not isinstance(data, dict):
        raise ConfigError(
            f"{source}: the case must be a mapping of sections, got {type(data).__name__}"
        )
    try:
        return Case.model_validate(data)
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
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise ConfigError(f"case file {str(path)!r} is not UTF-8 text ({exc.reason})") from None
    except OSError as exc:
        raise ConfigError(f"case file {str(path)!r} cannot be read: {exc.strerror}") from None
    if not text.strip():
        raise ConfigError(f"case file {str(path)!r} is empty")
    try:
        data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader subclass)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown place"
        raise ConfigError(f"{path}: YAML syntax error at {where}: {exc.problem}") from None
    except yaml.YAMLError as exc:
        raise ConfigError(f"{path}: YAML error: {exc}") from None
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
