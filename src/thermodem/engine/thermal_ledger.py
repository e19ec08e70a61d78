"""The thermal engine's heat ledger and checkpoint state: U = Σ m c T, the boundary heat,
the balance error, the summary, and the state saved in and loaded from checkpoints.

A mixin of :class:`thermodem.engine.thermal.ThermalEngine` (split from that module by concern).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from thermodem.engine import generation
from thermodem.engine.external_set import ExternalPairSet
from thermodem.engine.fields import STATE_PREFIX as FIELDS_PREFIX
from thermodem.errors import ConfigError
from thermodem.kernels import thermal as kernels
from thermodem.state import heat

#: Attributes never saved in checkpoints (objects, back references, derived tables).
SKIP = ("sim", "settings", "conditions", "contact", "terms", "generation", "range_set",
        "external", "_empty",
        "_conditions_key", "field_provider", "fields", "voronoi", "external_wall_conductance",
        "external_stamp", "implicit", "record_conductances")  # fmt: skip
#: Prefixes of the pair sets' state in the engine's checkpoint scalars and arrays.
RANGE_PREFIX = "range_set__"
EXTERNAL_PREFIX = "external__"
VORONOI_PREFIX = "voronoi__"
IMPLICIT_PREFIX = "implicit__"


class ThermalLedger:
    """Ledger and checkpoint state of the thermal engine (see the module docstring)."""

    # ---------------------------------------------------------------------------- ledger
    def thermal_energy(self, mask: np.ndarray | None = None) -> float:
        """Σ m c T over all particles (or ``mask``) [J] (Σ m h(T) with a tabulated c)."""
        p = self.sim.particles
        n = self.sim.owned_count  # (all particles; on several MPI ranks the owned ones)
        t, m, ty = p.temperature[:n], p.mass[:n], p.type_id[:n]
        if mask is not None:
            t, m, ty = t[mask[:n]], m[mask[:n]], ty[mask[:n]]
        if self.has_c_table:
            return self.sim.sum_over_ranks(
                kernels.total_enthalpy(t, m, ty, self.c_t, self.c_v, self.c_n)
            )
        return self.sim.sum_over_ranks(float(np.sum(m * self.specific_heat_by_type[ty] * t)))

    def inserted(self, temperature: np.ndarray, mass: np.ndarray, type_id: np.ndarray) -> None:
        """Ledger the thermal energy that inserted particles bring in."""
        if self.has_c_table:
            e = kernels.total_enthalpy(temperature, mass, type_id, self.c_t, self.c_v, self.c_n)
        else:
            e = float(np.sum(mass * self.specific_heat_by_type[type_id] * temperature))
        self.cumulative["inserted_heat"] += e

    def boundary_heat(self) -> float:
        """Heat that entered the particles through every boundary mechanism so far [J]."""
        return sum(v for k, v in self.cumulative.items() if k.startswith("heat_in_"))

    def balance_error(self) -> float:
        """U(t) - U(0) - boundary heat + heat absorbed by fixed particles - heat of inserted
        particles - resets of newly fixed particles [J]; round-off."""
        cum = self.cumulative
        return (self.thermal_energy() - self.initial_energy - self.boundary_heat()
                + cum["fixed_absorbed"] - cum["inserted_heat"] - cum["fixed_reset"])  # fmt: skip

    def summary(self) -> dict[str, float]:
        """Temperature statistics, heat rates by mechanism [W] and the heat ledger [J].

        ``heat_rate_<mechanism>``: for pairwise mechanisms the heat exchanged, ½ Σ|Q_i| (they
        sum to zero); for boundary mechanisms the net heat into the particles, Σ Q_i.
        """
        self.complete_rates()
        p = self.sim.particles
        out: dict[str, float] = {}
        if p.count:
            out.update(temperature_mean=float(p.temperature.mean()),
                       temperature_min=float(p.temperature.min()),
                       temperature_max=float(p.temperature.max()))  # fmt: skip
        for k in self.in_use:
            mech = heat.MECHANISMS[k]
            col = p.heat_rate_by_mechanism[:, k]
            total = float(col.sum()) if mech.boundary else 0.5 * float(np.abs(col).sum())
            out[f"heat_rate_{mech.name}"] = total
        out["thermal_energy"] = self.thermal_energy()
        for k in self.in_use:
            if heat.MECHANISMS[k].boundary:
                name = f"heat_in_{heat.HEAT_MECHANISMS[k]}"
                out[name] = self.cumulative[name]
        out.update({k: v for k, v in self.cumulative.items() if not k.startswith("heat_in_")})
        out["heat_balance_error"] = self.balance_error()
        if self.generation.active:
            out.update(generation.ledger(self))
        out["thermal_limit"] = self.limit
        if self.range_set is not None:
            out["range_pair_count"] = self.range_set.count
        if self.voronoi is not None:
            out["voronoi_pair_count"] = self.external.count
            out["tessellation_count"] = self.voronoi.count
            out["tessellation_seconds"] = self.voronoi.seconds
            out["voronoi_evaluated_fraction"] = self.external_evaluations / max(
                self.external_pair_steps, 1
            )
        return out

    # ------------------------------------------------------------------------ checkpoints
    def state_dict(self) -> dict[str, Any]:
        """Scalars and arrays of the engine (the range set's under ``range_set`` and
        ``range_set__<array>``), the layout the checkpoint writer stores."""
        from thermodem.engine.restart import _object_state

        state = _object_state(self, SKIP)
        for name, prefix in (("range_set", RANGE_PREFIX), ("external", EXTERNAL_PREFIX)):
            pairs = getattr(self, name)
            if pairs is not None:
                sub = pairs.state_dict()
                state["scalars"][name] = sub["scalars"]
                state["arrays"].update({f"{prefix}{k}": v for k, v in sub["arrays"].items()})
        if self.voronoi is not None:
            sub = self.voronoi.state_dict()
            state["scalars"]["voronoi"] = sub["scalars"]
            state["arrays"].update({f"{VORONOI_PREFIX}{k}": v for k, v in sub["arrays"].items()})
        if self.field_provider.active:
            sub = self.field_provider.state_dict()
            state["scalars"]["field_provider"] = sub["scalars"]
            state["arrays"].update({f"{FIELDS_PREFIX}{k}": v for k, v in sub["arrays"].items()})
        if self.implicit is not None:
            sub_scalars, sub_arrays = self.implicit.state()
            if sub_scalars:
                state["scalars"]["implicit"] = sub_scalars
                state["arrays"].update({f"{IMPLICIT_PREFIX}{k}": v for k, v in sub_arrays.items()})
        return state

    def load_state_dict(self, state: dict[str, Any]) -> None:
        scalars = dict(state["scalars"])
        arrays = dict(state["arrays"])
        range_scalars = scalars.pop("range_set", None)
        range_arrays = {
            k[len(RANGE_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(RANGE_PREFIX)
        }
        field_scalars = scalars.pop("field_provider", None)
        field_arrays = {
            k[len(FIELDS_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(FIELDS_PREFIX)
        }
        implicit_scalars = scalars.pop("implicit", None)
        implicit_arrays = {
            k[len(IMPLICIT_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(IMPLICIT_PREFIX)
        }
        voronoi_scalars = scalars.pop("voronoi", None)
        voronoi_arrays = {
            k[len(VORONOI_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(VORONOI_PREFIX)
        }
        external_scalars = scalars.pop("external", None)
        external_arrays = {
            k[len(EXTERNAL_PREFIX) :]: arrays.pop(k)
            for k in list(arrays)
            if k.startswith(EXTERNAL_PREFIX)
        }
        from thermodem.engine.restart import check_thermal_arrays, keep_derived_thermal

        # tables and ids made from the case stay this case's (a restart may change the case)
        changed = keep_derived_thermal(self, scalars, arrays)
        check_thermal_arrays(self, arrays)
        for name, value in scalars.items():
            current = getattr(self, name, None)
            if isinstance(current, float) and value is not None:
                value = float(value)
            if isinstance(current, dict):
                value = {k: float(v) for k, v in value.items()}
            setattr(self, name, value)
        for name, value in arrays.items():
            setattr(self, name, np.array(value, copy=True))
        if changed:  # conductances kept from the old case's models are stale
            self.conductance_ready = False
            self.term_ready[:] = False
        if self.range_set is not None:
            if range_scalars is None:
                raise ConfigError(
                    "checkpoint has no range pair set but this case's thermal terms need one "
                    "(thermal.indirect_conduction, or a direct model that conducts across gaps)"
                )
            self.range_set.load_state_dict({"scalars": range_scalars, "arrays": range_arrays})
        if external_scalars is not None:
            if self.external is None:  # a script had put a term on an external set
                self.set_external_term(self.external_term, ExternalPairSet())
            self.external.load_state_dict({"scalars": external_scalars, "arrays": external_arrays})
        if self.voronoi is not None:
            if voronoi_scalars is None:
                raise ConfigError(
                    f"checkpoint has no tessellation state but this case's {self.external_term}"
                    " is a Voronoi model"
                )
            self.voronoi.load_state_dict({"scalars": voronoi_scalars, "arrays": voronoi_arrays})
        if field_scalars is not None and self.field_provider.active:
            self.field_provider.load_state_dict({"scalars": field_scalars, "arrays": field_arrays})
        if implicit_scalars is not None and self.implicit is not None:
            self.implicit.load_state(implicit_scalars, implicit_arrays)
        self.conditions.invalidate()
