"""Command line: ``thermodem run | validate | restart | info | plot | export | models``,
``thermodem --version`` (errors, exit codes and MPI ranks: cli_guard.py).

Exit codes: 0 success, 1 simulation failure, 2 bad input (case, arguments, files), 130 (143)
when a run was stopped by SIGINT (SIGTERM) after writing a checkpoint.
"""

from __future__ import annotations

from pathlib import Path

import typer

from thermodem.cli_guard import (
    EXIT_INPUT,
    _fail,
    _guarded,
    _guarded_mpi,
    _mpi_ranks,
    _one_rank,
)
from thermodem.errors import ConfigError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="thermodem: thermal discrete element simulations. Exit codes: 0 success, "
    "1 simulation failure, 2 bad input, 130 interrupted (checkpoint written).",
)


_THREADS = typer.Option(None, "--threads", "-t", min=1, help="Numba threads")
_PROGRESS = typer.Option(
    None, "--progress/--no-progress", help="progress bar (default: only on a terminal)"
)
_LOG_INTERVAL = typer.Option(
    10.0, "--log-interval", min=0.0, help="seconds between plain progress lines"
)


def _version(value: bool) -> None:
    if value:
        from thermodem import __version__

        typer.echo(f"thermodem {__version__}")
        raise typer.Exit(0)


@app.callback()
def _main(
    version: bool = typer.Option(
        False, "--version", callback=_version, is_eager=True, help="print the version and exit"
    ),
) -> None:
    """thermodem: thermal discrete element simulations."""


def _threads(requested: int | None) -> int | None:
    """``--threads`` above the cores this process may use is clamped, with a message (Numba
    refuses more threads than ``NUMBA_NUM_THREADS``, which defaults to the core count)."""
    from thermodem.engine.threads import note_lowered

    note_lowered(None, None)
    if requested is None:
        return None
    import os

    import numba

    try:
        cores = len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        cores = os.cpu_count() or 1
    limit = max(1, min(cores, int(numba.config.NUMBA_NUM_THREADS)))
    if requested > limit:
        typer.echo(
            f"warning: --threads {requested} is more than the {limit} core(s) this process can "
            f"use; using {limit}",
            err=True,
        )
        note_lowered(requested, limit)
        return limit
    return requested


_REBALANCE = typer.Option(
    0.1,
    "--rebalance",
    min=0.0,
    help="under mpiexec: re-bisect the domain when the fullest rank has this fraction more "
    "particles than the mean (docs/mpi.md)",
)


@app.command()
def run(
    case: Path | None = typer.Argument(
        None, help="case file (YAML); optional with --restart (the stored case)"
    ),
    output: Path = typer.Option(..., "--output", "-o", help="output directory"),
    threads: int | None = _THREADS,
    overwrite: bool = typer.Option(False, "--overwrite", help="reuse a non-empty directory"),
    restart: Path | None = typer.Option(
        None, "--restart", help="start from this checkpoint (.h5) instead of t = 0"
    ),
    progress: bool | None = _PROGRESS,
    log_interval: float = _LOG_INTERVAL,
    end_time: float | None = typer.Option(
        None, "--end-time", help="stop at this simulated time [s] instead of the case's"
    ),
    steps: int | None = typer.Option(
        None, "--steps", min=1, help="run this many steps only (a quick try of a case)"
    ),
    rebalance: float = _REBALANCE,
) -> None:
    """Run a case: VTU/PVD frames, timeseries.csv, checkpoints, run.log, status.json.
    Under ``mpiexec -n P`` (P > 1) the case runs on P ranks (docs/mpi.md)."""
    from thermodem.config.load import load_case
    from thermodem.engine.restarted_runs import run_from_checkpoint
    from thermodem.engine.runner import run_case

    threads = _threads(threads)
    ranks = _mpi_ranks()

    def prepared() -> object:
        """The case (None: the checkpoint's) with --end-time/--steps applied."""
        loaded = load_case(case) if case is not None else None
        if end_time is not None or steps is not None:
            if loaded is None:
                from thermodem.io.checkpoint import read_checkpoint

                loaded = read_checkpoint(restart).case()
            _shorten(loaded, end_time, steps, restart)
        return loaded

    def go() -> None:
        if case is None and restart is None:
            raise ConfigError("give a case file, or --restart CHECKPOINT")
        if ranks > 1:
            loaded = prepared()
        else:
            # a signal while the case (or the checkpoint of --end-time/--steps) is read, before
            # the runner handles them: the runner's not-started message, nothing touched
            # (before: Ctrl-C exited 130 and SIGTERM killed the process without a word)
            from thermodem.engine.run_signals import Starting, not_started

            starting = Starting()
            try:
                with starting:
                    loaded = prepared()
            except KeyboardInterrupt:
                raise not_started(output, None, None, starting.signum, restart) from None
        name = case.stem if case is not None else None
        options = dict(progress=progress, log_interval=log_interval, case_name=name)
        if ranks > 1:
            from thermodem.mpi.runner import run_distributed

            run_distributed(loaded, output, threads, overwrite, checkpoint=restart,
                            rebalance_threshold=rebalance, **options)  # fmt: skip
        elif restart is not None:
            run_from_checkpoint(restart, output, loaded, threads, overwrite, **options)
        else:
            run_case(loaded, output, threads, overwrite, **options)

    if ranks > 1:
        _guarded_mpi(go)
    else:
        _guarded(go)


