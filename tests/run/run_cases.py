"""The small case the input tests of tests/run start from (a 2 × 2 × 2 lattice of glass
spheres on a floor, 100 steps): test_input_mistakes.py, test_input_at_build.py and
test_ignored_settings.py change a section or two of a copy; and :func:`cli`, the command
line run in the test's process."""

from __future__ import annotations

import copy
import subprocess
from typing import Any

from typer.testing import CliRunner

from thermodem.cli import app

BASE_CASE: dict[str, Any] = {
    "simulation": {"time_step": 1.0e-5, "end_time": 0.001},
    "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
    "materials": {
        "glass": {
            "density": 2500,
            "youngs_modulus": 1.0e7,
            "poisson_ratio": 0.3,
            "thermal_conductivity": 1.0,
            "specific_heat": 800,
        }
    },
    "walls": [{"kind": "plane", "point": [0, 0, 0], "normal": [0, 0, 1], "material": "glass"}],
    "insertion": [
        {
            "kind": "lattice",
            "material": "glass",
            "distribution": {"kind": "mono", "radius": 0.001},
            "lower": [0, 0, 0],
            "upper": [0.006, 0.006, 0.006],
            "count": [2, 2, 2],
        }
    ],
}


def base_case(**sections: Any) -> dict[str, Any]:
    """A deep copy of BASE_CASE with ``sections`` replaced."""
    return {**copy.deepcopy(BASE_CASE), **copy.deepcopy(sections)}


def cli(*args: object) -> subprocess.CompletedProcess:
    """``thermodem ARGS`` through the command-line application in this process (typer's
    runner): its exit code, stdout and stderr, as a user sees them. A new interpreter that
    imports thermodem and loads its compiled kernels costs ~1.5-2.5 s per call (a few hundred
    calls in the input tests); the behaviours that need a process of their own (signals, the
    exit, the threading layer, the newcomer's commands, MPI) keep tests through the installed
    command in a subprocess (test_cli.py, test_newcomer.py, test_*signal*.py, tests/mpi). An
    exception that escapes the application is raised here with its traceback, and a
    traceback printed by the application fails the call."""
    result = CliRunner().invoke(app, [str(a) for a in args])
    error = result.exception
    if error is not None and not isinstance(error, SystemExit):
        raise error
    assert "Traceback" not in result.stdout + result.stderr, result.stdout + result.stderr
    return subprocess.CompletedProcess(list(args), result.exit_code, result.stdout, result.stderr)
