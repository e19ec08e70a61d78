"""Heat generation at a thermal step: the accumulated dissipated energy becomes heat rates.

The contact passes (``kernels/pair_pass.py``, :func:`thermodem.kernels.contact.deposit_pair`)
add each contact's dissipated energy of every mechanical step, per mechanism, to its particles'
accumulators ``Particles.generation_energy`` (shared by the partition coefficient). A thermal
step of length Δt_th covers the mechanical steps since the previous one, so the particle's heat
rate of mechanism g over the step is Q = χ E_g / Δt_th, and Q Δt_th = χ E_g: the energy of
every mechanical step (sub-cycled or not) is turned into heat exactly once. The engine clears
the accumulators after the thermal step has used them.
"""

from __future__ import annotations

from numba import prange

from thermodem.kernels.variants import parallel_kernel
from thermodem.state.heat import M_GENERATION

CHUNK = 4096  # particles per parallel chunk


@parallel_kernel(error_model="numpy")
def generation_heat(energy, select, conversion_fraction, dt, by_mechanism):
    """Write χ E_g / Δt into the generation column of every selected mechanism g (the other
    generation columns are left as they are: zero)."""
    n = energy.shape[0]
    ng = energy.shape[1]
    scale = conversion_fraction / dt
    for c in prange((n + CHUNK - 1) // CHUNK):
        for i in range(c * CHUNK, min(n, (c + 1) * CHUNK)):
            for g in range(ng):
                if select[g] != 0.0:
                    by_mechanism[M_GENERATION + g, i] = scale * energy[i, g]