def _shorten(case, end_time: float | None, steps: int | None, restart: Path | None) -> None:  # noqa: ANN001
    """``--end-time`` / ``--steps``: a new ``simulation.end_time`` (recorded in
    case.resolved.yaml, so a restart continues to it)."""
    import math

    if end_time is not None and steps is not None:
        raise ConfigError("give --end-time or --steps, not both")
    start = 0.0
    if restart is not None:
        from thermodem.io.checkpoint import read_checkpoint

        start = read_checkpoint(restart).time
    option = f"--end-time {end_time:g}" if end_time is not None else f"--steps {steps}"
    case._shortened = (option, float(case.simulation.end_time))
    if end_time is not None:
        if not math.isfinite(end_time) or end_time <= start:
            where = f"the checkpoint's time {start:g} s" if restart is not None else "0"
            raise ConfigError(f"--end-time {end_time!r}: must be finite and greater than {where}")
        case.simulation.end_time = float(end_time)
        return
    dt = case.simulation.time_step
    thermal = getattr(case, "thermal", None)
    if thermal is not None and getattr(thermal, "frozen_mechanics", False):
        dt = thermal.time_step
    case.simulation.end_time = start + int(steps) * float(dt)


@app.command()
@_one_rank
def export(
    directory: Path = typer.Argument(..., help="output directory of a run"),
    frame: int | None = typer.Option(
        None, "--frame", help="the N-th frame of particles.pvd (from 0; -1 is the last)"
    ),
    checkpoint: Path | None = typer.Option(
        None, "--checkpoint", help="a checkpoint file (default: the newest in DIR/checkpoints)"
    ),
    out: Path | None = typer.Option(
        None, "--out", "-o", help="CSV file, or - for standard output (default: in DIR)"
    ),
    overwrite: bool = typer.Option(False, "--overwrite", help="replace an existing --out file"),
) -> None:
    """Particle state as CSV (one row per particle: global id, material, position, velocity,
    radius, and for a run with heat temperature and heat rate), from a frame or a
    checkpoint."""
    from thermodem.io.export import export_particles

    where = _guarded(export_particles, directory, frame, checkpoint, out, overwrite)
    if where != "standard output":
        typer.echo(where)


@app.command()
def restart(
    directory: Path = typer.Argument(..., help="output directory of an earlier run"),
    threads: int | None = _THREADS,
    end_time: float | None = typer.Option(
        None, "--end-time", help="new end time [s] (default: the case's)"
    ),
    progress: bool | None = _PROGRESS,
    log_interval: float = _LOG_INTERVAL,
    rebalance: float = _REBALANCE,
) -> None:
    """Continue a run from the newest checkpoint in DIRECTORY (appending to its outputs); under
    ``mpiexec -n P`` on P ranks, whatever number of ranks wrote it."""
    from thermodem.engine.restarted_runs import restart_run

    if _mpi_ranks() > 1:
        from thermodem.mpi.runner import restart_distributed

        _guarded_mpi(
            restart_distributed,
            directory,
            _threads(threads),
            end_time=end_time,
            progress=progress,
            log_interval=log_interval,
            rebalance_threshold=rebalance,
        )
        return
    _guarded(
        restart_run,
        directory,
        _threads(threads),
        end_time=end_time,
        progress=progress,
        log_interval=log_interval,
    )


def _announce_compile(case: Path) -> None:
    """'compiling kernels ...' on stderr when the cache is cold (a bad case says nothing here:
    the validation that follows reports it)."""
    from thermodem.config.load import load_case
    from thermodem.engine.kernel_cache import compile_note

    try:
        note = compile_note(load_case(case))
    except ConfigError:
        return
    if note:
        typer.echo(f"# {note}", err=True)


