"""The Voronoi tessellation of the particles: face areas, cell volumes, faces on walls.

The Voronoi conduction models (``models/thermal/voronoi.py``) run on the external pair set
(``engine/external_set.py``): its pairs are the particles whose cells share a face, each with
the face's area A_n as input; its wall pairs are the cells' faces on flat walls.
:class:`VoronoiProvider` fills it on its update policy (``thermal.tessellation``), and the
``voronoi`` porosity provider reads its cell volumes (ε_i = 1 - V_particle / V_cell).

The tessellation itself (compiled clipped cells, or freud / pyvoro2 with mirror particles,
the clipping planes, the checks, the walls a face lies on) is ``engine/tessellation.py``.

Checkpoints: the pairs and inputs are the external set's; the provider saves its counters and
the reference positions of its last tessellation, so a restart continues bit-identically.
"""

from __future__ import annotations

import math
import time as wallclock
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, Any

import numpy as np
from numba import prange

from thermodem.engine.tessellation import clipping_planes, tessellate, wall_name, wall_of_face
from thermodem.errors import RunNotice, SimulationError
from thermodem.kernels.variants import parallel_kernel
from thermodem.models.thermal.voronoi import INPUT_FACE_AREA, INPUT_WIDTH, closure_face_area

if TYPE_CHECKING:
    from thermodem.config.thermal import TessellationSettings
    from thermodem.engine.external_set import ExternalPairSet
    from thermodem.engine.simulation import Simulation


@parallel_kernel(error_model="numpy")
def _largest_move(position, reference, global_id, lower, upper, periodic, part):
    """Largest displacement since ``reference`` (rows by global id; minimum image), by fixed
    chunks: the maximum does not depend on the thread count."""
    length = upper - lower
    n = position.shape[0]
    chunk = 4096
    nchunks = (n + chunk - 1) // chunk
    for c in prange(nchunks):
        local = 0.0
        for i in range(c * chunk, min(n, (c + 1) * chunk)):
            g = global_id[i]
            d2 = 0.0
            for a in range(3):
                d = position[i, a] - reference[g, a]
                if periodic[a]:
                    d -= length[a] * np.round(d / length[a])
                d2 += d * d
            local = max(local, d2)
        part[c] = local
    best = 0.0
    for c in range(nchunks):
        best = max(best, part[c])
    return math.sqrt(best)


@parallel_kernel(error_model="numpy")
def closure_inputs(pair_i, pair_j, wall_i, radius, fields, porosity_column, inputs,
                   wall_inputs):  # fmt: skip
    """A_n of the porosity closure (Zhou et al. 2009) for every pair: the mean of the two
    particles' 0.985 R² (1 - ε)^(-2/3) (one value per pair, so that what i gains j loses), and
    the particle's for a wall pair."""
    for k in prange(pair_i.shape[0]):
        i = pair_i[k]
        j = pair_j[k]
        inputs[k, INPUT_FACE_AREA] = 0.5 * (
            closure_face_area(radius[i], fields[porosity_column, i])
            + closure_face_area(radius[j], fields[porosity_column, j])
        )
    for k in prange(wall_i.shape[0]):
        i = wall_i[k]
        wall_inputs[k, INPUT_FACE_AREA] = closure_face_area(radius[i], fields[porosity_column, i])


