"""Safe arithmetic expressions from the case file (e.g. ``"300 + 50 * z / 0.1"``).

Only numbers, the named variables, arithmetic and comparison operators and a fixed set of numpy
functions are allowed; anything else (attributes, calls of other names, subscripts, strings) is
refused with a message naming the offending part. Expressions are evaluated vectorised on
arrays.

Guards: integer literals are evaluated as floats, so a power tower such as ``9**9**9**9``
overflows at once instead of building an integer with hundreds of millions of digits (which
hangs the interpreter); the text is limited to :data:`MAX_LENGTH` characters; evaluation runs
with floating-point warnings silenced and any division by zero, overflow or other failure, and
any non-finite result, raises :class:`ExpressionError` naming the expression and the values of
its variables. :func:`probe_expression` evaluates an expression on sample points before a run
(used by the case schema for temperatures, which must also be > 0).
"""

from __future__ import annotations

import ast
from collections.abc import Callable
from typing import Any

import numpy as np

from thermodem.errors import SimulationError

MAX_LENGTH = 2000
"""Longest expression text accepted [characters]."""


class ExpressionError(SimulationError, ValueError):
    """An expression that cannot be evaluated or gives a non-finite value.

    A ValueError (the case schema turns it into a key-path message when the expression is
    probed before a run) and a SimulationError (a failure while the run evaluates it stops the
    run with a message and its last good checkpoint, never a traceback).
    """


class _FloatLiterals(ast.NodeTransformer):
    """Integer literals -> float literals (bounded powers, no unbounded integer arithmetic)."""

    def visit_Constant(self, node: ast.Constant) -> ast.Constant:
        if isinstance(node.value, int) and not isinstance(node.value, bool):
            try:
                value = float(node.value)
            except OverflowError:
                value = float("inf")
            return ast.copy_location(ast.Constant(value=value), node)
        return node


FUNCTIONS: dict[str, Callable] = {
    name: getattr(np, name)
    for name in (
        "sin",
        "cos",
        "tan",
        "exp",
        "log",
        "sqrt",
        "abs",
        "tanh",
        "minimum",
        "maximum",
        "where",
        "clip",
    )
}
CONSTANTS = {"pi": np.pi, "e": np.e}
_ALLOWED = (
    ast.Expression,
    ast.BinOp,
    ast.UnaryOp,
    ast.Compare,
    ast.BoolOp,
    ast.Constant,
    ast.Name,
    ast.Load,
    ast.Call,
    ast.IfExp,
    ast.operator,
    ast.unaryop,
    ast.cmpop,
    ast.boolop,
)


def compile_expression(text: str, variables: tuple[str, ...]) -> Callable[..., np.ndarray]:
    """A function of the named variables; raises ValueError for anything not allowed.

    The function raises :class:`ExpressionError` when an evaluation fails (division by zero,
    overflow, a non-finite result).
    """
    if not isinstance(text, str):
        raise ValueError(f"expression must be text, got {text!r}")
    if len(text) > MAX_LENGTH:
        raise ValueError(f"expression of {len(text)} characters is too long (at most {MAX_LENGTH})")
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"expression {text!r} is not valid: {exc.msg}") from None
    except (RecursionError, MemoryError):
        raise ValueError(f"expression {text[:60]!r}... is nested too deeply") from None
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED):
            raise ValueError(f"expression {text!r}: {type(node).__name__} is not allowed")
        if isinstance(node, ast.Constant) and not isinstance(node.value, int | float):
            raise ValueError(
                f"expression {text!r}: the constant {node.value!r} is not a number (only "
                "numbers, the variables and the allowed functions may appear)"
            )
        if isinstance(node, ast.Name) and node.id not in (*variables, *FUNCTIONS, *CONSTANTS):
            allowed = ", ".join((*variables, *CONSTANTS, *FUNCTIONS))
            raise ValueError(f"expression {text!r}: unknown name {node.id!r}; allowed: {allowed}")
        if isinstance(node, ast.Call) and not (
            isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
        ):
            raise ValueError(f"expression {text!r}: only {', '.join(FUNCTIONS)} may be called")
    tree = ast.fix_missing_locations(_FloatLiterals().visit(tree))
    code = compile(tree, "<case expression>", "eval")

    def evaluate(*values: np.ndarray | float) -> np.ndarray:
        scope = dict(zip(variables, values, strict=True))
        try:
            with np.errstate(all="ignore"):
                raw = eval(code, {"__builtins__": {}, **FUNCTIONS, **CONSTANTS}, scope)
                result = np.asarray(raw, dtype=np.float64)
        except (ArithmeticError, TypeError, ValueError) as exc:
            reason = str(exc) or type(exc).__name__
            if isinstance(exc, OverflowError):
                reason = "overflow (a value beyond 1.8e308)"
            raise ExpressionError(
                f"expression {_shown(text)} cannot be evaluated at "
                f"{_where(variables, values)}: {reason}"
            ) from None
        if not np.all(np.isfinite(result)):
            k = int(np.flatnonzero(~np.isfinite(np.broadcast_to(result, np.shape(result))))[0])
            bad = float(np.ravel(result)[k])
            raise ExpressionError(
                f"expression {_shown(text)} gives {bad!r} at {_where(variables, values, k)} "
                "(a division by zero or an overflow?)"
            )
        return result

    return evaluate


def _shown(text: str) -> str:
    return repr(text) if len(text) <= 80 else repr(text[:77] + "...")


def _where(variables: tuple[str, ...], values: tuple[Any, ...], k: int | None = None) -> str:
    """'x = 0.1, y = 0, z = 0.2' (element ``k`` of array values)."""
    parts = []
    for name, value in zip(variables, values, strict=True):
        arr = np.ravel(np.asarray(value, dtype=np.float64))
        if arr.size == 1:
            parts.append(f"{name} = {float(arr[0]):.6g}")
        elif k is not None and k < arr.size:
            parts.append(f"{name} = {float(arr[k]):.6g}")
        else:
            parts.append(f"{name} = ({arr.size} values)")
    return ", ".join(parts)


def probe_expression(
    text: str, variables: tuple[str, ...], samples: tuple[np.ndarray, ...], lower: float | None
) -> None:
    """Evaluate ``text`` on sample values (one array per variable, broadcast together) and
    raise ValueError unless every value is finite and, with ``lower``, > ``lower``."""
    fn = compile_expression(text, variables)
    values = np.broadcast_to(fn(*samples), np.broadcast(*samples).shape)
    if lower is not None:
        bad = np.flatnonzero(~(np.ravel(values) > lower))
        if bad.size:
            k = int(bad[0])
            flat = tuple(np.ravel(np.broadcast_to(s, values.shape)) for s in samples)
            raise ValueError(
                f"expression {_shown(text)} gives {float(np.ravel(values)[k]):.6g} at "
                f"{_where(variables, flat, k)}; it must stay > {lower:g}"
            )
