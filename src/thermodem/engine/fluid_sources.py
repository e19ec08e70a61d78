"""The fluid at each particle: the fluid temperature T_f, velocity u_f and properties of
``thermal.fluid`` (uniform, a table of time, an expression of (t, x, y, z), a grid file) and
the relative speed |u_f − v_p|, in the rows of the per-particle field array.

A mixin of :class:`thermodem.engine.fields.FieldProvider` (split from that module by concern:
the provider's set-up and the state it reads and writes are the provider's, its module
docstring describes every field).
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np

from thermodem.config.fluid import (
    ExpressionSource,
    GridSource,
    LiquidFluid,
    TableSource,
    UniformSource,
)
from thermodem.errors import ConfigError, SimulationError
from thermodem.kernels import fields as fk

#: Ideal gas constant [J/(mol K)] (exact, SI 2019).
GAS_CONSTANT = 8.314462618


class FluidSources:
    """The fluid sources of the field provider (see the module docstring)."""

    # ---------------------------------------------------------------------- set-up
    def _source(self, source: Any, name: str, components: int) -> Any:
        key = f"thermal.fluid.{name}"
        if isinstance(source, GridSource):
            from thermodem.io.grid_field import read_grid_field

            try:
                axes, values = read_grid_field(source.file, source.field, components,
                                               source.location)  # fmt: skip
            except ValueError as exc:
                raise ConfigError(f"{key}.file: {exc}") from None
            if components == 1 and not (values > 0).all():
                k = np.argwhere(values <= 0)[0]
                raise ConfigError(
                    f"{key}.file: temperature {float(values[tuple(k)])!r} K at grid index "
                    f"{tuple(int(v) for v in k[:3])} of {source.file}; temperatures must be > 0"
                )
            return ("grid", axes, values, source.file)
        if isinstance(source, ExpressionSource):
            from thermodem.engine.expressions import compile_expression

            return ("expression", [compile_expression(e, ("t", "x", "y", "z"))
                                   for e in source.expression], source.expression)  # fmt: skip
        if isinstance(source, TableSource):
            table = np.asarray(source.table, np.float64)
            return ("table", table)
        assert isinstance(source, UniformSource)
        return ("uniform", np.asarray(source.value, np.float64))

    def _properties_setup(self) -> None:
        props = self.fluid.properties
        if isinstance(props, LiquidFluid):
            for col, value in (
                (fk.F_FLUID_CONDUCTIVITY, props.thermal_conductivity),
                (fk.F_FLUID_DENSITY, props.density),
                (fk.F_FLUID_SPECIFIC_HEAT, props.specific_heat),
                (fk.F_FLUID_VISCOSITY, props.dynamic_viscosity),
            ):
                if isinstance(value, list):
                    arr = np.asarray(value, np.float64)
                    nodes = np.ascontiguousarray(arr[:, 0])
                    vals = np.ascontiguousarray(arr[:, 1])
                    self._property_tables.append((col, nodes, vals, False))
                    if col == fk.F_FLUID_VISCOSITY:
                        self._property_tables.append((fk.F_SURFACE_VISCOSITY, nodes, vals, True))
                else:
                    self._constant_properties[col] = float(value)
                    if col == fk.F_FLUID_VISCOSITY:
                        self._constant_properties[fk.F_SURFACE_VISCOSITY] = float(value)
            if props.thermal_expansion is not None:
                self.beta_mode, self.beta = 2, float(props.thermal_expansion)
        else:
            gas = self.settings.gas
            density = gas_density(gas)
            self._constant_properties = {
                fk.F_FLUID_CONDUCTIVITY: gas.thermal_conductivity,
                fk.F_FLUID_DENSITY: density,
                fk.F_FLUID_SPECIFIC_HEAT: gas.specific_heat,
                fk.F_FLUID_VISCOSITY: gas.dynamic_viscosity,
                fk.F_SURFACE_VISCOSITY: gas.dynamic_viscosity,
            }
            self.beta_mode = 1  # ideal gas: β = 1/T_f
        c = self._constant_properties
        if not self._property_tables:
            pr = (c[fk.F_FLUID_SPECIFIC_HEAT] * c[fk.F_FLUID_VISCOSITY]
                  / c[fk.F_FLUID_CONDUCTIVITY])  # fmt: skip
            c[fk.F_PRANDTL] = pr
            c[fk.F_PRANDTL_CBRT] = pr ** (1.0 / 3.0)

    def grid_values(self, name: str) -> np.ndarray | None:
        """The values of the fluid field ``name`` ('temperature', 'velocity') as read from its
        grid file, or None when it is not a grid (or no selected model reads it)."""
        source = self._sources.get(name)
        return source[2] if source is not None and source[0] == "grid" else None

    # ---------------------------------------------------------------------- update
    def _outside_warning(self, key: str, file: str, count: int, axes: Any, time: float) -> None:
        """Once: the particles outside the grid (on several MPI ranks summed over the ranks,
        said by rank 0)."""
        if key in self.warned:
            return
        count = int(self.sim.sum_over_ranks(float(count)))  # (collective)
        if count:
            self.warned.append(key)
            if not self.sim.says_warnings:
                return
            extent = ", ".join(
                f"{a} {ax[0]:.6g}..{ax[-1]:.6g}" for a, ax in zip("xyz", axes, strict=True)
            )
            warnings.warn(
                f"{key}: {count} particles outside the grid of {file} ({extent} m) at step "
                f"{self.sim.step_count} (t = {time:.6g} s): they take the value at the nearest "
                "point of the grid's boundary (reported once)",
                RuntimeWarning,
                stacklevel=2,
            )

    def _temperature(self, time: float, fields: np.ndarray) -> None:
        p = self.sim.particles
        n = fields.shape[1]  # (the owned particles)
        source = self._sources["temperature"]
        kind = source[0]
        if kind == "uniform":
            return  # a constant column
        if kind == "table":
            table = source[1]
            fk.fill_column(fields, fk.F_FLUID_TEMPERATURE,
                           float(np.interp(time, table[:, 0], table[:, 1])))  # fmt: skip
        elif kind == "expression":
            pos = p.position[:n]
            values = np.broadcast_to(source[1][0](time, pos[:, 0], pos[:, 1], pos[:, 2]), (n,))
            bad = ~(np.isfinite(values) & (values > 0))
            error = None
            if bad.any():
                k = int(np.argmax(bad))
                error = SimulationError(
                    f"thermal.fluid.temperature: the expression {source[2][0]!r} gives "
                    f"{float(values[k])!r} K at particle {int(p.global_id[k])} (x, y, z = "
                    f"{tuple(float(v) for v in pos[k])}) at step {self.sim.step_count} "
                    f"(t = {time:.6g} s); temperatures must be finite and > 0",
                    self.sim.step_count,
                    time,
                    int(p.global_id[k]),
                )
            self.sim.agree_failure(error)  # (collective on several MPI ranks)
            fields[fk.F_FLUID_TEMPERATURE, :] = values
        else:
            _, axes, values, file = source
            outside = fk.grid_sample(p.position[:n], axes[0], axes[1], axes[2], values,
                                     fields, fk.F_FLUID_TEMPERATURE, self._part())  # fmt: skip
            self._outside_warning("thermal.fluid.temperature", file, outside, axes, time)

    def _velocity(self, time: float, fields: np.ndarray) -> None:
        p = self.sim.particles
        n = fields.shape[1]  # (the owned particles)
        source = self._sources["velocity"]
        kind = source[0]
        uniform = kind in ("uniform", "table")
        if kind == "uniform":
            self.velocity_buffer[:, 0] = source[1]
        elif kind == "table":
            table = source[1]
            for a in range(3):
                self.velocity_buffer[a, 0] = np.interp(time, table[:, 0], table[:, 1 + a])
        else:
            if self.velocity_buffer.shape[1] != n:
                self.velocity_buffer = np.zeros((3, n))
            if kind == "expression":
                pos = p.position[:n]
                for a in range(3):
                    self.velocity_buffer[a, :] = source[1][a](time, pos[:, 0], pos[:, 1],
                                                              pos[:, 2])  # fmt: skip
                bad = ~np.isfinite(self.velocity_buffer).all(axis=0)
                error = None
                if bad.any():
                    k = int(np.argmax(bad))
                    error = SimulationError(
                        f"thermal.fluid.velocity: the expressions {list(source[2])} give "
                        f"{self.velocity_buffer[:, k].tolist()} m/s at particle "
                        f"{int(p.global_id[k])} at step {self.sim.step_count} (t = {time:.6g} s)",
                        self.sim.step_count,
                        time,
                        int(p.global_id[k]),
                    )
                self.sim.agree_failure(error)  # (collective on several MPI ranks)
            else:
                _, axes, values, file = source
                outside = fk.grid_sample(p.position[:n], axes[0], axes[1], axes[2], values,
                                         self.velocity_buffer, 0, self._part())  # fmt: skip
                self._outside_warning("thermal.fluid.velocity", file, outside, axes, time)
        fk.relative_speed(p.velocity[:n], self.velocity_buffer, uniform, fields)

    def fluid_velocity(self) -> np.ndarray:
        """u_f at the particles at the last update [m/s], (n, 3) (or (1, 3) if uniform)."""
        return self.velocity_buffer.T.copy()


def gas_density(gas: Any) -> float:
    """ρ of the case gas [kg/m³]: ``density`` if given, else the ideal gas P M / (R T) of its
    ``pressure``, ``temperature`` and ``molar_mass``."""
    if getattr(gas, "density", None) is not None:
        return float(gas.density)
    if gas.pressure is None or gas.temperature is None:
        raise ConfigError(
            "thermal.gas.density: missing; needed by the convection models (the Reynolds "
            "number) when the gas gives mean_free_path instead of pressure and temperature: "
            "give thermal.gas.density [kg/m³]"
        )
    return float(gas.pressure * gas.molar_mass / (GAS_CONSTANT * gas.temperature))


__all__ = ["GAS_CONSTANT", "FluidSources", "gas_density"]
