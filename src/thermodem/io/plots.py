"""PNG figures of an output directory's ``timeseries.csv`` (matplotlib, Agg backend).

:func:`plot_directory` writes, into ``OUT/plots/`` by default:

- ``energies.png``: stored energies (kinetic, elastic, gravitational relative to the first
  row) and, below, the cumulative dissipation by mechanism, wall work, inserted energy and the
  energy balance error;
- ``contacts.png``: contact and particle counts, and the largest overlap ratio;
- ``temperature.png`` (when the run has ``temperature_*`` columns): mean, min and max;
- ``heat.png`` (when it has ``heat_rate_*`` or ``heat_*`` columns): heat rate by mechanism
  and the cumulative heat ledger;
- ``generation.png`` (with a heat generation model): the heat rate generated per mechanism
  and, below, per mechanism the heat generated (χ × dissipated), into the particles and to
  the walls, and the generation balance error.

Columns are picked by name, so new columns reported by the engine appear without changes here
as long as they follow the prefixes.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from thermodem.errors import ConfigError


def _figure(rows: int):  # noqa: ANN202
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(8.0, 3.2 * rows), layout="constrained")
    FigureCanvasAgg(fig)
    axes = fig.subplots(rows, 1, sharex=True, squeeze=False)[:, 0]
    return fig, axes


def _plot(ax, t: np.ndarray, data: dict[str, np.ndarray], names: list[str], ylabel: str) -> bool:  # noqa: ANN001
    drawn = False
    for name in names:
        if name in data and np.any(np.isfinite(data[name])):
            ax.plot(t, data[name], label=name)
            drawn = True
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    if drawn:
        ax.legend(fontsize="small", loc="best")
    return drawn


#: Every figure :func:`plot_directory` may write.
FIGURES = ("energies.png", "contacts.png", "temperature.png", "heat.png", "generation.png")


def _plot_target(directory: Path, out: str | os.PathLike[str] | None, overwrite: bool) -> Path:
    """The directory the figures go to, made; ConfigError for a path under a file, and for
    figures of the same names in a directory of the user's choice (``--out``) unless
    ``overwrite`` (``DIR/plots`` is thermodem's own and is replaced)."""
    target = Path(out) if out is not None else directory / "plots"
    for parent in (target, *target.parents):
        if parent.exists():
            if not parent.is_dir():
                where = "is a file" if parent == target else f"is under the file {str(parent)!r}"
                raise ConfigError(
                    f"--out {str(target)!r} {where}, not a directory; choose another --out"
                )
            break
    own = out is None or target.resolve() == (directory / "plots").resolve()
    if not own and not overwrite and target.is_dir():
        existing = [name for name in FIGURES if (target / name).exists()]
        if existing:
            raise ConfigError(
                f"--out {str(target)!r} already holds {', '.join(existing)}, which this would "
                "replace; give --overwrite to replace them, or another --out"
            )
    try:
        target.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ConfigError(f"--out {str(target)!r} cannot be made: {exc.strerror}") from None
    return target


def plot_directory(
    directory: str | os.PathLike[str],
    out: str | os.PathLike[str] | None = None,
    overwrite: bool = False,
) -> list[Path]:
    """Write the figures; returns their paths. ConfigError without a readable time series, or
    for an ``out`` that is a file or holds figures of the same names (unless ``overwrite``)."""
    from thermodem.engine.runner import TIMESERIES_FILE, read_timeseries

    directory = Path(directory)
    path = directory / TIMESERIES_FILE
    if not path.is_file():
        from thermodem.io.run_files import never_ran

        why = never_ran(directory) if directory.is_dir() else ""
        raise ConfigError(
            f"{path} does not exist" + (why or f": is {str(directory)!r} a thermodem output?")
        )
    data = read_timeseries(path)
    if "time" not in data or data["time"].size == 0:
        raise ConfigError(f"{path} has no rows yet")
    given = f"--out {str(out)!r}" if out is not None else f"{str(directory / 'plots')!r} (no --out)"
    try:
        target = _plot_target(directory, out, overwrite)
    except OSError as exc:  # (a name too long, no permission)
        raise ConfigError(
            f"{given} cannot be used: {exc.strerror or exc}; choose another --out"
        ) from None
    t = data["time"]
    written: list[Path] = []

    def save(fig, name: str) -> None:  # noqa: ANN001
        fig.axes[-1].set_xlabel("time [s]")
        file = target / name
        try:
            fig.savefig(file, dpi=110)
        except OSError as exc:  # (a file system that refuses it: read-only, /proc, full)
            raise ConfigError(
                f"{given}: {name} cannot be written: {exc.strerror or exc}; choose another --out"
            ) from None
        written.append(file)

    # energies
    fig, (ax1, ax2) = _figure(2)
    stored = [k for k in data if k.startswith(("kinetic_", "elastic_"))]
    if "gravitational" in data:
        data["gravitational - initial"] = data["gravitational"] - data["gravitational"][0]
        stored.append("gravitational - initial")
    _plot(ax1, t, data, stored, "stored energy [J]")
    ledger = [k for k in data if k.startswith("dissipated_")]
    ledger += ["wall_work", "stiffness_work", "inserted_energy", "energy_balance_error"]
    _plot(ax2, t, data, ledger, "cumulative [J]")
    fig.suptitle(f"energies: {directory.name}")
    save(fig, "energies.png")

    # contacts
    fig, (ax1, ax2) = _figure(2)
    _plot(ax1, t, data, ["contact_count", "particle_count"], "count")
    _plot(ax2, t, data, ["max_overlap_ratio"], "largest overlap / radius")
    fig.suptitle(f"contacts: {directory.name}")
    save(fig, "contacts.png")

    # temperatures
    temps = [k for k in data if k.startswith("temperature_")]
    if temps:
        fig, (ax,) = _figure(1)
        _plot(ax, t, data, temps, "temperature [K]")
        fig.suptitle(f"temperature: {directory.name}")
        save(fig, "temperature.png")

    # heat
    rates = [k for k in data if k.startswith("heat_rate_")]
    ledger = [k for k in data if k.startswith("heat_") and k not in rates]
    if rates or ledger:
        fig, axes = _figure(2 if rates and ledger else 1)
        k = 0
        if rates:
            _plot(axes[k], t, data, rates, "heat rate [W]")
            k += 1
        if ledger:
            _plot(axes[k], t, data, ledger, "cumulative heat [J]")
        fig.suptitle(f"heat: {directory.name}")
        save(fig, "heat.png")

    # heat generation by mechanism
    gen_rates = [k for k in data if k.startswith("heat_rate_generation_")]
    if gen_rates:
        fig, (ax1, ax2) = _figure(2)
        _plot(ax1, t, data, gen_rates, "generated heat rate [W]")
        cumulative = [
            k
            for k in data
            if k.startswith(("generated_", "heat_in_generation_", "heat_to_walls_generation_"))
        ]
        _plot(ax2, t, data, [*cumulative, "generation_balance_error"], "cumulative [J]")
        fig.suptitle(f"heat generation: {directory.name}")
        save(fig, "generation.png")
    return written
