"""The Beaulieu (2020) heated steel bed (examples/beaulieu_heated_bed) against the measured
temperatures, in its reduced form: the example's bed and case, backward Euler at Δt = 80 s
(50 steps; the documented run takes Δt = 10 s)."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "beaulieu_heated_bed"


@pytest.fixture(scope="module")
def run():  # noqa: ANN201
    sys.path.insert(0, str(EXAMPLE))
    try:
        import run as example

        yield example
    finally:
        sys.path.remove(str(EXAMPLE))
        sys.modules.pop("run", None)
        sys.modules.pop("common", None)


def test_reduced_bed_follows_the_measured_heating(run) -> None:  # noqa: ANN001
    result = run.simulate(dt=run.REDUCED_DT)
    assert min(result["probe_counts"]) >= 20
    # the measured curves rise by 13.0, 6.3 and 3.7 K over 4000 s; the model, with the
    # published parameters (not fitted), heats faster: on the poured 8849-sphere bed RMS
    # 2.30, 1.97, 1.33 K at Δt = 10 s, 2.21, 1.94, 1.32 K at 80 s, this test's run
    # (2026-12-05; the earlier 5670-sphere crop gave 1.71, 1.26, 0.80 K at 80 s). The bound
    # keeps it within 2.5 K.
    assert max(result["rms"]) < 2.5, result["rms"]
    rise = result["curves"][-1] - result["curves"][0]
    assert rise[0] > rise[1] > rise[2] > 2.0
    assert abs(result["balance_error"]) < 1e-10 * result["energy"]
