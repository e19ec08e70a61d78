"""Particle-wall heat models of Kratos ThermalDEM, re-derived for tools/kratos_sphere_wall.py
(written from reading the Kratos source, not thermodem code and not Kratos code; what was
read, with files and commits, is in that tool's docstring). Each function gives the heat
into the particle [W] from a plane wall at the distance d from its centre, with the
particle's radius R and temperature T; ``o`` holds the options of the run (Kratos' reading or
thermodem's, see KRATOS/OFF there).
"""

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from kratos_colliding_spheres import (  # noqa: E402
    CONDUCTION_RADIUS,
    CORE,
    FLUID,
    FLUID_LAYER,
    MAT,
    MAX_CONDUCTION_DISTANCE,
    MIN_CONDUCTION_DISTANCE,
    POROSITY,
    bob_contact_coeff,
    bob_separated_coeff,
    gamma_thornton,  # noqa: F401  (re-exported for the wall tool)
    integral,
    lin,
)

PARTICLE, WALL = MAT[0], MAT[1]
WALL_TEMPERATURE = 400.0  # TEMPERATURE of the wall's nodes (testDEM_FEM_boundary.mdpa)


def contact_radius(R, d):
    """R_c = sqrt(R² - d²) in contact, 0 out of it (the wall radius is 0)."""
    return math.sqrt(R * R - d * d) if d < R else 0.0


def bob_wall_coeff(o, T, R, d):
    """Batchelor & O'Brien complete: R* = R (wall), k_p = (k_p + k_w)/2; touching, or
    separated by less than MAX_CONDUCTION_DISTANCE x R (0 beyond)."""
    k, k_w = lin(PARTICLE["k"], T), lin(WALL["k"], WALL_TEMPERATURE)
    if d < R:
        return bob_contact_coeff(0.5 * (k + k_w), FLUID["k"], R, contact_radius(R, d))
    if d - R < MAX_CONDUCTION_DISTANCE * R:
        return bob_separated_coeff(0.5 * (k + k_w), FLUID["k"], R, d - R)
    return 0.0


def collisional_wall(o, T, R, d, st):
    """Zhou et al. (2008) against the wall: R* = R, m* = m; E* from the particle's E(T), ν(T)
    and the wall's table values at 400 K (4e6 Pa, 0.4), or (thermodem) the simulation's
    rigid-wall E*; ρc and k of the wall its tables at 400 K. st: impact speed, collision time,
    mass, E*_particle-side quantities of the run."""
    v = st["vimp"]
    m = st["m"] * o["tc_mass"]
    if o["wall_E"]:
        e_w, nu_w = lin(WALL["E"], WALL_TEMPERATURE), lin(WALL["nu"], WALL_TEMPERATURE)
        es = 1.0 / ((1.0 - st["nu"] ** 2) / st["E"] + (1.0 - nu_w**2) / e_w)
    else:
        es = st["E"] / (1.0 - st["nu"] ** 2)
    tmax = 2.87 * (m * m / (R * es * es * v)) ** 0.2
    k, k_w = lin(PARTICLE["k"], T), lin(WALL["k"], WALL_TEMPERATURE)
    dT = WALL_TEMPERATURE - T
    if st["tcol"] >= tmax:  # static: Batchelor & O'Brien simple
        return 4.0 * k * k_w / (k + k_w) * contact_radius(R, d) * dT
    er = es * o["ereal"]
    rcmax = (15.0 * m * R * R * v * v / (16.0 * er)) ** 0.2
    treal = 2.87 * (m * m / (R * er * er * v)) ** 0.2
    rhoc = [
        st["rho"] * lin(PARTICLE["c"], T),
        lin(WALL["rho"], WALL_TEMPERATURE) * lin(WALL["c"], WALL_TEMPERATURE),
    ]
    kk = [k, k_w]

    def coeff(a, b):
        fo = kk[a] * treal / (rhoc[a] * rcmax * rcmax)
        c = rhoc[a] / rhoc[b]
        c1 = -2.300 * c * c + 8.909 * c - 4.235
        c2 = 8.169 * c * c - 33.770 * c + 24.885
        c3 = -5.758 * c * c + 24.464 * c - 20.511
        return 0.435 * (math.sqrt(c2 * c2 - 4.0 * c1 * (c3 - fo)) - c2) / c1

    C = coeff(0, 1) if not o["symmetric"] else 0.5 * (coeff(0, 1) + coeff(1, 0))
    b = [rhoc[n] * kk[n] for n in range(2)]
    return C * math.pi * rcmax**2 * tmax**-0.5 * dT / (b[0] ** -0.5 + b[1] ** -0.5)


