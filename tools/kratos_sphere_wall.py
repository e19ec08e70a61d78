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

What Kratos computes for the wall (as read; the heat models are in
tools/kratos_sphere_wall_models.py):

* Mechanics: the DEM reads the wall's YOUNG_MODULUS and POISSON_RATIO from the material's
  plain variables, 1.0 and 1.0, so (1 - ν_w²)/E_w = 0: the wall is rigid in the normal
  direction, E* = E_p(T)/(1 - ν_p(T)²), R* = R, m* = m, the same damping 2 γ sqrt(m k_n) and
  clip as between spheres, GlobalDamping 0.1. (The tangential stiffness 8 G* sqrt(R δ) has
  G* = 0.25 Pa: the x force of the reference, -28 N, is its viscous part, the slip of 9.5 m/s
  being far from the Coulomb cap; it does not enter the normal motion.)
* When the wall is a neighbour. The DEM-FEM search runs before the first step and then at the
  steps with (TIME_STEPS + 1) % NeighbourSearchFrequency = 0, here 4, 9, 14, ...
  (DEMApplication custom_strategies/strategies/explicit_solver_strategy.cpp, stored version
  00c110db: Initialize, SearchFEMOperations), and the particle keeps that list of walls until
  the next search; the contact force and every wall heat term need the wall in the list. A
  face enters it when the centre is within R of it (rigid_face_geometrical_object_configure.h,
  06948f66 and 6293c1a3: DoubleHierarchyMethod3D, FacetCheck with GetInteractionRadius() = R):
  the sphere touches at step 402 and the wall enters at step 404, two steps late. That is the
  0.33 % / 0.99 % of T - T0 by which this re-derivation missed ConductionDir_01/04 before
  (the overlap 0.9 % deeper at the end); with it both are reproduced to 4e-13. Where the heat
  model has a search distance (GetSearchDistance: R × max_conduction_distance for
  batchelor_obrien_complete/modified (it inherits it) and voronoi_a/b, R × fluid_layer_thickness
  for surrounding_layer; ThermalExplicitSolverStrategy::SetSearchRadii at 3b95a5ee adds it to
  the search radius), the references are reproduced only if the wall enters the list when the
  centre is within R (1 + that ratio): before the first step for Voronoi (0.7 < 1.0), from
  step 4 for the layer, so the force starts at the touch. The stored hierarchy code does not
  show how the search distance reaches that check (found from the numbers: with R alone
  Dir_02 misses by -12 %, Indir_01..03 by -7 %, -34 %, -43 %). Option "reach" below.
