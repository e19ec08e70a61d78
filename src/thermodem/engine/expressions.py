"""Safe arithmetic expressions from the case file (e.g. ``"300 + 50 * z / 0.1"``).

Only numbers, the named variables, arithmetic and comparison operators and a fixed set of numpy
functions are allowed; anything else (attributes, calls of other names, subscripts) is refused
with a message naming the offending part. Expressions are evaluated vectorised on arrays.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

import numpy as np

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
    """A function of the named variables; raises ValueError for anything not allowed."""
    try:
        tree = ast.parse(text, mode="eval")
    except SyntaxError as exc:
        raise ValueError(f"expression {text!r} is not valid: {exc.msg}") from None
    for node in ast.walk(tree):
        if not isinstance(node, _ALLOWED):
            raise ValueError(f"expression {text!r}: {type(node).__name__} is not allowed")
        if isinstance(node, ast.Name) and node.id not in (*variables, *FUNCTIONS, *CONSTANTS):
            allowed = ", ".join((*variables, *CONSTANTS, *FUNCTIONS))
            raise ValueError(f"expression {text!r}: unknown name {node.id!r}; allowed: {allowed}")
        if isinstance(node, ast.Call) and not (
            isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
        ):
            raise ValueError(f"expression {text!r}: only {', '.join(FUNCTIONS)} may be called")
    code = compile(tree, "<case expression>", "eval")

    def evaluate(*values: np.ndarray | float) -> np.ndarray:
        scope = dict(zip(variables, values, strict=True))
        return np.asarray(
            eval(code, {"__builtins__": {}, **FUNCTIONS, **CONSTANTS}, scope), dtype=np.float64
        )

    return evaluate
