"""Radius distributions of the ``insertion`` entries (``distribution``, selected by its
``kind``: ``mono``, ``uniform``, ``truncated_normal``, ``lognormal`` or ``discrete``), SI
units. Their sampling is :mod:`thermodem.geometry.distributions`."""

from __future__ import annotations

import math
from typing import Annotated, Literal

import numpy as np
from pydantic import (
    Field,
    model_validator,
)
from scipy.special import ndtr

from thermodem.config.base import StrictModel

PositiveLength = Annotated[float, Field(gt=0, allow_inf_nan=False)]
"""A strictly positive, finite length [m]."""

FRACTION_SUM_TOLERANCE = 1e-9
"""Allowed deviation of the sum of discrete fractions from 1."""


class MonoRadius(StrictModel):
    """Every particle has the same radius."""

    kind: Literal["mono"] = "mono"
    radius: PositiveLength = Field(description="particle radius [m]")

    @property
    def max_radius_bound(self) -> float:
        """Largest radius the distribution can produce [m]."""
        return self.radius


class UniformRadius(StrictModel):
    """Radius uniformly distributed (by number) on ``[min_radius, max_radius]``."""

    kind: Literal["uniform"] = "uniform"
    min_radius: PositiveLength = Field(description="smallest radius [m]")
    max_radius: PositiveLength = Field(description="largest radius [m]")

    @model_validator(mode="after")
    def _check_bounds(self) -> UniformRadius:
        if not self.min_radius <= self.max_radius:
            raise ValueError(
                f"uniform radius distribution: min_radius={self.min_radius!r} must be <= "
                f"max_radius={self.max_radius!r}"
            )
        return self

    @property
    def max_radius_bound(self) -> float:
        """Largest radius the distribution can produce [m]."""
        return self.max_radius


def _normal_interval_mass(alpha: float, beta: float) -> float:
    """Probability of a standard normal variable in ``[alpha, beta]``, accurate in the tails."""
    if alpha > 0.0:
        alpha, beta = -beta, -alpha
    return float(ndtr(beta) - ndtr(alpha))


class TruncatedNormalRadius(StrictModel):
    """Normal distribution (by number) truncated to ``[min_radius, max_radius]``.

    ``mean`` and ``std`` are the parameters of the parent (untruncated) normal distribution; the
    mean and standard deviation of the truncated distribution differ unless the truncation is far
    in the tails.
    """

    kind: Literal["truncated_normal"] = "truncated_normal"
    mean: PositiveLength = Field(description="mean of the parent normal distribution [m]")
    std: PositiveLength = Field(description="standard deviation of the parent normal [m]")
    min_radius: PositiveLength = Field(description="lower truncation radius [m]")
    max_radius: PositiveLength = Field(description="upper truncation radius [m]")

    @model_validator(mode="after")
    def _check_bounds(self) -> TruncatedNormalRadius:
        if not self.min_radius < self.max_radius:
            raise ValueError(
                f"truncated_normal radius distribution: min_radius={self.min_radius!r} must be "
                f"< max_radius={self.max_radius!r}"
            )
        alpha = (self.min_radius - self.mean) / self.std
        beta = (self.max_radius - self.mean) / self.std
        if not _normal_interval_mass(alpha, beta) > 0.0:
            raise ValueError(
                f"truncated_normal radius distribution: the interval [{self.min_radius!r}, "
                f"{self.max_radius!r}] lies so far in the tail of N(mean={self.mean!r}, "
                f"std={self.std!r}) that it has zero probability; move the bounds towards the "
                "mean or increase std"
            )
        return self

    @property
    def max_radius_bound(self) -> float:
        """Largest radius the distribution can produce [m]."""
        return self.max_radius