* Heat (thermal_spheric_particle.cpp at 896bfcef): wall temperature the mean of its nodes
  (400 K); the wall's k, ρ, c, E, ν its tables at that temperature (GetWall*: 400, 30, 0.4,
  4e6 Pa, 0.4); the wall radius and mass 0 ("consistent with its use in formulations"), so
  R* = R (ComputeEffectiveRadius), m* = m (ComputeEffectiveMass); d = centre-to-plane
  distance, R_c = sqrt(R² - d²) (R the expanding radius); k_p of Batchelor & O'Brien
  complete/modified the mean (k_p + k_w)/2 (ComputeMeanConductivity).
  - batchelor_obrien_simple Q = 4 k_p k_w/(k_p + k_w) R_c ΔT; thermal_pipe with the wall
    radius 0: k_avg = (R + 0)/(R/k_p + 0) = k_p, Q = k_p π R_c² ΔT / d.
  - batchelor_obrien_complete (conduction/direct_conduction_bob_complete.cpp, stored version
    05a62061): the spheres' formulas with R* = R, the separated branch while the gap is below
    max_conduction_distance × R (the wall being a neighbour long before the touch).
  - batchelor_obrien_modified (direct_conduction_bob_modified.cpp at 0b3b7027,
    InnerResistanceWithWall): the particle's inner resistance alone, R/k_p × π R_cyl² as
    written (the spheres' C++ precedence), R_cyl = conduction_radius × R; none in the wall.
  - collisional (DirectConductionCollisional, thermal_spheric_particle.cpp at 01a8a547, and
    896bfcef's helpers): the impact speed |v_z| of the first step the wall is in contact, t_c
    and R_c^max with m* = m, R* = R and E* from the particle's E(T), ν(T) and the wall's
    4e6 Pa, 0.4 (ComputeEffectiveYoung reads the wall's table, the mechanics its plain 1, 1);
    C with the particle's Fo and ρc ratio (ρ_p(T)c_p(T))/(ρ_w c_w) = 0.5 (outside the fit's
    0.56..3.3, as written); the reference is reproduced with E, not REAL_YOUNG_MODULUS_RATIO
    × E, in R_c^max and Fo (as for the spheres; with it the miss is -54 %).
    t_c = 0.021 s > the contact: no switch to the static model.
  - surrounding_layer (indirect_conduction_surround_layer.cpp at 05cf9247, SphereWallCoeff):
    the analytic particle-wall solution in R-scaled lengths, a = (d - R)/R, r_in where the
    gap is min_conduction_distance (0 while the whole surface is farther), r_out where it is
    the layer; while the gap < fluid_layer_thickness × R.
  - voronoi_a / voronoi_b (indirect_conduction_voronoi_a.cpp at 159bc81a, _b.cpp at 34d98943,
    SphereWallCoeff): the particle's path then the fluid's, nothing in the wall; the face
    radius of the porosity closure with the particle's radius alone, 0.56 R (1 - ε)^(-1/3)
    (GetVoronoiCellFaceRadius); while the gap < max_conduction_distance × R.
  - vargas_mccarthy (indirect_conduction_vargas.cpp at 1d2c68b2): touching only; "the wall is
    assumed as a particle with the same radius": R_avg = R.
  - convection as for the spheres (|v - u_f| with v = (10, 0, v_z): the friction's
    -0.0165 m/s of v_x is left out, < 3e-6 of T - T0); radiation with walls is not
    implemented and a single particle has no radiative neighbour: Radiation_01/02 are the
    prescribed flux and source alone.

Readings of thermodem that differ (PLAIN, in the OFFSET): the wall a neighbour at every step
(contact from the touch; each model's own range, e.g. Voronoi from the start); modified's
inner resistance R/(k π r̄²) (SPEC_INNER); zhou2008's symmetric C, the emulation's m/1.1 and
the simulation's rigid-wall E* (ZHOU); the Voronoi closure A_n = 0.985 R² (1 - ε)^(-2/3)
(ZHOU_FACE); vargas_mccarthy2002's R_p = 2R̄ = 2R at a wall (VARGAS_WALL).

Status (measured, ``python tools/kratos_sphere_wall.py``): every reference of the case is
reproduced, the conduction ones to 4e-7 of T - T0 (Dir_01, _04, _05 and Indir_04 to
round-off), the convection ones to 3e-6 (no tangential motion), the radiation ones bit for bit.

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
    FLUID_LAYER,
    MAX_CONDUCTION_DISTANCE,
    POROSITY,
    nusselt,
)
from kratos_sphere_wall_models import (  # noqa: E402
    PARTICLE,
    direct_wall,
    gamma_thornton,
    indirect_wall,
    lin,
)

T0 = 300.0
R0 = 0.5
Z0, VX0, VZ0 = 0.7, 10.0, -10.0  # centre height over the wall, velocity (testDEM.mdpa)
SEARCH = 5  # NeighbourSearchFrequency

KRATOS = dict(
    direct=None,
    indirect=None,
    conv=None,
    rad=None,
    por=POROSITY,
    freq=5,
    ET=True,
    expand=True,
    ereal=1.0,  # the reference wants E, not REAL_YOUNG_MODULUS_RATIO x E (the docstring)
    gd_emulated=False,
    search=SEARCH,  # the wall enters the list at a search: None = a neighbour at every step
    quad="simpson",
    rij=0.56,
    inner="kratos",
    wall_E=True,
    symmetric=False,
    tc_mass=1.0,
    vargas_wall=1.0,
    reach=0.0,  # ... when the centre is within R (1 + reach) of the face (REACH_BOB, CASES)
)
# Kratos-only settings off, and GlobalDamping as thermodem's test emulates it (rho/1.1, c x 1.1,
# alpha sqrt(1.1)): x 1.1 throughout the contact, where Kratos has x 0.9 once the particle
# rebounds (v_z > 0, from about 0.0265 s; the spheres' references end before that); the wall
# a neighbour at every step (thermodem's contact detection), each model deciding its range
OFF = dict(freq=1, ET=False, expand=False, gd_emulated=True, search=None)
# thermodem's readings where Kratos reads the spec otherwise (see the docstring)
SPEC_INNER = dict(inner="spec")
ZHOU_FACE = dict(rij=math.sqrt(0.985 / math.pi))
ZHOU = dict(symmetric=True, tc_mass=1.0 / 1.1, wall_E=False)
# the models' search distance / R (GetSearchDistance): max_conduction_distance (Batchelor &
# O'Brien complete/modified, Voronoi), fluid_layer_thickness (surrounding_layer), 0 otherwise
REACH_BOB = dict(reach=MAX_CONDUCTION_DISTANCE)
VARGAS_WALL = dict(vargas_wall=3.0)  # R_p = 2R: the mean of R and a "wall radius" of 3R


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
    search = o["search"]
    # the wall in the particle's list of wall neighbours (the first search before step 1)
    neighbour = search is None or z < R * (1.0 + o["reach"])
    impact = None  # (step, normal speed) of the first touching step
    fn = 0.0
    for step in range(1, round(end / dt) + 1):
        if search and (step + 1) % search == 0:  # DEM-FEM search: centre within R of the face
            neighbour = z < R * (1.0 + o["reach"])
        solve = (step - 1) % freq == 0
        nsteps = 1 if step == 1 else freq
        t_prev = T
        delta = R - z
        TE = T if o["ET"] else T0
        E = lin(PARTICLE["E"], TE)
        nu = lin(PARTICLE["nu"], TE)
        e_star = E / (1.0 - nu * nu)  # rigid wall: (1 - nu_w^2)/E_w = 0
        fn = 0.0
        touching = neighbour and delta > 0
        if touching:
            if impact is None:
                impact = (step, abs(vz))
            kn = 2.0 * e_star * math.sqrt(R * delta)
            fn = max(2.0 / 3.0 * kn * delta - 2.0 * g * math.sqrt(m * kn) * vz, 0.0)
        else:
            impact = None
        force = fn
        if o["gd_emulated"]:  # thermodem's emulation: x (1 + gd) throughout the contact
            force *= 1.0 + gdamp
        elif gdamp and force * vz != 0:
            force *= 1.0 - gdamp * math.copysign(1.0, force * vz)
        if solve:
            Q = PARTICLE["q"] * 4.0 * math.pi * R * R + PARTICLE["s"] * 4.0 / 3.0 * math.pi * R**3
            if o["direct"] and neighbour:
                st = None
                if touching:
                    rho = lin(PARTICLE["rho"], T) if o["ET"] else lin(PARTICLE["rho"], T0)
                    st = dict(vimp=impact[1], tcol=(step - impact[0]) * dt, m=m, E=E, nu=nu,
                              rho=rho)  # fmt: skip
                Q += direct_wall(o, T, R, z, st)
            if o["indirect"] and neighbour:
                Q += indirect_wall(o, T, R, z)
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
    "ConductionDir_02": ("complete", 370.50095465826786, REACH_BOB, OFF),
    "ConductionDir_03": ("modified", 357.6311276648615, REACH_BOB, dict(OFF, **SPEC_INNER)),
    "ConductionDir_04": ("pipe", 310.48362717100804, {}, OFF),
    "ConductionDir_05": ("collisional", 315.3010968244975, {}, dict(OFF, **ZHOU)),
    "ConductionIndir_01": (
        None, 376.06270482468074, dict(indirect="layer", reach=FLUID_LAYER),
        dict(OFF, indirect="layer"),
    ),
    "ConductionIndir_02": (
        None, 326.4291943017667, dict(indirect="voronoi_a", **REACH_BOB),
        dict(OFF, indirect="voronoi_a", quad="exact", **ZHOU_FACE),
    ),
    "ConductionIndir_03": (
        None, 322.91314450953814, dict(indirect="voronoi_b", **REACH_BOB),
        dict(OFF, indirect="voronoi_b", **ZHOU_FACE),
    ),
    "ConductionIndir_04": (
        None, 325.3907485650992, dict(indirect="vargas"),
        dict(OFF, indirect="vargas", **VARGAS_WALL),
    ),
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