def direct_wall(o, T, R, d, st=None):
    """Direct conduction from the wall into the particle [W] (touching only but for the
    Batchelor & O'Brien complete and modified models)."""
    model = o["direct"]
    if d >= R and model not in ("complete", "modified"):
        return 0.0
    rc = contact_radius(R, d)
    k = lin(PARTICLE["k"], T)
    k_w = lin(WALL["k"], WALL_TEMPERATURE)
    dT = WALL_TEMPERATURE - T
    if model == "simple":
        return 4.0 * k * k_w / (k + k_w) * rc * dT
    if model == "pipe":  # k_avg = (R + 0)/(R/k + 0/k_w) = k
        return k * math.pi * rc * rc * dT / d
    if model == "complete":
        return bob_wall_coeff(o, T, R, d) * dT
    if model == "modified":  # the particle's inner resistance only (none in the wall)
        rcyl = CONDUCTION_RADIUS * R
        if o["inner"] == "kratos":  # R/k × π Rcyl², as written (C++ precedence)
            r_inn = R / k * math.pi * rcyl * rcyl
        else:  # the spec's 1/H_i = R/(k π r̄²)
            r_inn = R / (k * math.pi * rcyl * rcyl)
        h = bob_wall_coeff(o, T, R, d)
        return dT / (1.0 / h + r_inn) if h > 0.0 else 0.0
    if model == "collisional":
        return collisional_wall(o, T, R, d, st)
    raise ValueError(model)


def indirect_wall(o, T, R, d):
    """Indirect conduction from the wall into the particle [W]; each model's own range (the
    wall radius 0: the range factor multiplies R)."""
    model = o["indirect"]
    sep = d - R
    kf = FLUID["k"]
    k = lin(PARTICLE["k"], T)
    dT = WALL_TEMPERATURE - T
    rc = contact_radius(R, d)
    if model == "layer":  # the analytic particle-wall solution, in R-scaled lengths
        if not sep < FLUID_LAYER * R:
            return 0.0
        S = MIN_CONDUCTION_DISTANCE
        a = (d - R) / R
        r_in = 0.0 if d > R + S else math.sqrt(1.0 - (S / R - a - 1.0) ** 2)
        lay = (1.0 + FLUID_LAYER) ** 2
        r_out = math.sqrt(lay - (a + 1.0) ** 2) if a > math.sqrt(lay - 1.0) - 1.0 else 1.0
        b, c = math.sqrt(1.0 - r_out * r_out), math.sqrt(1.0 - r_in * r_in)
        h = (
            2.0
            * math.pi
            * kf
            * R
            * ((a + 1.0) * math.log(abs(b - a - 1.0) / abs(a - c + 1.0)) + b - c)
        )
        return h * dT
    if model == "vargas":  # touching only; the wall as a particle of radius o["vargas_wall"] R
        if sep >= 0:
            return 0.0
        ravg = 0.5 * (R + o["vargas_wall"] * R)
        return (
            2.0 * math.pi * kf * dT * (1.0 - 0.5 * (rc / ravg) ** 2) * (ravg - rc)
            / (1.0 - math.pi / 4.0)
        )  # fmt: skip
    # Voronoi models: the face radius of the porosity closure with the particle's radius alone
    if not sep < MAX_CONDUCTION_DISTANCE * R:
        return 0.0
    rij = o["rij"] * R * (1.0 - POROSITY) ** (-1.0 / 3.0)
    if rij <= rc:
        return 0.0
    if model == "voronoi_a":  # particle then fluid along each path; nothing in the wall
        upp = R * rij / math.sqrt(rij * rij + d * d)

        def f(r):
            s = math.sqrt(R * R - r * r)
            return 2.0 * math.pi * r / ((s - r * d / rij) / k + (d - s) / kf)

        return integral(o, f, rc, upp) * dT
    if model == "voronoi_b":
        a = (1.0 / (CORE * R) - 1.0 / R) / (2.0 * k) + 1.0 / (2.0 * kf * R)
        b = 1.0 / (2.0 * kf * d)
        c0 = d / math.sqrt(rij * rij + d * d)
        c1 = d / math.sqrt(rc * rc + d * d)
        fr = (a - b * c0) / (a - b * c1)
        return math.pi * (math.log(fr) if fr > 0 else 0.0) / b * dT
    raise ValueError(model)
