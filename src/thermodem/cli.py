"""Command line: ``thermodem run | validate | models``.

Exit codes: 0 success, 1 simulation failure, 2 bad input.
"""

from __future__ import annotations

from pathlib import Path

import typer

from thermodem.errors import ConfigError, SimulationError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="thermodem: thermal discrete element simulations",
)


def _fail(message: str, code: int) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


@app.command()
def run(
    case: Path = typer.Argument(..., help="case file (YAML)"),
    output: Path = typer.Option(..., "--output", "-o", help="output directory"),
    threads: int | None = typer.Option(None, "--threads", "-t", min=1, help="Numba threads"),
    overwrite: bool = typer.Option(False, "--overwrite", help="reuse a non-empty directory"),
) -> None:
    """Run a case and write VTU/PVD output."""
    from thermodem.config.load import load_case
    from thermodem.engine.runner import run_case

    try:
        sim = run_case(load_case(case), output, threads=threads, overwrite=overwrite)
    except ConfigError as exc:
        _fail(str(exc), 2)
    except SimulationError as exc:
        _fail(str(exc), 1)
    typer.echo(
        f"done: {sim.step_count} steps, {sim.particles.count} particles; "
        f"open {output / 'particles.pvd'} in ParaView"
    )


@app.command()
def validate(case: Path = typer.Argument(..., help="case file (YAML)")) -> None:
    """Check a case (schema, time step) and print it with every default filled in."""
    from thermodem.config.load import load_case
    from thermodem.engine.checks import check_simulation_time_step
    from thermodem.engine.runner import resolved_case_yaml
    from thermodem.engine.simulation import Simulation

    try:
        c = load_case(case)
        sim = Simulation(c)
        warnings = check_simulation_time_step(sim)
    except ConfigError as exc:
        _fail(str(exc), 2)
    for w in warnings:
        typer.echo(f"warning: {w}", err=True)
    typer.echo(resolved_case_yaml(c))


@app.command()
def models() -> None:
    """List every registered model: family, name, parameters, reference."""
    from thermodem.models.registry import all_models

    for spec in all_models():
        typer.echo(f"{spec.family}.{spec.name}: {spec.summary}")
        for pname, field in spec.params.model_fields.items():
            default = "" if field.is_required() else f" (default {field.default!r})"
            typer.echo(f"    {pname}: {field.description or ''}{default}")
        typer.echo(f"    reference: {spec.reference}")


if __name__ == "__main__":  # pragma: no cover
    app()
