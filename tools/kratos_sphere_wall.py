"""Where thermodem and Kratos ThermalDEM's colliding_sphere_wall_3d regression case differ: the
wall mode of tools/kratos_colliding_spheres.py (whose material tables, Thornton damping fit,
fluid and Nusselt correlations it imports), an independent one-dimensional re-derivation
(along the wall normal) of what that Kratos case computes, written from reading the Kratos
source (KratosMultiphysics/Kratos, applications/ThermalDEMApplication: the particle-wall
branches of custom_elements/thermal_spheric_particle.cpp at 896bfcef, the models of
custom_constitutive/conduction/ at 0ceab79a and 159bc81a; the DEM-FEM branch of
applications/DEMApplication/custom_constitutive/DEM_D_Hertz_viscous_Coulomb_CL.cpp at
03f57bf0), not thermodem code and not Kratos code.

The Kratos case (tests/colliding_sphere_wall_3d/, reference_solutions.json at ec954286): one
R = 0.5 m sphere at (-0.2, 0, 0.7), velocity (10, 0, -10) m/s, ω_y = 1 rad/s, 300 K, the
"Particle" material of colliding_spheres_3d (k(T), c(T), E(T), ν(T), ρ(T), expansion tables),
HEATFLUX 50 W/m², HEATSOURCE -100 W/m³; a wall z = 0 of two triangles (±1 m) whose nodes hold
400 K, of the "Wall" material (tables of the right-hand sphere of colliding_spheres_3d, read at
the wall temperature: k_w = 400 W/(m K)), Δt = 5e-5 s to 0.03 s (contact from 0.02 s).

What Kratos computes for the wall (as read):

* Mechanics: the DEM reads the wall's YOUNG_MODULUS and POISSON_RATIO from the material's
  plain variables, 1.0 and 1.0, so (1 - ν_w²)/E_w = 0: the wall is rigid in the normal
  direction, E* = E_p(T)/(1 - ν_p(T)²), R* = R, m* = m, the same damping 2 γ sqrt(m k_n) and
  clip as between spheres, GlobalDamping 0.1. (The tangential stiffness 8 G* sqrt(R δ) has
  G* = 0.25 Pa: the x force of the reference, -28 N, is its viscous part, the slip of 9.5 m/s
  being far from the Coulomb cap; it does not enter the normal motion.)
* Heat: wall temperature the mean of its nodes (400 K), k_w the table at that temperature;
  distance d = centre-to-plane distance, R_c = sqrt(R² - d²) (R the expanding radius);
  batchelor_obrien_simple Q = 4 k_p k_w/(k_p + k_w) R_c ΔT; thermal_pipe with the wall radius
  0: k_avg = (R + 0)/(R/k_p + 0) = k_p, Q = k_p π R_c² ΔT / d; convection as for the spheres
  (|v - u_f| with v = (10, 0, v_z): the friction's -0.0165 m/s of v_x is left out, < 1e-5 of
  T - T0); radiation with walls is not implemented and a single particle has no radiative
  neighbour: Radiation_01/02 are the prescribed flux and source alone.

Status (measured, ``python tools/kratos_sphere_wall.py``): the convection and radiation
references are reproduced to 1e-5 or better; the two conduction references are NOT: the
re-derivation is 0.33 % (ConductionDir_01) and 0.99 % (ConductionDir_04) of T - T0 low. Read
back from the reference's HEATFLUX at the last thermal step, Kratos' overlap there is 0.9 %
larger (3.04e-2 m against 3.01e-2 m) in both cases. Tried and not the cause (each changes the
two misses by different factors): contact starting 1 or 2 steps later (neighbour search every
5 steps), the mass following ρ(T) or the radius, the expansion left out of the mechanics or of
the heat, the wall's table E and ν (4e6 Pa, 0.4: 4 % and 9 % too high), both triangles
conducting (74 %), 601 steps. E* = E_p(T) (no 1 - ν²) leaves +0.19 % and +0.21 %; no reading
of the source was found for it. So for these two cases the OFFSET below (the Kratos-only
settings) is measured with a re-derivation that misses by up to 1 %, and the test's tolerance
holds that miss.

    python tools/kratos_sphere_wall.py

prints, per case, the re-derived temperature, its distance to the reference, the one without
the Kratos-only settings and their difference (the OFFSET [K] of
tests/verification/test_kratos_wall_reference.py).
"""

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from kratos_colliding_spheres import (  # noqa: E402
    FLUID,
    MAT,
    POROSITY,
    REAL_YOUNG_RATIO,
    gamma_thornton,
    lin,
    nusselt,
)

PARTICLE, WALL = MAT[0], MAT[1]
T0 = 300.0
WALL_TEMPERATURE = 400.0  # TEMPERATURE of the wall's nodes (testDEM_FEM_boundary.mdpa)
R0 = 0.5
Z0, VX0, VZ0 = 0.7, 10.0, -10.0  # centre height over the wall, velocity (testDEM.mdpa)