class VoronoiProvider:
    """Fills an external pair set with the faces of the tessellation, on its update policy
    (see the module docstring); with ``closure`` the pairs are the near pairs within the
    models' cut-off and A_n comes from each particle's porosity (Zhou et al. 2009)."""

    def __init__(self, sim: Simulation, settings: TessellationSettings | None,
                 external: ExternalPairSet | None,
                 closure_gap: Callable[[float], float] | None = None) -> None:  # fmt: skip
        from thermodem.config.thermal import TessellationSettings

        self.sim = sim
        self.settings = settings or TessellationSettings()
        self.external = external
        self.closure = closure_gap is not None
        self.closure_gap = closure_gap  # largest conducting gap for particles up to a radius
        frozen = bool(sim.case.thermal.frozen_mechanics)
        self.every = None if frozen else self.settings.every_steps
        self.ratio = None if frozen else self.settings.displacement_ratio
        self.count = 0  # tessellations made
        self.seconds = 0.0  # their total wall-clock time
        self.last_seconds = 0.0
        self.last_step = -1
        self.particles = -1  # particle count at the last tessellation
        self.reference = np.zeros((0, 3))  # positions at the last one, rows by global id
        self.volume = np.zeros(0)  # cell volumes by global id [m³]
        self.mirrors = 0
        self._part = np.zeros(1)
        self._warned = False
        self.range_set = None
        if self.closure:
            from thermodem.engine.range_set import RangePairSet

            self.range_set = RangePairSet(sim.case.thermal.range_skin)
            self._range_builds = -1

    # ------------------------------------------------------------------ the policy
    def due(self) -> bool:
        sim = self.sim
        p = sim.particles
        if self.count == 0 or p.count != self.particles:
            return True
        if self.every is not None and sim.step_count - self.last_step >= self.every:
            return True
        if self.ratio is not None and p.count:
            rows = p.count // 4096 + 1
            if self._part.shape[0] < rows:
                self._part = np.zeros(rows)
            if int(p.global_id.max()) >= self.reference.shape[0]:
                return True
            moved = _largest_move(p.position, self.reference, p.global_id, sim.lower,
                                  sim.upper, sim.periodic, self._part)  # fmt: skip
            return moved > self.ratio * float(p.radius.min())
        return False

    def update(self, fields: np.ndarray | None = None) -> bool:
        """Tessellate if due (and, with the closure, refresh the near pairs and A_n); returns
        whether the external set's pairs changed."""
        if self.sim.particles.count == 0:
            return False
        if self.closure:
            return self._closure(fields)
        if not self.due():
            return False
        self.tessellate()
        return True

    def tessellate(self) -> None:
        sim = self.sim
        p = sim.particles
        started = wallclock.perf_counter()
        planes, hot_elsewhere, lower, upper = clipping_planes(sim)
        if hot_elsewhere and not self._warned:
            self._warned = True
            names = ", ".join(wall_name(sim, w) for w in hot_elsewhere)
            warnings.warn(
                f"thermal.tessellation: fixed-temperature walls {names} are not flat walls on a "
                "clipping plane (a non-periodic domain face or a plane wall): the Voronoi "
                "models exchange no heat with them",
                RuntimeWarning,
                stacklevel=2,
            )
        try:
            backend = "auto" if self.settings.backend == "compiled" else "library"
            faces = tessellate(p.position, p.radius, lower, upper, sim.periodic, planes,
                               self.settings.method, p.global_id, backend)  # fmt: skip
        except ValueError as exc:
            raise SimulationError(
                f"thermal.tessellation ({self.settings.method}): {exc} (step {sim.step_count}, "
                f"t = {sim.time:.6g} s, {p.count} particles)",
                sim.step_count,
                sim.time,
            ) from None
        gid = p.global_id
        size = int(gid.max()) + 1 if p.count else 0
        self.volume = np.zeros(size)
        self.volume[gid] = faces.volume
        self.reference = np.zeros((size, 3))
        self.reference[gid] = p.position
        if self.external is not None:
            walls = wall_of_face(sim, planes, faces.wall_particle, faces.wall_index)
            keep = walls >= 0
            self.external.set_pairs(gid[faces.pair_i], gid[faces.pair_j],
                                    faces.pair_area[:, None])  # fmt: skip
            self.external.set_wall_pairs(gid[faces.wall_particle[keep]], walls[keep],
                                         faces.wall_area[keep][:, None])  # fmt: skip
        self.count += 1
        self.last_step = sim.step_count
        self.particles = p.count
        self.mirrors = faces.mirrors
        self.last_seconds = wallclock.perf_counter() - started
        self.seconds += self.last_seconds
        if self.count <= 3 or self.count % 10 == 0 or faces.fallback:
            pairs = faces.pair_i.size
            how = (
                "compiled clipped cells"
                if faces.attempts == 0
                else f"library cells with {faces.mirrors} mirror particles ({faces.attempts} "
                f"attempt{'s' if faces.attempts > 1 else ''})"
            )
            if faces.fallback:
                how = f"the compiled cells failed their check: {how}"
            warnings.warn(
                f"tessellation {self.count} ({self.settings.method}) at step {sim.step_count}: "
                f"{p.count} cells, {pairs} faces between particles, {faces.wall_area.size} on "
                f"clipping planes, {how}, {self.last_seconds:.3g} s; "
                f"{self.seconds:.3g} s in {self.count} tessellations so far",
                RunNotice,
                stacklevel=2,
            )

    def _closure(self, fields: np.ndarray) -> bool:
        sim = self.sim
        rs = self.range_set
        changed = False
        if rs.due(sim):
            gap = self.closure_gap(float(sim.particles.radius.max()))
            rs.build(sim, gap, gap)
        if rs.builds != self._range_builds:
            self._range_builds = rs.builds
            gid = sim.particles.global_id
            wall_i = rs.wall_i[: rs.wall_count]
            self.external.set_pairs(gid[rs.i[: rs.count]], gid[rs.j[: rs.count]])
            self.external.set_wall_pairs(gid[wall_i], rs.wall_w[: rs.wall_count])
            changed = True
        ext = self.external
        ext.prepare(sim)
        from thermodem.kernels.fields import F_POROSITY

        closure_inputs(ext.i, ext.j, ext.wall_i, sim.particles.radius, fields, F_POROSITY,
                       ext.inputs, ext.wall_inputs)  # fmt: skip
        return changed

    def porosity(self) -> np.ndarray:
        """ε_i = 1 - (4/3 π R_i³)/V_cell,i of the current particles (tessellating if due)."""
        if self.due():
            self.tessellate()
        p = self.sim.particles
        return 1.0 - (4.0 / 3.0) * math.pi * p.radius**3 / self.volume[p.global_id]

    # --------------------------------------------------------------- checkpoints
    def state_dict(self) -> dict[str, Any]:
        scalars = {"count": self.count, "seconds": self.seconds, "last_step": self.last_step,
                   "particles": self.particles, "mirrors": self.mirrors,
                   "warned": self._warned}  # fmt: skip
        arrays = {"reference": self.reference, "volume": self.volume}
        if self.range_set is not None:
            sub = self.range_set.state_dict()
            scalars["range_set"] = sub["scalars"]
            scalars["range_builds"] = self._range_builds
            arrays.update({f"range__{k}": v for k, v in sub["arrays"].items()})
        return {"scalars": scalars, "arrays": arrays}

    def load_state_dict(self, state: dict[str, Any]) -> None:
        s, a = state["scalars"], state["arrays"]
        self.count = int(s["count"])
        self.seconds = float(s["seconds"])
        self.last_step = int(s["last_step"])
        self.particles = int(s["particles"])
        self.mirrors = int(s["mirrors"])
        self._warned = bool(s["warned"])
        self.reference = np.array(a["reference"], np.float64).reshape(-1, 3)
        self.volume = np.array(a["volume"], np.float64)
        if self.range_set is not None and "range_set" in s:
            sub = {k[len("range__") :]: v for k, v in a.items() if k.startswith("range__")}
            self.range_set.load_state_dict({"scalars": s["range_set"], "arrays": sub})
            self._range_builds = int(s["range_builds"])


class TessellationPorosity:
    """``thermal.porosity: {kind: voronoi}``: ε_i = 1 - (4/3 π R_i³)/V_cell,i from the
    tessellation of the Voronoi model when the case has one (the same cells, on its update
    policy), else from a tessellation of its own (``thermal.tessellation``)."""

    def __init__(self, sim: Simulation, settings: Any) -> None:
        self.sim = sim
        self.own: VoronoiProvider | None = None

    def update(self, sim: Simulation, fields: np.ndarray) -> None:
        from thermodem.kernels.fields import F_POROSITY

        shared = getattr(sim.thermal, "voronoi", None)
        if shared is None or shared.closure:
            if self.own is None:
                self.own = VoronoiProvider(sim, sim.case.thermal.tessellation, None)
            shared = self.own
        fields[F_POROSITY, :] = shared.porosity()


def _register_porosity() -> None:
    from thermodem.engine.fields import POROSITY_PROVIDERS

    POROSITY_PROVIDERS["voronoi"] = TessellationPorosity


_register_porosity()

__all__ = ["VoronoiProvider", "INPUT_WIDTH"]
