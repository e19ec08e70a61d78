"""The thread governor (engine/threads.py: ThreadGovernor) of an automatically chosen count.

It times the steps in windows, probes the other count (1 thread, or back to the chosen one)
every PERIOD_WINDOWS windows and keeps the faster. Checked on synthetic step times (the
decisions), then on a run that switches every few steps: results must be bit-identical to a
run on one thread, since no kernel's result depends on the thread count.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from thermodem.engine import threads as T
from thermodem.engine.threads import ThreadGovernor


def drive(governor: ThreadGovernor, seconds_per_step: dict[int, float], steps: int) -> list[int]:
    """The counts the steps ran on, each step taking seconds_per_step[count]."""
    ran = []
    for _ in range(steps):
        ran.append(governor.current)
        governor.tick(seconds_per_step[governor.current])
    return ran


def window_steps(per_step: float) -> int:
    return int(np.ceil(ThreadGovernor.WINDOW_SECONDS / per_step))


def test_one_thread_faster_is_kept_and_probed_again():
    g = ThreadGovernor(2, automatic=True)
    assert g.active and g.current == 2
    speed = {1: 1e-3, 2: 2e-3}  # another process holds a core: 2 threads at half speed
    first = window_steps(speed[2])
    ran = drive(g, speed, first)
    assert set(ran) == {2} and g.current == 1  # the probe starts after one window
    probe = window_steps(speed[1])
    ran = drive(g, speed, probe)
    assert set(ran) == {1} and g.current == 1  # 1 was faster: it stays
    # then PERIOD_WINDOWS windows on 1 thread and a probe of the chosen count, which loses
    ran = drive(g, speed, ThreadGovernor.PERIOD_WINDOWS * probe)
    assert set(ran) == {1} and g.current == 2
    ran = drive(g, speed, first)
    assert set(ran) == {2} and g.current == 1
    assert g.single_steps == (1 + ThreadGovernor.PERIOD_WINDOWS) * probe


def test_chosen_count_faster_comes_back_after_the_probe():
    g = ThreadGovernor(2, automatic=True)
    speed = {1: 2e-3, 2: 1.1e-3}
    drive(g, speed, window_steps(speed[2]))
    assert g.current == 1
    drive(g, speed, window_steps(speed[1]))
    assert g.current == 2  # the probe lost: back to 2
    # no further probe for PERIOD_WINDOWS windows
    ran = drive(g, speed, (ThreadGovernor.PERIOD_WINDOWS - 1) * window_steps(speed[2]))
    assert set(ran) == {2}


def test_a_slow_first_step_does_not_decide():
    # the first step loads or compiles kernels: 2 s on the chosen count, which is faster
    g = ThreadGovernor(2, automatic=True)
    speed = {1: 2e-3, 2: 1e-3}
    g.tick(2.0)
    assert g.current == 2  # one step is no window (MIN_WINDOW_STEPS)
    drive(g, speed, ThreadGovernor.MIN_WINDOW_STEPS)
    assert g.current == 1  # the probe of 1 thread starts ...
    drive(g, speed, window_steps(speed[1]))
    assert g.current == 2  # ... and loses: the 2 s step was left out of the reference


def test_within_the_margin_the_count_before_the_probe_stays():
    g = ThreadGovernor(2, automatic=True)
    speed = {1: 0.98e-3, 2: 1e-3}  # 1 thread 2 % faster: not worth a switch
    drive(g, speed, window_steps(speed[2]) + window_steps(speed[1]))
    assert g.current == 2


@pytest.mark.parametrize("chosen, automatic", [(2, False), (1, True)])
def test_inactive_for_a_request_or_one_thread(chosen, automatic):
    g = ThreadGovernor(chosen, automatic=automatic)
    assert not g.active
    ran = drive(g, {1: 1e-3, 2: 1.0}, 10_000)
    assert set(ran) == {chosen} and g.switches == 0


def heated_case(tmp_path) -> dict:
    from thermodem.geometry.insertion import InsertedParticles, save_particle_file

    r0 = 0.002
    rng = np.random.default_rng(5)
    grid = np.stack(np.meshgrid(*(np.arange(n) for n in (8, 8, 6)), indexing="ij"), -1)
    pos = (grid.reshape(-1, 3) + 0.5) * 1.99 * r0
    rad = rng.uniform(0.97 * r0, r0, len(pos))
    path = tmp_path / "bed.txt"
    save_particle_file(
        path, InsertedParticles(pos, rad, rng.normal(0, 0.1, pos.shape), None, "grain")
    )
    upper = [8 * 1.99 * r0, 8 * 1.99 * r0, 0.05]
    return {
        "simulation": {"time_step": 1e-5, "end_time": 1.0, "gravity": [0.0, 0.0, -9.81]},
        "domain": {"lower": [-0.01] * 3, "upper": [u + 0.01 for u in upper]},
        "materials": {
            "grain": {
                "density": 2500.0,
                "youngs_modulus": 1e7,
                "poisson_ratio": 0.3,
                "restitution": 0.5,
                "sliding_friction": 0.5,
                "thermal_conductivity": 5.0,
                "specific_heat": 800.0,
            }
        },
        "walls": [
            {
                "kind": "box",
                "material": "grain",
                "lower": [0.0] * 3,
                "upper": upper,
                "open_top": True,
                "thermal": {"kind": "fixed", "temperature": 400.0},
            }
        ],
        "insertion": [{"kind": "file", "material": "grain", "path": str(path)}],
        "thermal": {
            "direct_conduction": "batchelor_obrien_simple",
            "initial_temperature": {"kind": "uniform", "value": 300.0},
        },
    }


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
def test_switching_counts_mid_run_changes_no_result(tmp_path, monkeypatch):
    from thermodem.config.load import case_from_dict
    from thermodem.engine.simulation import Simulation

    case = case_from_dict(heated_case(tmp_path))
    one = Simulation(case, threads=1)
    assert not one.governor.active
    one.run(steps=80)

    # a chosen count of 2 (the bed is small), probed every other window of one step
    monkeypatch.setattr(T, "PARALLEL_MIN_PARTICLES", 1)
    monkeypatch.setattr(T, "available_threads", lambda: 2)
    monkeypatch.setattr(ThreadGovernor, "WINDOW_SECONDS", 0.0)
    monkeypatch.setattr(ThreadGovernor, "MIN_WINDOW_STEPS", 1)
    monkeypatch.setattr(ThreadGovernor, "PERIOD_WINDOWS", 2)
    governed = Simulation(case)
    assert governed.threads == 2 and governed.governor.active
    seen: list[int] = []
    governed.run(steps=80, callback=lambda s: seen.append(numba.get_num_threads()))
    assert set(seen) == {1, 2} and governed.governor.switches > 10
    assert governed.running_threads == governed.governor.current

    def by_gid(sim, name):
        return getattr(sim.particles, name)[np.argsort(sim.particles.global_id)]

    for name in ("position", "velocity", "angular_velocity", "temperature"):
        assert np.array_equal(by_gid(one, name), by_gid(governed, name)), name
    assert one.energies() == governed.energies()