class LognormalRadius(StrictModel):
    """Log-normal distribution (by number): ``ln r`` is normal with standard deviation ``sigma``.

    Give exactly one of ``median`` (= exp(mu)) or ``mean`` (= exp(mu + sigma^2/2)) of the
    untruncated distribution. ``min_radius``/``max_radius`` optionally truncate it.
    """

    kind: Literal["lognormal"] = "lognormal"
    median: PositiveLength | None = Field(default=None, description="median radius [m]")
    mean: PositiveLength | None = Field(
        default=None, description="mean radius of the untruncated distribution [m]"
    )
    sigma: float = Field(gt=0, allow_inf_nan=False, description="standard deviation of ln r [-]")
    min_radius: PositiveLength | None = Field(default=None, description="lower truncation [m]")
    max_radius: PositiveLength | None = Field(default=None, description="upper truncation [m]")

    @model_validator(mode="after")
    def _check(self) -> LognormalRadius:
        if (self.median is None) == (self.mean is None):
            raise ValueError(
                "lognormal radius distribution: give exactly one of 'median' or 'mean', got "
                f"median={self.median!r} and mean={self.mean!r}"
            )
        if (
            self.min_radius is not None
            and self.max_radius is not None
            and not self.min_radius < self.max_radius
        ):
            raise ValueError(
                f"lognormal radius distribution: min_radius={self.min_radius!r} must be < "
                f"max_radius={self.max_radius!r}"
            )
        alpha = -math.inf if self.min_radius is None else (math.log(self.min_radius) - self.mu)
        beta = math.inf if self.max_radius is None else (math.log(self.max_radius) - self.mu)
        if not _normal_interval_mass(alpha / self.sigma, beta / self.sigma) > 0.0:
            raise ValueError(
                f"lognormal radius distribution: the truncation interval [{self.min_radius!r}, "
                f"{self.max_radius!r}] has zero probability for median={math.exp(self.mu)!r} "
                f"and sigma={self.sigma!r}; move the bounds towards the median"
            )
        return self

    @property
    def mu(self) -> float:
        """Mean of ``ln r`` of the untruncated distribution."""
        if self.median is not None:
            return math.log(self.median)
        assert self.mean is not None
        return math.log(self.mean) - 0.5 * self.sigma**2

    @property
    def max_radius_bound(self) -> float | None:
        """Largest radius the distribution can produce [m] (None: unbounded)."""
        return self.max_radius


class DiscreteRadius(StrictModel):
    """A finite set of radii with the fraction of each, by number or by mass.

    With ``fraction_basis: mass`` the fractions are mass fractions; since every particle of an
    entry has the same material, a particle's mass is proportional to r^3 and the number
    fractions are ``n_i = (w_i / r_i^3) / sum_j (w_j / r_j^3)``.
    """

    kind: Literal["discrete"] = "discrete"
    radii: list[PositiveLength] = Field(min_length=1, description="the radii [m]")
    fractions: list[Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)]] = Field(
        min_length=1, description="fraction of each radius [-], summing to 1"
    )
    fraction_basis: Literal["number", "mass"] = Field(
        default="number", description="whether fractions are by particle number or by mass"
    )

    @model_validator(mode="after")
    def _check(self) -> DiscreteRadius:
        if len(self.radii) != len(self.fractions):
            raise ValueError(
                f"discrete radius distribution: radii has {len(self.radii)} entries but "
                f"fractions has {len(self.fractions)}; give one fraction per radius"
            )
        total = math.fsum(self.fractions)
        if abs(total - 1.0) > FRACTION_SUM_TOLERANCE:
            raise ValueError(
                f"discrete radius distribution: fractions {self.fractions!r} sum to {total!r}; "
                f"they must sum to 1 (within {FRACTION_SUM_TOLERANCE:g})"
            )
        return self

    def number_fractions(self) -> np.ndarray:
        """Fraction by number of each radius (converted from mass fractions if needed)."""
        w = np.asarray(self.fractions, dtype=np.float64)
        if self.fraction_basis == "mass":
            w = w / np.asarray(self.radii, dtype=np.float64) ** 3
        return w / w.sum()

    @property
    def max_radius_bound(self) -> float:
        """Largest radius the distribution can produce [m] (only radii with nonzero fraction)."""
        return max(r for r, f in zip(self.radii, self.fractions, strict=True) if f > 0)


RadiusDistribution = Annotated[
    MonoRadius | UniformRadius | TruncatedNormalRadius | LognormalRadius | DiscreteRadius,
    Field(discriminator="kind"),
]
"""One radius distribution, selected by ``kind``."""
