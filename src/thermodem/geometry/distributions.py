"""Radius distributions: sampling particle radii for insertion.

:func:`sample_radii` draws radii from a radius distribution model of the case
(:mod:`thermodem.config.insertion`); :func:`_radii_for_volume` draws until a total sphere volume
is reached. All randomness goes through the :class:`numpy.random.Generator` the caller passes in.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from scipy.special import ndtr, ndtri

from thermodem.config.insertion import (
    DiscreteRadius,
    LognormalRadius,
    MonoRadius,
    TruncatedNormalRadius,
    UniformRadius,
)


def _open_uniform(rng: np.random.Generator, count: int) -> np.ndarray:
    """Uniform samples on the open interval (0, 1) (``rng.random`` may return exactly 0)."""
    k = np.floor(rng.random(count) * 2.0**53)
    return (k + 0.5) / 2.0**53


def _truncated_standard_normal(
    alpha: float, beta: float, count: int, rng: np.random.Generator
) -> np.ndarray:
    """Standard normal samples restricted to ``[alpha, beta]`` by inverse-CDF sampling.

    An interval entirely in the upper tail is mirrored into the lower tail, where the normal CDF
    is represented accurately.
    """
    flip = alpha > 0.0
    if flip:
        alpha, beta = -beta, -alpha
    p_lo = float(ndtr(alpha))
    p_hi = float(ndtr(beta))
    z = ndtri(p_lo + _open_uniform(rng, count) * (p_hi - p_lo))
    z = np.clip(z, alpha, beta)
    return -z if flip else z


def sample_radii(dist: Any, count: int, rng: np.random.Generator) -> np.ndarray:
    """Draw ``count`` radii [m] from a radius distribution model (float64 array)."""
    count = int(count)
    if count < 0:
        raise ValueError(f"count must be >= 0, got {count}")
    if isinstance(dist, MonoRadius):
        return np.full(count, dist.radius, dtype=np.float64)
    if isinstance(dist, UniformRadius):
        return rng.uniform(dist.min_radius, dist.max_radius, count)
    if isinstance(dist, TruncatedNormalRadius):
        alpha = (dist.min_radius - dist.mean) / dist.std
        beta = (dist.max_radius - dist.mean) / dist.std
        r = dist.mean + dist.std * _truncated_standard_normal(alpha, beta, count, rng)
        return np.clip(r, dist.min_radius, dist.max_radius)
    if isinstance(dist, LognormalRadius):
        mu, sigma = dist.mu, dist.sigma
        alpha = -math.inf if dist.min_radius is None else (math.log(dist.min_radius) - mu) / sigma
        beta = math.inf if dist.max_radius is None else (math.log(dist.max_radius) - mu) / sigma
        r = np.exp(mu + sigma * _truncated_standard_normal(alpha, beta, count, rng))
        return np.clip(r, dist.min_radius, dist.max_radius)
    if isinstance(dist, DiscreteRadius):
        radii = np.asarray(dist.radii, dtype=np.float64)
        return radii[rng.choice(radii.size, size=count, p=dist.number_fractions())]
    raise TypeError(f"unknown radius distribution {type(dist).__name__}")


def _measure(r: np.ndarray, planar: bool) -> np.ndarray:
    """Sphere volumes 4/3 π r³, or disc areas π r² (``planar``: a 2D case fills areas)."""
    return np.pi * r**2 if planar else 4.0 / 3.0 * np.pi * r**3


def _radii_for_volume(
    dist: Any, volume: float, rng: np.random.Generator, planar: bool = False
) -> np.ndarray:
    """Radii drawn one after another until their summed sphere volume (``planar``: disc area)
    reaches ``volume``."""
    chunks: list[np.ndarray] = []
    total = 0.0
    size = 1024
    while total < volume:
        r = sample_radii(dist, size, rng)
        chunks.append(r)
        total += float(np.sum(_measure(r, planar)))
        size *= 2
    radii = np.concatenate(chunks)
    cumulative = np.cumsum(_measure(radii, planar))
    n = int(np.searchsorted(cumulative, volume)) + 1
    return radii[: min(n, radii.size)]


def mean_sphere_volume(dist: Any, samples: int = 8192, planar: bool = False) -> float:
    """Mean sphere volume 4/3 π E[r³] [m³] of a radius distribution: exact for ``mono`` and
    ``discrete``, else estimated from ``samples`` radii drawn with a fixed seed of their own
    (the run's generator is not touched, so the particles of the run do not change). Used to
    judge whether a requested count can fit a region before drawing it. ``planar`` (a 2D
    case): the mean disc area π E[r²] [m²] instead."""
    if planar:
        if isinstance(dist, MonoRadius):
            return math.pi * dist.radius**2
        if isinstance(dist, DiscreteRadius):
            radii = np.asarray(dist.radii, dtype=np.float64)
            return float(math.pi * np.sum(dist.number_fractions() * radii**2))
        r = sample_radii(dist, samples, np.random.default_rng(20240601))
        return float(math.pi * np.mean(r**2))
    if isinstance(dist, MonoRadius):
        return 4.0 / 3.0 * math.pi * dist.radius**3
    if isinstance(dist, DiscreteRadius):
        radii = np.asarray(dist.radii, dtype=np.float64)
        return float(4.0 / 3.0 * math.pi * np.sum(dist.number_fractions() * radii**3))
    r = sample_radii(dist, samples, np.random.default_rng(20240601))
    return float(4.0 / 3.0 * math.pi * np.mean(r**3))