KRATOS = dict(
    direct=None,
    conv=None,
    rad=None,
    por=POROSITY,
    freq=5,
    ET=True,
    expand=True,
    ereal=REAL_YOUNG_RATIO,
    gd_emulated=False,
)
# Kratos-only settings off, and GlobalDamping as thermodem's test emulates it (ρ/1.1, c × 1.1,
# α √1.1): × 1.1 throughout the contact, where Kratos has × 0.9 once the particle rebounds
# (v_z > 0, from about 0.0265 s; the spheres' references end before that)
OFF = dict(freq=1, ET=False, expand=False, gd_emulated=True)


def direct_wall(o, T, R, d):
    """Direct conduction from the wall into the particle [W] (0 out of contact)."""
    if d >= R:
        return 0.0
    rc = math.sqrt(R * R - d * d)
    k = lin(PARTICLE["k"], T)
    k_w = lin(WALL["k"], WALL_TEMPERATURE)
    dT = WALL_TEMPERATURE - T
    if o["direct"] == "simple":
        return 4.0 * k * k_w / (k + k_w) * rc * dT
    if o["direct"] == "pipe":  # k_avg = (R + 0)/(R/k + 0/k_w) = k
        return k * math.pi * rc * rc * dT / d
    raise ValueError(o["direct"])


def convection_wall(o, T, R, vx, vz):
    u = FLUID["v"]
    rel = math.sqrt((vx - u[0]) ** 2 + u[1] ** 2 + (vz - u[2]) ** 2)
    nu = nusselt(o, dict(R=[R], rel=[rel]), 0)
    return nu * FLUID["k"] / (2.0 * R) * 4.0 * math.pi * R * R * (FLUID["T"] - T)


def run(model=None, gdamp=0.1, dt=5e-5, end=0.03, e=0.2, **opts):
    """One Kratos run of the wall case; opts override KRATOS. Returns T, v_z, F_n."""
    o = dict(KRATOS, direct=model)
    o.update(opts)
    g = gamma_thornton(e)
    T, R, z, vz = T0, R0, Z0, VZ0
    m = lin(PARTICLE["rho"], T0) * 4.0 / 3.0 * math.pi * R0**3
    freq = o["freq"]
    fn = 0.0
    for step in range(1, round(end / dt) + 1):
        solve = (step - 1) % freq == 0
        nsteps = 1 if step == 1 else freq
        t_prev = T
        delta = R - z
        TE = T if o["ET"] else T0
        E = lin(PARTICLE["E"], TE)
        nu = lin(PARTICLE["nu"], TE)
        e_star = E / (1.0 - nu * nu)  # rigid wall: (1 - ν_w²)/E_w = 0
        fn = 0.0
        if delta > 0:
            kn = 2.0 * e_star * math.sqrt(R * delta)
            fn = max(2.0 / 3.0 * kn * delta - 2.0 * g * math.sqrt(m * kn) * vz, 0.0)
        force = fn
        if o["gd_emulated"]:  # thermodem's emulation: × (1 + gd) throughout the contact
            force *= 1.0 + gdamp
        elif gdamp and force * vz != 0:
            force *= 1.0 - gdamp * math.copysign(1.0, force * vz)
        if solve:
            Q = PARTICLE["q"] * 4.0 * math.pi * R * R + PARTICLE["s"] * 4.0 / 3.0 * math.pi * R**3
            if o["direct"]:
                Q += direct_wall(o, T, R, z)
            if o["conv"]:
                Q += convection_wall(o, T, R, VX0, vz)
            # o["rad"]: radiation with walls is not implemented in Kratos and there is no
            # neighbour particle: nothing
        vz += force / m * dt  # symplectic Euler
        z += vz * dt
        if solve:
            T += dt * nsteps * Q / (m * lin(PARTICLE["c"], T))
            if o["expand"]:
                R *= 1.0 + lin(PARTICLE["a"], T) * (T - t_prev)
    return dict(T=T, vz=vz, F=fn, R=R)


# case: (model, reference T at 0.03 s (ec954286), Kratos settings beyond KRATOS, PLAIN)
CASES = {
    "ConductionDir_01": ("simple", 322.9703553967616, {}, OFF),
    "ConductionDir_04": ("pipe", 310.48362717100804, {}, OFF),
    "Convection_01": (
        None, 334.97888349023617, dict(conv="ranz_marshall"), dict(OFF, conv="ranz_marshall"),
    ),
    "Convection_02": (
        None, 332.7069267613779, dict(conv="whitaker"), dict(OFF, conv="whitaker"),
    ),
    "Convection_03": (None, 340.04594604175827, dict(conv="gunn"), dict(OFF, conv="gunn")),
    "Convection_04": (
        None, 323.9893852478977, dict(conv="li_mason"), dict(OFF, conv="li_mason"),
    ),
    "Radiation_01": (None, 300.9910452746127, dict(rad="zhou"), dict(OFF, rad="zhou")),
    "Radiation_02": (None, 300.9910452746127, dict(rad="krause"), dict(OFF, rad="krause")),
}  # fmt: skip


if __name__ == "__main__":
    for case, (model, ref, kratos_opts, plain_opts) in CASES.items():
        kratos = run(model=model, **kratos_opts)["T"]
        err = (kratos - ref) / (ref - T0)
        plain = run(model=model, **plain_opts)["T"]
        print(
            f"{case}: re-derived {kratos:.6f} (vs reference {err:+.1e} of T - T0), without the "
            f"Kratos-only settings {plain:.6f}, OFFSET {plain - kratos:.8f}"
        )