@app.command()
@_one_rank
def etc(
    case: Path = typer.Argument(..., help="case file (YAML): the packing and its thermal models"),
    axes: str | None = typer.Option(
        None, "--axes", help="axes to measure along, letters of 'xyz' [default: xyz; 2D: xy]"
    ),
    layer: list[float] = typer.Option(
        None, "--layer", help="boundary-layer thickness [m] (repeat; default 1 and 2 diameters)"
    ),
    temperature: float | None = typer.Option(
        None, "--temperature", help="cold-layer temperature [K] [default: 300.0]"
    ),
    difference: float | None = typer.Option(
        None, "--difference", help="hot minus cold [K] [default: 1.0]"
    ),
    periodic: bool = typer.Option(
        False,
        "--periodic",
        help="impose a mean gradient across the period of periodic axes instead of two "
        "boundary layers (--layer, --temperature, --difference do not apply)",
    ),
    as_json: bool = typer.Option(False, "--json", help="print the results as JSON"),
    threads: int | None = _THREADS,
) -> None:
    """Effective thermal conductivity of the case's packing along each axis (steady network
    between two boundary layers of particles, or a periodic gradient;
    docs/effective-conductivity.md)."""
    import json

    from thermodem.config.load import load_case
    from thermodem.engine.etc import effective_conductivity_of_case
    from thermodem.engine.threads import apply_threads

    t = _threads(threads)
    if t:
        apply_threads(t)

    def go() -> list:
        import math

        def measured_axes(loaded) -> str:  # noqa: ANN001
            # (2D: the axes of the plane; a 2D user who gives no --axes measures x and y)
            return axes if axes is not None else "xy" if loaded.simulation.planar else "xyz"

        if periodic:
            given = [f"--layer {s!r}" for s in layer or ()] + [
                f"{name} {value!r}"
                for name, value in (("--temperature", temperature), ("--difference", difference))
                if value is not None
            ]
            if given:
                raise ConfigError(
                    f"{', '.join(given)}: not used with --periodic (an imposed mean gradient "
                    "across the period: no boundary layers, no layer temperatures); give "
                    "either --periodic or the boundary-layer options"
                )
            loaded = load_case(case)
            return effective_conductivity_of_case(loaded, measured_axes(loaded), periodic=True)
        temperature_ = 300.0 if temperature is None else temperature
        difference_ = 1.0 if difference is None else difference
        if not (math.isfinite(temperature_) and temperature_ > 0.0):
            raise ConfigError(f"--temperature {temperature_!r}: must be a finite temperature > 0 K")
        if not (math.isfinite(difference_) and difference_ != 0.0):
            raise ConfigError(f"--difference {difference_!r}: must be finite and not 0 [K]")
        if not temperature_ + difference_ > 0.0:
            raise ConfigError(
                f"--difference {difference_!r}: the hot layer would be at "
                f"{temperature_ + difference_:g} K; temperatures must stay > 0 K"
            )
        for s in layer or ():
            if not (math.isfinite(s) and s > 0.0):
                raise ConfigError(f"--layer {s!r}: must be a finite thickness > 0 [m]")
        loaded = load_case(case)
        return effective_conductivity_of_case(
            loaded, measured_axes(loaded), layers=tuple(layer) if layer else None,
            base_temperature=temperature_, difference=difference_,
        )  # fmt: skip

    results = _guarded(go)
    if as_json:
        typer.echo(json.dumps([r.as_dict() for r in results], indent=1))
        return
    for r in results:
        if periodic:
            typer.echo(
                f"k_eff along {r.axis} = {r.conductivity:.6g} ± {r.uncertainty:.2g} W/(m K)  "
                f"(periodic gradient {r.gradient:.6g} K/m; Q {r.heat_hot:.6g} W through "
                f"A {r.area:.6g} m²)"
            )
            continue
        layers = ", ".join(f"{s * 1e3:.3g} mm: {k:.6g}" for s, k in r.by_layer.items())
        typer.echo(
            f"k_eff along {r.axis} = {r.conductivity:.6g} ± {r.uncertainty:.2g} W/(m K)  "
            f"(by layer {layers}; Q hot {r.heat_hot:.6g} W, cold {r.heat_cold:.6g} W, "
            f"A {r.area:.6g} m², dT/dx {r.gradient:.6g} K/m, {r.interior_particles} interior "
            "particles)"
        )


@app.command()
@_one_rank
def validate(
    case: Path = typer.Argument(..., help="case file (YAML)"),
    threads: int | None = _THREADS,
) -> None:
    """Check a case (schema, completeness, time step, resources); print it resolved."""
    from thermodem.config.dump import resolved_case_yaml
    from thermodem.engine.validation import gas_note, validate_case

    _announce_compile(case)
    result = _guarded(validate_case, case, _threads(threads))
    for w in result.warnings:
        typer.echo(f"warning: {w}", err=True)
    typer.echo(f"# {case}: valid (schema, completeness, time step, resources)")
    for line in result.estimate.lines():
        typer.echo(f"# {line}")
    note = gas_note(result.case)
    if note:
        typer.echo(f"# {note}")
    typer.echo(resolved_case_yaml(result.case))


