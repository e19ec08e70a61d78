"""Reading a case file, with errors that name the key path, the bad value and what is allowed."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from thermodem.config.schema import Case
from thermodem.errors import ConfigError


def _format_validation_error(exc: ValidationError) -> str:
    lines = []
    for err in exc.errors():
        path = ".".join(str(p) for p in err["loc"] if not str(p).startswith("function-"))
        msg = err["msg"].removeprefix("Value error, ")
        value = err.get("input")
        shown = "" if isinstance(value, dict | list) else f" (got {value!r})"
        if err["type"] == "extra_forbidden":
            msg = "unknown key"
            shown = ""
        lines.append(f"{path}: {msg}{shown}")
    return "\n".join(lines)


def case_from_dict(data: Any, source: str = "<case>") -> Case:
    """Validate a mapping into a Case, raising ConfigError with key paths."""
    if not isinstance(data, dict):
        raise ConfigError(
            f"{source}: the case must be a mapping of sections, got {type(data).__name__}"
        )
    try:
        return Case.model_validate(data)
    except ValidationError as exc:
        raise ConfigError(f"{source}: invalid case\n{_format_validation_error(exc)}") from None


def load_case(path: str | Path) -> Case:
    """Read and validate a YAML case file."""
    path = Path(path)
    if not path.exists():
        raise ConfigError(f"case file {str(path)!r} does not exist")
    if path.is_dir():
        raise ConfigError(f"case file {str(path)!r} is a directory, expected a YAML file")
    text = path.read_text()
    if not text.strip():
        raise ConfigError(f"case file {str(path)!r} is empty")
    try:
        data = yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark
        where = f"line {mark.line + 1}, column {mark.column + 1}" if mark else "unknown place"
        raise ConfigError(f"{path}: YAML syntax error at {where}: {exc.problem}") from None
    case = case_from_dict(data, str(path))
    # relative file paths in the case are relative to the case file
    for entry in case.insertion:
        if getattr(entry, "kind", None) == "file" and not Path(entry.path).is_absolute():
            entry.path = str(path.parent / entry.path)
    return case
