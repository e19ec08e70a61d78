"""Effective thermal conductivity of a packing from its steady conductance network.

For each axis the particles whose centres lie within a boundary layer of thickness ``s`` of
the bed's two faces normal to the axis are held at T₀ + ΔT (low side) and T₀ (high side);
the steady temperatures of the others are solved on the case's conductance network (every
selected term, ``engine/implicit.py``). Then

    k_eff = (Q / A) / |dT/dx|

with Q the heat leaving the hot layer (equal to the heat entering the cold one up to the
solver's residual; both are reported), A the bed's cross-section normal to the axis (the
domain's period on a periodic axis, otherwise the extent of the particles, centre ± radius),
and dT/dx the least-squares slope of the temperatures of the free particles at least one
mean diameter away from both layers (so the contact resistance between a layer and the bed
does not enter). The boundary layers disturb the packing's structure near the faces; the
result is therefore computed for s = one and two mean diameters (default), and the
**uncertainty** is |k(s₁) - k(s₂)| plus twice the standard error of the fitted slope, plus
the relative heat imbalance |Q_hot - Q_cold| / Q times k. A choice of this module (docs:
docs/effective-conductivity.md).

**Periodic gradient** (``periodic_gradient``, ``thermodem etc --periodic``) along an axis on
which the domain is periodic: no boundary layers; the temperature is T = θ + G x with a mean
gradient G imposed across the period and a periodic fluctuation θ. Each pair (i, j) of the
network (every term) with the minimum-image separation Δx_ij carries H_ij (θ_j - θ_i + G Δx_ij),
so the steady state is the graph-Laplacian system

    Σ_j H_ij (θ_i - θ_j) = G Σ_j H_ij Δx_ij      (one θ fixed per connected cluster)

and the heat flux is the network's: q = (1/V) Σ_pairs H_ij (T_i - T_j) Δx_ij, k_eff = -q/G,
V the period's volume (on non-periodic transverse axes, the particles' extent as above).
The dissipation gives it again, k' = (1/(V G²)) Σ_pairs H_ij (T_i - T_j)² (equal at the exact
steady state); the reported uncertainty is |k - k'|, i.e. the solver's — not the statistical
scatter of the sample. On a lattice the fluctuation is zero and k is the lattice sum below.

On a lattice of identical conductances H (exact test in tests/verification/test_etc.py) a
temperature field linear in x is an exact steady solution of the interior (every node is a
centre of symmetry of its bonds) and the heat flux is q = (H/V) Σ_b (b·e)² ∂T/∂x over the
bonds b of one cell counted once:

    k = (H / V_cell) Σ_{bonds in a cell} (b·e)²:  SC H/a, BCC 2H/a, FCC 4H/a

with a the cubic cell edge (a = 2R, 4R/√3, 2√2 R for touching spheres).

2D cases of discs: the axes are x and y, and the cross-section is the in-plane extent times
the disc thickness b (docs/two-dimensional.md).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from thermodem.engine.implicit import ImplicitSolver
from thermodem.errors import ConfigError

AXES = {"x": 0, "y": 1, "z": 2}


@dataclass
class AxisConductivity:
    """k_eff along one axis and the figures it is made of."""

    axis: str
    conductivity: float  # W/(m K), with the thinner layer
    uncertainty: float  # W/(m K)
    by_layer: dict  # layer thickness [m] -> k_eff [W/(m K)]
    heat_hot: float  # W, leaving the hot layer (thinner layer)
    heat_cold: float  # W, entering the cold layer
    area: float  # m²
    gradient: float  # K/m, fitted in the interior
    interior_particles: int

    def as_dict(self) -> dict:
        return asdict(self)


def _check_case(sim) -> None:  # noqa: ANN001
    eng = sim.thermal
    if eng is None:
        raise ConfigError("effective conductivity: the case has no thermal section")
    s = eng.settings
    given = [name for name in ("fixed_temperature", "heat_flux", "volumetric_source",
                               "external_source") if getattr(s, name)]  # fmt: skip
    if given:
        raise ConfigError(
            f"effective conductivity: thermal.{given[0]} is given; the measurement imposes its "
            "own temperatures on two boundary layers and needs a case without fixed "
            "temperatures or sources (remove them)"
        )
    hot = [
        w.name or f"walls.{k}" for k, w in enumerate(sim.case.walls) if w.thermal.kind == "fixed"
    ]
    if hot:
        raise ConfigError(
            f"effective conductivity: wall {hot[0]!r} has thermal.kind fixed; the walls must "
            "be adiabatic (the heat enters and leaves through the boundary layers of particles)"
        )


def effective_conductivity(
    sim,  # noqa: ANN001
    axes: str = "xyz",
    layers: tuple[float, ...] | None = None,
    base_temperature: float = 300.0,
    difference: float = 1.0,
) -> list[AxisConductivity]:
    """k_eff of the simulation's current packing along each of ``axes`` (module docstring).

    ``layers``: boundary-layer thicknesses [m] (default one and two mean diameters); the
    first gives the reported value. The particles' temperatures are left at the last solve.
    """
    _check_case(sim)
    allowed = "xy" if getattr(sim, "planar", False) else "xyz"  # 2D: in the plane
    bad = [a for a in axes if a not in allowed]
    if bad or not axes or len(set(axes)) < len(axes):
        raise ConfigError(
            f"effective conductivity: axes = {axes!r}; allowed: letters of {allowed!r}, each once"
        )
    p = sim.particles
    if p.count == 0:
        raise ConfigError(no_particles_text(sim))
    diameter = 2.0 * float(p.radius.mean())
    layers = layers or (diameter, 2.0 * diameter)
    solver = ImplicitSolver(sim.thermal)
    results = []
    for name in axes:
        a = AXES[name]
        if sim.periodic[a]:
            raise ConfigError(
                f"effective conductivity along {name}: the domain is periodic along {name}; "
                "the two boundary layers would touch through the period (make it non-periodic, "
                "or use the periodic gradient: thermodem etc --periodic)"
            )
        x = p.position[:, a]
        low = float(np.min(x - p.radius))
        high = float(np.max(x + p.radius))
        area = 1.0
        for b in range(3):
            if b == a:
                continue
            if b == 2 and getattr(sim, "disc_thickness", 0.0) > 0.0:
                area *= float(sim.disc_thickness)  # 2D discs: a section of the thickness
            elif sim.periodic[b]:
                area *= float(sim.upper[b] - sim.lower[b])
            else:
                pb = p.position[:, b]
                area *= float(np.max(pb + p.radius) - np.min(pb - p.radius))
        by_layer = {}
        first = None
        for s in layers:
            hot = x - low < s
            cold = high - x < s
            interior = ~hot & ~cold & (x - low >= s + diameter) & (high - x >= s + diameter)
            # (the interior slope needs its particles at two coordinates at least: a lattice
            # column alone between the margins gave a ZeroDivisionError)
            spread = np.ptp(x[interior]) if interior.any() else 0.0
            if not hot.any() or not cold.any() or interior.sum() < 3 or not spread > 0.0:
                raise ConfigError(
                    f"effective conductivity along {name}: the bed ({high - low:.4g} m) is too "
                    f"thin for boundary layers of {s:.4g} m plus one diameter of margin on each "
                    "side (need particles in both layers and at least 3 in between, at two "
                    f"{name} coordinates at least)"
                )
            p.temperature[:] = base_temperature + 0.5 * difference
            p.temperature[hot] = base_temperature + difference
            p.temperature[cold] = base_temperature
            try:
                net = solver.steady(extra_fixed=hot | cold)
            except ConfigError as exc:
                if not str(exc).startswith("steady state:"):
                    raise
                # (the steady solver's advice, a fixed wall or particle, is what etc refuses)
                raise ConfigError(
                    f"effective conductivity along {name}: "
                    + str(exc).split(": ", 1)[1].split(" exchange heat")[0]
                    + f" are linked to neither boundary layer of {s:.4g} m by conducting "
                    "pairs, so the packing does not conduct from one layer to the other (the "
                    "contacts come from the overlaps at t = 0: a lattice whose spacing is the "
                    "diameter touches nowhere; direct_conduction: none conducts through no "
                    "contact); allowed: a packing whose particles overlap (a bed settled by a "
                    "run, as a particle file), or a model that conducts across gaps "
                    "(thermal.indirect_conduction)"
                ) from None
            t = p.temperature
            q = net.rhs - net.conductance @ t  # heat into each particle [W]
            q_hot = -float(q[hot].sum())
            q_cold = float(q[cold].sum())
            xi, ti = x[interior], t[interior]
            design = np.vstack([xi - xi.mean(), np.ones_like(xi)]).T
            coef, res, _, _ = np.linalg.lstsq(design, ti, rcond=None)
            slope = float(coef[0])
            dof = max(xi.shape[0] - 2, 1)
            sigma2 = float(res[0]) / dof if res.shape[0] else 0.0
            slope_se = float(np.sqrt(sigma2 / np.sum((xi - xi.mean()) ** 2)))
            k = 0.5 * (q_hot + q_cold) / area / abs(slope)
            by_layer[float(s)] = k
            if first is None:
                first = (k, q_hot, q_cold, slope, slope_se, int(interior.sum()))
        k, q_hot, q_cold, slope, slope_se, count = first
        ks = list(by_layer.values())
        uncertainty = (max(ks) - min(ks)) + 2.0 * k * slope_se / abs(slope)
        uncertainty += k * abs(q_hot - q_cold) / abs(0.5 * (q_hot + q_cold))
        results.append(AxisConductivity(name, k, uncertainty, by_layer, q_hot, q_cold, area,
                                        slope, count))  # fmt: skip
    return results


def periodic_gradient(
    sim,  # noqa: ANN001
    axes: str = "xyz",
    gradient: float = 1000.0,
) -> list[AxisConductivity]:
    """k_eff along each of ``axes`` (periodic axes only) by an imposed mean gradient
    [K/m] across the period (module docstring). The particles' temperatures are left as
    T = 300 K + θ + G (x - x_min)."""
    import scipy.sparse.linalg as spla
    from scipy.sparse.csgraph import connected_components

    from thermodem.engine.implicit_network import laplacian, pair_lists

    _check_case(sim)
    allowed = "xy" if getattr(sim, "planar", False) else "xyz"  # 2D: in the plane
    bad = [a for a in axes if a not in allowed]
    if bad or not axes or len(set(axes)) < len(axes):
        raise ConfigError(
            f"effective conductivity: axes = {axes!r}; allowed: letters of {allowed!r}, each once"
        )
    p = sim.particles
    if p.count == 0:
        raise ConfigError(no_particles_text(sim))
    eng = sim.thermal
    solver = ImplicitSolver(eng)
    solver._rates(sim.time)  # the engine's passes store every term's conductances
    i, j, h = pair_lists(eng)
    n = p.count
    period = np.asarray(sim.upper - sim.lower, float)
    results = []
    for name in axes:
        a = AXES[name]
        if not sim.periodic[a]:
            raise ConfigError(
                f"effective conductivity, periodic gradient along {name}: the domain is not "
                f"periodic along {name} (domain.periodic); use the boundary layers instead"
            )
        dx = p.position[j, a] - p.position[i, a]
        dx -= period[a] * np.round(dx / period[a])  # minimum image
        volume = 1.0
        for b in range(3):
            if sim.periodic[b]:
                volume *= float(period[b])
            else:
                pb = p.position[:, b]
                volume *= float(np.max(pb + p.radius) - np.min(pb - p.radius))
        lap = laplacian(n, i, j, h, np.zeros(n))
        source = gradient * (np.bincount(i, h * dx, n) - np.bincount(j, h * dx, n))
        count, labels = connected_components(lap, directed=False)
        pinned = np.zeros(n, np.bool_)
        pinned[np.unique(labels, return_index=True)[1]] = True
        free = ~pinned
        theta = np.zeros(n)
        block = lap[free][:, free].tocsr()
        if free.sum() < 5000:
            theta[free] = spla.spsolve(block.tocsc(), source[free])
        elif free.any():
            inverse = 1.0 / block.diagonal()
            jacobi = spla.LinearOperator(block.shape, matvec=lambda v, d=inverse: d * v)
            theta[free], info = spla.cg(block, source[free], rtol=1e-12, maxiter=20 * n,
                                        M=jacobi)  # fmt: skip
            if info != 0:
                raise ConfigError(
                    "effective conductivity, periodic gradient: conjugate gradients did not "
                    f"converge in {20 * n} iterations"
                )
        drop = theta[i] - theta[j] - gradient * dx  # T_i - T_j
        flux = float(np.sum(h * drop * dx)) / volume
        k = -flux / gradient
        k_dissipation = float(np.sum(h * drop * drop)) / (volume * gradient**2)
        p.temperature[:] = 300.0 + theta + gradient * (p.position[:, a] - p.position[:, a].min())
        area = volume / float(period[a])
        results.append(AxisConductivity(name, k, abs(k - k_dissipation), {0.0: k}, -flux * area,
                                        -flux * area, area, gradient, int(n - count)))  # fmt: skip
    return results


def effective_conductivity_of_case(case, axes: str = "xyz", **options) -> list[AxisConductivity]:  # noqa: ANN001, ANN003
    """Build the simulation of a case (its initial packing and contacts) and measure k_eff
    (``periodic=True``: by the periodic gradient, the other options then do not apply)."""
    from thermodem.engine.validation import built_simulation

    if options.pop("periodic", False):
        return periodic_gradient(built_simulation(case), axes)
    return effective_conductivity(built_simulation(case), axes, **options)


def no_particles_text(sim: Any) -> str:
    """The refusal of a case with no particle at t = 0, naming its pour entries (they insert
    during a run; etc measures the packing at the start)."""
    pours = [f"insertion.{k}" for k, e in enumerate(sim.case.insertion) if e.kind == "pour"]
    if not pours:
        return "effective conductivity: the case has no particles"
    return (
        f"effective conductivity: the case has no particles at t = 0: {', '.join(pours)} "
        "pour(s) them during a run, and etc measures the packing at the start; allowed: an "
        "entry that places the packing at t = 0 (lattice, random_box, random_cylinder, file "
        "or list)"
    )
