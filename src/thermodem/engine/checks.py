"""Physics sanity before a run: the mechanical time step criteria.

- Rayleigh time (Li et al. 2005, spec section 1.4): Δt_R = π R sqrt(ρ/G) / (0.8766 + 0.163 ν),
  per material with its smallest radius. Warn above ``rayleigh_warn_fraction`` × Δt_R, refuse
  above Δt_R.
- Hertz collision time (spec appendix A): t_c = 2.87 (m*² / (R* E*² v))^{1/5} for two of the
  smallest particles of each material pair (and particle–wall, m* = m, R* = R) at the
  characteristic impact speed v. Warn when a collision would last fewer than
  ``collision_warn_steps`` steps, refuse below ``collision_min_steps``.
  For the linear spring the collision time is π sqrt(m*/k) / sqrt(1 - ζ²) instead, and the
  same with k = (π/4) E* b for the 2D line contact ``hertz_2d`` (masses of discs, ρ π R² b);
  for Walton & Braun's law (π/2) (sqrt(m*/k1) + sqrt(m*/k2)), k2 = k1/e² (its loading and
  unloading half periods).

``allow_unstable: true`` turns refusals into warnings.
"""

from __future__ import annotations

import math

import numpy as np

from thermodem.config.schema import Case
from thermodem.errors import ConfigError
from thermodem.models.mechanics.normal import (
    hertz_2d_stiffness,
    hertz_collision_time,
    linear_collision_time,
)
from thermodem.state.materials import effective_youngs_modulus, resolve_pair
from thermodem.state.particles import particle_mass


def rayleigh_time(radius: float, density: float, shear_modulus: float, poisson: float) -> float:
    """Δt_R = π R sqrt(ρ/G) / (0.8766 + 0.163 ν) (Li et al. 2005)."""
    return math.pi * radius * math.sqrt(density / shear_modulus) / (0.8766 + 0.163 * poisson)


def characteristic_speed(case: Case, velocities: np.ndarray | None = None) -> float:
    chk = case.simulation.time_step_check
    if chk.impact_velocity is not None:
        return chk.impact_velocity
    g = float(np.linalg.norm(case.simulation.gravity))
    height = float(np.max(np.subtract(case.domain.upper, case.domain.lower)))
    speeds = [1.0, math.sqrt(2.0 * g * height)]
    if velocities is not None and velocities.size:
        speeds.append(float(np.sqrt((velocities**2).sum(axis=1)).max()))
    for w in case.walls:
        speeds.append(float(np.linalg.norm(w.velocity)))
        if getattr(w, "angular_velocity", 0.0):
            speeds.append(abs(w.angular_velocity) * w.radius)
    return max(speeds)


def critical_times(
    case: Case,
    radius: np.ndarray,
    type_id: np.ndarray,
    names: list[str],
    velocities: np.ndarray | None = None,
) -> dict[str, float]:
    """Smallest Rayleigh time and collision time over materials present [s]."""
    v = characteristic_speed(case, velocities)
    r_min = {}
    for t, name in enumerate(names):
        sel = radius[type_id == t]
        if sel.size:
            r_min[name] = float(sel.min())
    out = {"rayleigh": math.inf, "collision": math.inf, "impact_speed": v}
    normal = case.contact.normal
    wall_mats = {w.material for w in case.walls}
    thickness = case.simulation.disc_thickness  # 2D discs: their masses, hertz_2d's stiffness

    def mass(density: float, r: float) -> float:
        return float(particle_mass(np.float64(density), np.float64(r), thickness))

    for a, ra in r_min.items():
        ma = case.materials[a]
        out["rayleigh"] = min(
            out["rayleigh"], rayleigh_time(ra, ma.density, ma.shear_modulus, ma.poisson_ratio)
        )
        partners = [(b, r_min[b], False) for b in r_min] + [(b, math.inf, True) for b in wall_mats]
        for b, rb, is_wall in partners:
            mb = case.materials[b]
            m_a = mass(ma.density, ra)
            if is_wall:
                m_eff, r_eff = m_a, ra
            else:
                m_b = mass(mb.density, rb)
                m_eff, r_eff = m_a * m_b / (m_a + m_b), ra * rb / (ra + rb)
            if normal.model in ("linear", "hertz_2d"):
                if normal.model == "linear":
                    k = normal.params.stiffness
                else:
                    k = hertz_2d_stiffness(effective_youngs_modulus(ma, mb), thickness or 1.0)
                e = resolve_pair(ma, mb).restitution
                tc = linear_collision_time(m_eff, k, max(e, 1e-6))  # (e = 0: critical damping)
            elif normal.model == "walton_braun":
                k1 = normal.params.loading_stiffness
                e = max(resolve_pair(ma, mb).restitution, 1e-6)
                tc = 0.5 * math.pi * (math.sqrt(m_eff / k1) + e * math.sqrt(m_eff / k1))
            else:
                tc = hertz_collision_time(m_eff, r_eff, effective_youngs_modulus(ma, mb), v)
            out["collision"] = min(out["collision"], tc)
    return out


