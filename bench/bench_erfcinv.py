"""Micro-benchmark of erfc⁻¹ and of the Beaulieu (2020) resistance network conductance.

    python bench/bench_erfcinv.py [--n 1000000] [--repeat 7] [--seed 1]

Prints ns per call (best of ``--repeat`` timed passes of an njit loop over ``--n`` inputs; CPU
time of the thread, so that other processes on a shared machine inflate it less):

- ``erfcinv_iterative`` (the Newton/Halley routine, kept as reference) and ``erfcinv`` on three
  argument sets: the two arguments of realistic contacts (below), log-uniform x in
  [1e-300, 0.5] and uniform x in (0, 2);
- ``resistance_network_conductance`` and ``conductance_reference`` (the kernel as it was
  before the fast erfc⁻¹: each resistance function, ``**0.96``, iterative erfc⁻¹) over ``--n``
  random realistic contacts: F_n log-uniform in [1e-6, 1] N, R_i = 1 mm, R_j = 1 mm (10 % walls,
  R_j = inf), E = 1e7 Pa, ν = 0.3, H' log-uniform in [5e8, 2e9] Pa, σ = 1.4 µm, τ = 0.14,
  k = 1 W/(m K), air (k_g = 0.0263, M from α = 0.8), B = 0;

and the largest relative difference between the two conductances and between the two erfc⁻¹.
"""

from __future__ import annotations

import argparse
import math
import time

import numpy as np
from numba import njit

from thermodem.models.thermal import resistance_network as rn
from thermodem.models.thermal.contact_radius import effective_radius, hertz_radius_from_force

erfcinv = rn.erfcinv
erfcinv_iterative = getattr(rn, "erfcinv_iterative", rn.erfcinv)  # before: only the iterative


@njit(cache=False, error_model="numpy")
def conductance_reference(
    k_i, k_j, r_i, r_j, f_n, e_star, c_zhou, h_micro, sigma, tau, k_g, m_gas, b
):
    """The kernel before the fast erfc⁻¹ (each resistance by its function), for comparison."""
    r_eff = effective_radius(r_i, r_j)
    r_c = c_zhou * hertz_radius_from_force(f_n, r_eff, e_star)
    res_solid = rn.resistance_solid_layer(k_i, r_i, r_c) + rn.resistance_solid_layer(k_j, r_j, r_c)
    conductance = 1.0 / (res_solid + rn.resistance_macrogap(k_g, 2.0 * r_eff, r_c, m_gas, b))
    if r_c <= 0.0:
        return conductance
    k_h = 2.0 * k_i * k_j / (k_i + k_j)
    p0 = min(1.5 * f_n / (math.pi * r_c * r_c), h_micro)
    a1 = erfcinv_iterative(min(2.0 * p0 / h_micro, 1.0))
    a2 = erfcinv_iterative(0.03 * p0 / h_micro) - a1
    g_s = 1.0 / rn.resistance_microcontacts(k_h, r_c, p0, h_micro, sigma, tau)
    g_g = 1.0 / rn.resistance_microgap(k_g, r_c, sigma, a1, a2, m_gas)
    return conductance + 1.0 / (rn.resistance_contact_surface(k_h, r_c) + 1.0 / (g_s + g_g))


@njit(cache=False, error_model="numpy")
def loop_erfcinv(x, out):
    for i in range(x.size):
        out[i] = erfcinv(x[i])


@njit(cache=False, error_model="numpy")
def loop_erfcinv_iterative(x, out):
    for i in range(x.size):
        out[i] = erfcinv_iterative(x[i])


@njit(cache=False, error_model="numpy")
def loop_conductance(c, out):
    for i in range(c.shape[0]):
        out[i] = rn.resistance_network_conductance(
            c[i, 0], c[i, 1], c[i, 2], c[i, 3], c[i, 4], c[i, 5], c[i, 6],
            c[i, 7], c[i, 8], c[i, 9], c[i, 10], c[i, 11], c[i, 12],
        )  # fmt: skip


