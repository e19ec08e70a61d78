"""Cold-cache first-run time of a small case (the compile cost a change adds).

    THERMODEM_CACHE_DIR=$(mktemp -d) python tools/measure_compile.py mechanics|epsd|heat|generation

Builds a 64-sphere box (Hertz–Mindlin; ``epsd`` adds EPSD rolling; ``heat`` BOB simple with
heat every second step; ``generation`` adds ``heat_generation: mechanical_dissipation``), runs
5 steps and prints the wall and CPU seconds of the whole process so far (imports, compilation,
run) as JSON. Run it with an empty cache directory each time; on a shared machine compare the
CPU seconds.
"""

from __future__ import annotations

import json
import os
import sys
import time

t0_wall, t0_cpu = time.perf_counter(), time.process_time()

from thermodem.config.load import case_from_dict  # noqa: E402
from thermodem.engine.simulation import Simulation  # noqa: E402


def case(which: str) -> dict:
    glass = {"density": 2500.0, "youngs_modulus": 1e7, "poisson_ratio": 0.3,
             "restitution": 0.5, "sliding_friction": 0.5, "rolling_friction": 0.05,
             "thermal_conductivity": 1.0, "specific_heat": 800.0}  # fmt: skip
    data = {
        "simulation": {"time_step": 1e-5, "end_time": 1.0},
        "domain": {"lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01]},
        "materials": {"glass": glass},
        "walls": [{"kind": "box", "lower": [0, 0, 0], "upper": [0.01, 0.01, 0.01],
                   "material": "glass"}],
        "insertion": [{"kind": "lattice", "material": "glass",
                       "distribution": {"kind": "mono", "radius": 0.0009},
                       "lower": [0.001, 0.001, 0.001], "upper": [0.009, 0.009, 0.009],
                       "spacing": 0.00185}],
    }  # fmt: skip
    if which == "epsd":
        data["contact"] = {"rolling": "epsd"}
    if which in ("heat", "generation"):
        data["thermal"] = {"substeps": 2}
    if which == "generation":
        data["thermal"]["heat_generation"] = "mechanical_dissipation"
    return data


def main() -> None:
    which = sys.argv[1] if len(sys.argv) > 1 else "mechanics"
    sim = Simulation(case_from_dict(case(which)))
    sim.run(steps=5)
    print(json.dumps({"case": which, "wall_s": time.perf_counter() - t0_wall,
                      "cpu_s": time.process_time() - t0_cpu,
                      "load": os.getloadavg()[0]}))  # fmt: skip


if __name__ == "__main__":
    main()
