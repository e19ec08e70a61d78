"""Where thermodem and Kratos ThermalDEM's colliding_spheres_3d regression case differ: an
independent one-dimensional (line of centres) re-derivation of what that Kratos case computes,
written from reading the Kratos source (KratosMultiphysics/Kratos,
applications/ThermalDEMApplication), not thermodem code and not Kratos code. It reproduces the
reference temperatures of ConductionDir_01 and _04 (reference_solutions.json at ec954286) to
1e-6 of T - T0, and with the Kratos-only settings switched off (heat every 5th step, E(T) and
ν(T) tables, thermal expansion; GlobalDamping kept: thermodem's test emulates it) gives the
OFFSET of tests/verification/test_kratos_reference.py:

    python tools/kratos_colliding_spheres.py

prints, per case, the reference-like temperatures, those without the Kratos-only settings and
their difference (the OFFSET T1, T2 [K]).
"""

import math


def lin(tab, x):
    (x0, y0), (x1, y1) = tab
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0)


MAT = [
    dict(
        rho=[[300, 30], [400, 40]],
        E=[[300, 2e6], [400, 3e6]],
        nu=[[300, 0.2], [400, 0.3]],
        k=[[300, 200], [400, 300]],
        c=[[300, 0.2], [400, 0.3]],
        a=[[300, 2e-4], [400, 3e-4]],
        q=50.0,
        s=-100.0,
    ),
    dict(
        rho=[[300, 20], [400, 30]],
        E=[[300, 3e6], [400, 4e6]],
        nu=[[300, 0.3], [400, 0.4]],
        k=[[300, 300], [400, 400]],
        c=[[300, 0.3], [400, 0.4]],
        a=[[300, 3e-4], [400, 4e-4]],
        q=-100.0,
        s=50.0,
    ),
]


def gamma_thornton(e):
    h = [
        -6.918798,
        -16.41105,
        146.8049,
        -796.4559,
        2928.711,
        -7206.864,
        11494.29,
        -11342.18,
        6276.757,
        -1489.915,
    ]
    a = 0.0
    for hk in reversed(h):
        a = e * (hk + a)
    return math.sqrt(1.0 / (1.0 - (1.0 + e) ** 2 * math.exp(a)) - 1.0)


def run(
    model="simple",
    ET=True,
    expand=True,
    gdamp=0.1,
    freq=5,
    dt=5e-5,
    end=0.02,
    e=0.2,
    gamma=None,
    scheme="symplectic",
    flux=True,
    const_at=None,
    trace=None,
):
    g = gamma_thornton(e) if gamma is None else gamma
    T = [300.0, 400.0]
    R = [0.5, 0.5]
    s = [-math.sqrt(0.5), math.sqrt(0.5)]
    v = [math.sqrt(200.0), -math.sqrt(200.0)]
    m = [lin(MAT[i]["rho"], T[i]) * 4 / 3 * math.pi * R[i] ** 3 for i in range(2)]
    Tc = list(T) if const_at is None else const_at  # temperatures of E, nu if not ET
    n = round(end / dt)
    F = [0.0, 0.0]
    Q = [0.0, 0.0]
    for step in range(1, n + 1):
        solve = freq and (step - 1) % freq == 0
        nsteps = 1 if step == 1 else freq
        Tprev = list(T)
        d = s[1] - s[0]
        delta = R[0] + R[1] - d
        F = [0.0, 0.0]
        if delta > 0:
            TE = T if ET else Tc
            E = [lin(MAT[i]["E"], TE[i]) for i in range(2)]
            nu = [lin(MAT[i]["nu"], TE[i]) for i in range(2)]
            Es = 1.0 / ((1 - nu[0] ** 2) / E[0] + (1 - nu[1] ** 2) / E[1])
            Rs = R[0] * R[1] / (R[0] + R[1])
            ms = m[0] * m[1] / (m[0] + m[1])
            kn = 2 * Es * math.sqrt(Rs * delta)
            fel = 2.0 / 3.0 * kn * delta
            vrel = v[0] - v[1]  # approach speed
            fd = 2 * g * math.sqrt(ms * kn) * vrel
            fn = max(fel + fd, 0.0)
            F = [-fn, fn]
        for i in range(2):
            if gdamp and F[i] * v[i] != 0:
                F[i] *= 1 - gdamp * math.copysign(1.0, F[i] * v[i])
        if solve:
            k = [lin(MAT[i]["k"], T[i]) for i in range(2)]
            Q = [0.0, 0.0]
            if delta > 0:
                Rc = math.sqrt(abs(R[0] ** 2 - ((R[0] ** 2 - R[1] ** 2 + d * d) / (2 * d)) ** 2))
                if model == "simple":
                    keff = k[0] * k[1] / (k[0] + k[1])
                    Qc = 4 * keff * Rc * (T[1] - T[0])
                elif model == "pipe":
                    kavg = (R[0] + R[1]) / (R[0] / k[0] + R[1] / k[1])
                    Qc = kavg * math.pi * Rc * Rc * (T[1] - T[0]) / d
                Q = [Qc, -Qc]
            if flux:
                for i in range(2):
                    Q[i] += (
                        MAT[i]["q"] * 4 * math.pi * R[i] ** 2
                        + MAT[i]["s"] * 4 / 3 * math.pi * R[i] ** 3
                    )
        # move
        for i in range(2):
            if scheme == "symplectic":
                v[i] += F[i] / m[i] * dt
                s[i] += v[i] * dt
        if trace is not None:
            trace.append((step * dt, R[0] + R[1] - (s[1] - s[0]), v[0]))
        if solve:
            for i in range(2):
                c = lin(MAT[i]["c"], T[i])
                T[i] += dt * nsteps * Q[i] / (m[i] * c)
            if expand:
                for i in range(2):
                    R[i] *= 1 + lin(MAT[i]["a"], T[i]) * (T[i] - Tprev[i])
    return dict(
        T=T, v=[x / math.sqrt(2) for x in v], Fx=[-F[0] / math.sqrt(2) * -1, 0], F=F, Q=Q, R=R
    )


if __name__ == "__main__":
    for case, model in (("ConductionDir_01", "simple"), ("ConductionDir_04", "pipe")):
        kratos = run(model=model)["T"]
        plain = run(model=model, freq=1, ET=False, expand=False, gdamp=0.1)["T"]
        offset = [b - a for a, b in zip(kratos, plain, strict=True)]  # (what the test adds)
        print(
            f"{case}: re-derived {kratos}, without the Kratos-only settings {plain}, "
            f"OFFSET {offset}"
        )