def check_time_step(
    case: Case,
    radius: np.ndarray,
    type_id: np.ndarray,
    names: list[str],
    velocities: np.ndarray | None = None,
) -> list[str]:
    """Warnings about the time step; raises ConfigError when it is refused."""
    dt = case.simulation.time_step
    chk = case.simulation.time_step_check
    t = critical_times(case, radius, type_id, names, velocities)
    warnings: list[str] = []
    refusals: list[str] = []
    if math.isfinite(t["rayleigh"]):
        frac = dt / t["rayleigh"]
        msg = (
            f"simulation.time_step = {dt:.4g} s is {frac:.3g} × the Rayleigh time "
            f"{t['rayleigh']:.4g} s (Li et al. 2005)"
        )
        if frac > 1.0:
            refusals.append(msg + "; the limit is 1")
        elif frac > chk.rayleigh_warn_fraction:
            warnings.append(msg + f"; above the warning fraction {chk.rayleigh_warn_fraction}")
    if math.isfinite(t["collision"]):
        steps = t["collision"] / dt
        msg = (
            f"simulation.time_step = {dt:.4g} s resolves the collision time "
            f"{t['collision']:.4g} s (at {t['impact_speed']:.3g} m/s) with {steps:.3g} steps"
        )
        if steps < chk.collision_min_steps:
            refusals.append(msg + f"; at least {chk.collision_min_steps:g} are required")
        elif steps < chk.collision_warn_steps:
            warnings.append(msg + f"; fewer than {chk.collision_warn_steps:g} recommended")
    if refusals and not chk.allow_unstable:
        raise ConfigError(
            "time step refused:\n"
            + "\n".join(refusals)
            + "\n(set simulation.time_step_check.allow_unstable: true to run "
            "anyway)"
        )
    return refusals + warnings


def check_simulation_time_step(sim) -> list[str]:  # noqa: ANN001 (avoids an import cycle)
    """:func:`check_time_step` over the particles present and those that pouring will add.

    Pour entries contribute 1,000 radii drawn from their distribution (with a generator of
    their own, so the simulation's random sequence is untouched) and their initial velocity.
    """
    from thermodem.geometry.insertion import sample_radii

    radius = [sim.particles.radius]
    types = [sim.particles.type_id]
    velocity = [sim.particles.velocity]
    rng = np.random.default_rng(0)
    for pourer in sim.pourers:
        entry = pourer.entry
        r = sample_radii(entry.distribution, 1000, rng)
        radius.append(r)
        types.append(np.full(r.size, sim.material_index[entry.material], np.int32))
        velocity.append(np.tile(np.asarray(entry.velocity, float), (r.size, 1)))
    mechanical = check_time_step(
        sim.case,
        np.concatenate(radius),
        np.concatenate(types),
        sim.material_names,
        np.concatenate(velocity),
    )
    return mechanical + check_thermal_time_step(sim)


def check_thermal_time_step(sim) -> list[str]:  # noqa: ANN001 (avoids an import cycle)
    """Thermal time step against ρ c R² / k (spec 1.4, Rojek 2014) and m c / ΣH.

    The spec's criterion is evaluated per particle material with its smallest radius; the
    sharper per-particle limit m c / ΣH uses the conductances of the contacts present at the
    start (it is re-checked at every thermal step during the run). Refused above either
    limit unless ``thermal.stability.allow_unstable``; warned above ``warn_fraction`` × limit.
    """
    th = sim.thermal
    if th is None or sim.particles.count == 0:
        return []
    s = th.settings
    if s.scheme != "explicit":  # backward Euler and Crank-Nicolson are unconditionally stable
        return []
    dt = s.time_step if s.frozen_mechanics else (1 if s.substeps == "auto" else s.substeps)
    if not s.frozen_mechanics:
        dt = dt * sim.dt
    warnings: list[str] = []
    refusals: list[str] = []
    p = sim.particles
    for t, name in enumerate(sim.material_names):
        sel = p.type_id == t
        m = sim.case.materials[name]
        if not sel.any() or m.thermal_conductivity is None or m.specific_heat is None:
            continue
        r = float(p.radius[sel].min())
        limit = m.density * m.specific_heat * r**2 / m.thermal_conductivity
        msg = (
            f"thermal time step {dt:.4g} s vs ρ c R² / k = {limit:.4g} s of material "
            f"{name!r} (R = {r:.4g} m)"
        )
        if dt > limit:
            refusals.append(msg + ": above the limit")
        elif dt > s.stability.warn_fraction * limit:
            warnings.append(msg + f": above {s.stability.warn_fraction} × the limit")
    fixed = th.fixed if th.fixed.shape[0] == p.count else np.zeros(p.count, np.bool_)
    from thermodem.kernels.thermal import stability_limit

    limit, where = stability_limit(p.mass, th.specific_heat(), th.conductance_sum, fixed)
    if math.isfinite(limit):
        gid = int(p.global_id[where])
        msg = (
            f"thermal time step {dt:.4g} s vs the explicit Euler limit m c / ΣH = {limit:.4g} s "
            f"(particle {gid}, from the contacts at the start)"
        )
        if dt > limit:
            refusals.append(msg + ": above the limit")
        elif dt > s.stability.warn_fraction * limit:
            warnings.append(msg + f": above {s.stability.warn_fraction} × the limit")
    if refusals and not s.stability.allow_unstable:
        raise ConfigError(
            "thermal time step refused:\n" + "\n".join(refusals) + f"\n({_thermal_remedy(sim)})"
        )
    return refusals + warnings


def _thermal_remedy(sim) -> str:  # noqa: ANN001
    """What a refused explicit thermal step can change: the frozen run's thermal.time_step,
    thermal.substeps when there are several, else (one mechanical step per thermal step,
    ``substeps`` 1 or auto) the mechanical time step or the properties themselves."""
    s = sim.thermal.settings
    last = "or set thermal.stability.allow_unstable: true"
    if s.frozen_mechanics:
        return f"reduce thermal.time_step, choose an implicit thermal.scheme, {last}"
    if s.substeps != "auto" and s.substeps > 1:
        return f"reduce thermal.substeps, use substeps: auto, {last}"
    return (
        f"the thermal step is already one mechanical step (thermal.substeps: {s.substeps}): "
        "reduce simulation.time_step, or check density, specific_heat [J/(kg K)] and "
        f"thermal_conductivity [W/(m K)] for a unit mistake, {last}"
    )