@njit(cache=False, error_model="numpy")
def loop_conductance_reference(c, out):
    for i in range(c.shape[0]):
        out[i] = conductance_reference(
            c[i, 0], c[i, 1], c[i, 2], c[i, 3], c[i, 4], c[i, 5], c[i, 6],
            c[i, 7], c[i, 8], c[i, 9], c[i, 10], c[i, 11], c[i, 12],
        )  # fmt: skip


def contacts(n: int, rng: np.random.Generator) -> np.ndarray:
    """(n, 13) rows of resistance_network_conductance arguments (see the module docstring)."""
    e_star = 1e7 / (2.0 * (1.0 - 0.3**2))
    gas = rn.GasProperties()
    m_gas = rn.gas_parameter(0.8, 0.8, gas)
    c = np.empty((n, 13))
    c[:, 0] = 1.0
    c[:, 1] = 1.0
    c[:, 2] = 1e-3
    c[:, 3] = np.where(rng.random(n) < 0.1, np.inf, 1e-3)
    c[:, 4] = 10.0 ** rng.uniform(-6.0, 0.0, n)
    c[:, 5] = e_star
    c[:, 6] = 1.0
    c[:, 7] = 10.0 ** rng.uniform(math.log10(5e8), math.log10(2e9), n)
    c[:, 8] = 1.4e-6
    c[:, 9] = 0.14
    c[:, 10] = gas.thermal_conductivity
    c[:, 11] = m_gas
    c[:, 12] = 0.0
    return c


def contact_arguments(c: np.ndarray) -> np.ndarray:
    """The two erfc⁻¹ arguments min(2P0/H', 1) and 0.03 P0/H' of each contact, interleaved."""
    r_eff = 1.0 / (1.0 / c[:, 2] + 1.0 / c[:, 3])
    r_c = (0.75 * c[:, 4] * r_eff / c[:, 5]) ** (1.0 / 3.0)
    p0 = np.minimum(1.5 * c[:, 4] / (np.pi * r_c**2), c[:, 7])
    x = np.empty(2 * len(c))
    x[0::2] = np.minimum(2.0 * p0 / c[:, 7], 1.0)
    x[1::2] = 0.03 * p0 / c[:, 7]
    return x


def ns_per_call(loop, data, repeat: int) -> tuple[float, np.ndarray]:
    out = np.empty(data.shape[0])
    loop(data[:10], out[:10])  # compile
    best = math.inf
    for _ in range(repeat):
        start = time.thread_time()
        loop(data, out)
        best = min(best, time.thread_time() - start)
    return best / data.shape[0] * 1e9, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    rng = np.random.default_rng(args.seed)
    c = contacts(args.n, rng)
    sets = {
        "contact arguments": contact_arguments(c)[: args.n],
        "log-uniform [1e-300, 0.5]": 0.5 * 10.0 ** rng.uniform(-300.0, 0.0, args.n),
        "uniform (0, 2)": rng.uniform(0.0, 2.0, args.n),
    }
    print(f"erfc^-1, ns per call ({args.n} calls, best of {args.repeat})")
    print(f"  {'arguments':28s} {'iterative':>10s} {'erfcinv':>10s}  max rel. diff")
    for name, x in sets.items():
        t_old, y_old = ns_per_call(loop_erfcinv_iterative, x, args.repeat)
        t_new, y_new = ns_per_call(loop_erfcinv, x, args.repeat)
        diff = np.max(np.abs(y_new - y_old) / np.abs(y_old))
        print(f"  {name:28s} {t_old:10.1f} {t_new:10.1f}  {diff:.1e}")
    print(f"resistance network conductance, ns per contact ({args.n} contacts)")
    t_old, g_old = ns_per_call(loop_conductance_reference, c, args.repeat)
    t_new, g_new = ns_per_call(loop_conductance, c, args.repeat)
    diff = np.max(np.abs(g_new - g_old) / np.abs(g_old))
    print(f"  reference (before) {t_old:7.1f}   resistance_network_conductance {t_new:7.1f}")
    print(f"  max rel. diff {diff:.1e}")


if __name__ == "__main__":
    main()
