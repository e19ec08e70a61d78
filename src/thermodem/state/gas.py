"""The interstitial gas of a case (case-file section ``thermal.gas``), shared by every model.

One gas fills the space between the particles for the whole case. Every thermal model that
needs it reads it from the :class:`~thermodem.state.materials.PairContext` its ``pack``
receives (``pair.gas``), never from its own parameters: the resistance network (k_g, and the
gas parameter M from Λ, Pr and γ), the Batchelor & O'Brien complete and modified models (k_f),
and the indirect conduction models. The convection models read it as the fluid's properties
when ``thermal.fluid.properties`` is ``gas`` (the default): k_g, c_p, μ and the density ρ_g
(``density``, or the ideal gas P M / (R T) of ``pressure``, ``temperature``, ``molar_mass``).
A model lists the gas properties it reads in its registry entry (``uses_gas``), which
``thermodem models`` prints.

The defaults are air at 300 K and 101325 Pa (Incropera et al. 2006, Fundamentals of Heat and
Mass Transfer, 6th ed., table A.4; kinetic diameter of air 0.366 nm): a case whose thermal
section gives no ``gas`` runs in air, and the resolved case (``thermodem validate``,
``OUT/case.resolved.yaml``) shows the values used.
"""

from __future__ import annotations

import math

from pydantic import Field, field_validator, model_validator

from thermodem.config.base import StrictModel

BOLTZMANN = 1.380649e-23  # J/K (exact, SI 2019)

#: Air at 300 K, 1 atm: what the mean free path is computed from when the case gives neither
#: ``mean_free_path`` nor these keys (each missing one takes its air value).
#: The largest heat capacity ratio accepted: 5/3 of a monatomic ideal gas, as 1.67 (rounded).
GAMMA_MAX = 1.67
#: Largest molar mass of a gas [kg/mol] (UF6 is 0.352; a value in g/mol is ~1000 times more).
MOLAR_MASS_MAX = 1.0

AIR_KINETIC = {"pressure": 101325.0, "temperature": 300.0, "molecular_diameter": 3.66e-10}


class GasProperties(StrictModel):
    """Interstitial gas; defaults: air at 300 K and 101325 Pa (Incropera et al. 2006,
    table A.4; kinetic diameter 0.366 nm).

    The mean free path is ``mean_free_path`` when given, else the kinetic theory value
    Λ = k_B T / (√2 π d² P) from ``pressure``, ``temperature`` and ``molecular_diameter`` (air
    values for those not given). Giving both is an error (one of them would be ignored).
    """

    thermal_conductivity: float = Field(default=0.0263, gt=0, description="k_g [W/(m K)]")
    specific_heat: float = Field(default=1007.0, gt=0, description="c_p,g [J/(kg K)]")
    dynamic_viscosity: float = Field(default=1.846e-5, gt=0, description="μ_g [Pa s]")
    heat_capacity_ratio: float = Field(
        default=1.4,
        ge=1,
        description="γ_g = c_p/c_v [-]; 1 is allowed (the limit of many internal degrees of "
        "freedom; Lethe's resistance tests use it): the factor 2γ/(1 + γ) of M is then 1",
    )
    mean_free_path: float | None = Field(
        default=None, gt=0, description="Λ [m]; null: from pressure, temperature, diameter"
    )
    pressure: float | None = Field(
        default=None, gt=0, description="P [Pa] for Λ; 101325 unless mean_free_path is given"
    )
    temperature: float | None = Field(
        default=None, gt=0, description="T [K] for Λ; 300 unless mean_free_path is given"
    )
    molecular_diameter: float | None = Field(
        default=None, gt=0, description="d [m] for Λ; 3.66e-10 unless mean_free_path is given"
    )
    density: float | None = Field(
        default=None,
        gt=0,
        description="ρ_g [kg/m³] (convection); null: the ideal gas "
        "P M / (R T) of pressure, temperature and molar_mass",
    )
    molar_mass: float = Field(
        default=0.0289647, gt=0, description="M [kg/mol] for the ideal-gas density (air)"
    )

    @field_validator("molar_mass")
    @classmethod
    def _kilograms_per_mole(cls, v: float) -> float:
        # (28.97, air in g/mol, ran with a density 1000 times too large)
        if v > MOLAR_MASS_MAX:
            raise ValueError(
                f"{v:g} kg/mol is heavier than any gas (uranium hexafluoride, among the "
                f"heaviest, 0.352 kg/mol); the unit is kg/mol: is it a value in g/mol? "
                f"({v:g} g/mol = {v / 1000:g} kg/mol); allowed: 0 < molar_mass <= "
                f"{MOLAR_MASS_MAX:g}"
            )
        return v

    @field_validator("heat_capacity_ratio")
    @classmethod
    def _ideal_gas_ratio(cls, v: float) -> float:
        # γ = 1 + 2/f for f >= 3 degrees of freedom: 5/3 (monatomic) is the largest; 1.67
        # (5/3 rounded) is allowed. A larger value is not a gas's (γ = 40 ran silently).
        if v > GAMMA_MAX:
            raise ValueError(
                "above 5/3, the largest c_p/c_v of a gas "
                "(monatomic 5/3, diatomic 1.4, polyatomic below; the rarefied-gas models read "
                f"it through 2γ/(1 + γ)); allowed: 1 <= heat_capacity_ratio <= {GAMMA_MAX:g}"
            )
        return v

    @model_validator(mode="after")
    def _mean_free_path_source(self) -> GasProperties:
        given = [k for k in AIR_KINETIC if getattr(self, k) is not None]
        if self.mean_free_path is not None:
            if given:
                values = ", ".join(f"{k} = {getattr(self, k)!r}" for k in given)
                raise ValueError(
                    "give either mean_free_path or pressure, temperature and molecular_diameter "
                    f"(from which it is computed), not both: got mean_free_path = "
                    f"{self.mean_free_path!r} and {values}"
                )
        else:
            for k, v in AIR_KINETIC.items():
                if getattr(self, k) is None:
                    self.__dict__[k] = v  # no re-validation (validate_assignment)
        return self

    def mean_free_path_value(self) -> float:
        """Λ [m]: the given value, or k_B T / (√2 π d² P)."""
        if self.mean_free_path is not None:
            return self.mean_free_path
        d2 = self.molecular_diameter**2
        return BOLTZMANN * self.temperature / (math.sqrt(2.0) * math.pi * d2 * self.pressure)

    def prandtl(self) -> float:
        """Pr = μ_g c_p,g / k_g [-]."""
        return self.dynamic_viscosity * self.specific_heat / self.thermal_conductivity

    def summary(self) -> str:
        """One line: the properties and the derived Λ and Pr."""
        source = (
            "given"
            if self.mean_free_path is not None
            else f"from P = {self.pressure:g} Pa, T = {self.temperature:g} K, "
            f"d = {self.molecular_diameter:g} m"
        )
        return (
            f"k_g = {self.thermal_conductivity:g} W/(m K), c_p = {self.specific_heat:g} "
            f"J/(kg K), μ = {self.dynamic_viscosity:g} Pa s, γ = {self.heat_capacity_ratio:g}, "
            f"Pr = {self.prandtl():.4g}, Λ = {self.mean_free_path_value():.4g} m ({source})"
        )