@app.command()
@_one_rank
def info(directory: Path = typer.Argument(..., help="output directory")) -> None:
    """Summarise an output directory: status, time reached, frames, checkpoints, last row."""
    from thermodem.engine.runner import output_summary

    for line in _guarded(output_summary, directory):
        typer.echo(line)


@app.command()
@_one_rank
def plot(
    directory: Path = typer.Argument(..., help="output directory"),
    out: Path | None = typer.Option(None, "--out", help="where the PNGs go (default DIR/plots)"),
    overwrite: bool = typer.Option(
        False, "--overwrite", help="replace figures of the same names in --out"
    ),
) -> None:
    """PNG figures of timeseries.csv: energies, contacts, temperatures and heat."""
    from thermodem.io.plots import plot_directory

    for path in _guarded(plot_directory, directory, out, overwrite):
        typer.echo(str(path))


def _bounds(field) -> str:  # noqa: ANN001
    parts = []
    for m in field.metadata:
        for attr, sym in (("gt", ">"), ("ge", ">="), ("lt", "<"), ("le", "<=")):
            value = getattr(m, attr, None)
            if value is not None:
                parts.append(f"{sym} {value:g}" if isinstance(value, float | int) else "")
    return ", ".join(p for p in parts if p)


def _unit(description: str) -> tuple[str, str]:
    """('[unit]', rest of the description) from 'text [unit] more'."""
    import re

    m = re.search(r"\[([^\]]*)\]", description)
    if not m:
        return "", description
    rest = description[: m.start()] + description[m.end() :]
    rest = re.sub(r"\s+([,;:)])", r"\1", re.sub(r"\s+", " ", rest)).strip(" ,;")
    return m.group(1), rest


_THERMAL_PAIR_FAMILIES = ("direct_conduction", "indirect_conduction")
_TARGET_TEXT = {
    "contacts": "touching pairs (contact lists)",
    "range": "pairs within the model's interaction range (the range pair set)",
    "external": "an external pair set (e.g. Voronoi neighbours)",
    "particles": "single particles",
}


def _conducts_across_gaps(spec) -> bool:  # noqa: ANN001
    """Whether the model conducts across a gap (its interaction range is > 0)."""
    if spec.interaction_range is None:
        return False
    try:
        params = spec.params(**spec.example_params)
    except ValueError:
        return True
    return spec.interaction_range(params, 1.0, 1.0) > 0.0


@app.command()
@_one_rank
def models(
    family: str | None = typer.Argument(None, help="only this family (e.g. normal)"),
) -> None:
    """List every model: parameters (unit, default, bounds), requirements, reference."""
    from thermodem.models.registry import FAMILIES, all_models, planar_support

    if family is not None and family not in FAMILIES:
        _fail(f"unknown family {family!r}; families: {', '.join(FAMILIES)}", EXIT_INPUT)
    specs = all_models()
    for fam in FAMILIES:
        if family is not None and fam != family:
            continue
        members = [s for s in specs if s.family == fam]
        typer.echo(f"== {fam} ==")
        if not members:
            typer.echo("  (no models registered yet)")
        for spec in members:
            typer.echo(f"  {fam}.{spec.name}: {spec.summary}")
            if spec.requires:
                typer.echo(f"    requires materials.*: {', '.join(spec.requires)}")
            if spec.requires_of is not None:
                typer.echo(
                    "    requires materials.* what its options read (e.g. the partition "
                    f"formula's properties; docs/models/{fam}-{spec.name}.md)"
                )
            if spec.uses_gas:
                typer.echo(f"    reads thermal.gas: {', '.join(spec.uses_gas)}")
            if fam in _THERMAL_PAIR_FAMILIES and spec.name != "none":
                where = _TARGET_TEXT[spec.target]
                if _conducts_across_gaps(spec) and spec.target == "contacts":
                    where += "; pairs across a gap: the range pair set"
                if spec.range_parameter:
                    where += f"; its range is set by {spec.range_parameter}"
                typer.echo(f"    runs on: {where}")
            typer.echo(f"    2D (simulation.dimension: 2): {planar_support(spec)}")
            if spec.conductance_from_force:
                typer.echo(
                    "    allows thermal.conductance_force_tolerance (conductance reuse, "
                    "docs/models/conductance_reuse.md)"
                )
            fields = spec.params.model_fields
            if not fields:
                typer.echo("    parameters: none")
            for pname, field in fields.items():
                unit, text = _unit(field.description or "")
                if field.is_required():
                    default = "required"
                elif field.default_factory is not None:
                    default = f"default {field.default_factory()!r}"
                else:
                    default = f"default {field.default!r}"
                bounds = _bounds(field)
                details = ", ".join(
                    x for x in (f"[{unit}]" if unit else "", default, bounds, text) if x
                )
                typer.echo(f"    {pname}: {details}")
            typer.echo(f"    reference: {spec.reference}")


if __name__ == "__main__":  # pragma: no cover
    app()
