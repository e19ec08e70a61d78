"""Case-file expressions: escapes refused, evaluation guarded (no hang, no silent inf/NaN)."""

from __future__ import annotations

import time

import numpy as np
import pytest

from thermodem.engine.expressions import ExpressionError, compile_expression, probe_expression
from thermodem.errors import SimulationError


def test_values_are_the_arithmetic_written():
    f = compile_expression("300 + 50 * (t > 1) + 2**3 - sqrt(4)", ("t",))
    np.testing.assert_array_equal(f(np.array([0.0, 2.0])), [306.0, 356.0])
    g = compile_expression("where(z < 0.5, 1 / 4, 7 // 2)", ("x", "y", "z"))
    np.testing.assert_array_equal(g(0.0, 0.0, np.array([0.0, 1.0])), [0.25, 3.0])


@pytest.mark.parametrize(
    "text",
    [
        "__import__('os').system('true')",
        "().__class__.__base__.__subclasses__()",
        "[c for c in ()]",
        "t.real",
        "(lambda: 1)()",
        "open('x')",
    ],
)
def test_escapes_are_refused_at_compile_time(text):
    with pytest.raises(ValueError, match="not allowed|may be called|unknown name|not a number"):
        compile_expression(text, ("t",))


@pytest.mark.parametrize("text", ["'300'", "b'1'", "None", "..."])
def test_non_numeric_constants_are_refused(text):
    with pytest.raises(ValueError, match="not a number|not allowed"):
        compile_expression(text, ("t",))


@pytest.mark.parametrize("text", ["9**9**9**9", "(2**1000)**1000", "10**400", "9" * 400])
def test_power_towers_and_huge_literals_fail_fast(text):
    """Integer literals are floats: overflow in microseconds instead of a hang building an
    integer of 370 million digits (what Python does for 9**9**9**9)."""
    start = time.perf_counter()
    f = compile_expression(text, ("t",))
    with pytest.raises(ExpressionError, match="overflow|gives inf"):
        f(np.array([0.0]))
    assert time.perf_counter() - start < 1.0


@pytest.mark.parametrize(
    ("text", "pattern"),
    [
        ("1/0", "cannot be evaluated at t = 0.5: float division by zero"),
        ("300 / (t - 0.5)", r"gives inf at t = 0.5"),
        ("log(t - 0.5)", r"gives -inf at t = 0.5"),
        ("sqrt(t - 1)", r"gives nan at t = 0.5"),
    ],
)
def test_division_by_zero_and_non_finite_results_name_the_point(text, pattern):
    f = compile_expression(text, ("t",))
    with pytest.raises(ExpressionError, match=pattern) as err:
        f(np.array([0.5]))
    # a failure while a run evaluates it is a SimulationError (message, checkpoint, exit 1)
    assert isinstance(err.value, SimulationError) and isinstance(err.value, ValueError)


def test_probe_refuses_values_at_or_below_the_bound():
    t = np.linspace(0.0, 1.0, 11)
    probe_expression("300 - 100 * t", ("t",), (t,), 0.0)
    with pytest.raises(ValueError, match=r"gives -50 at t = 0.3; it must stay > 0"):
        probe_expression("250 - 1000 * t", ("t",), (t,), 0.0)


def test_length_limit():
    with pytest.raises(ValueError, match="too long"):
        compile_expression("+".join(["t"] * 2000), ("t",))
