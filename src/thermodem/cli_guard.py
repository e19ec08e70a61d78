"""What the command line does with errors, warnings and MPI ranks: one ``error: ...`` line and
the exit code for a refusal (2), a simulation failure (1) or a stop by a signal (130/143),
thermodem's warnings as ``warning: ...`` lines, and under ``mpiexec`` the agreed errors said
once by rank 0 and the commands that run no case run on rank 0 alone."""

from __future__ import annotations

import typer

from thermodem.errors import ConfigError, RunInterrupted, SimulationError

EXIT_OK, EXIT_SIMULATION, EXIT_INPUT = 0, 1, 2


def _fail(message: str, code: int) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


def _guarded(fn, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
    """Map thermodem's exceptions to messages and exit codes (never a traceback); thermodem's
    own RuntimeWarnings (a section no selected model reads, said while the case is built)
    as ``warning: ...`` lines, not Python's 'FILE:LINE: RuntimeWarning:' form; a
    :class:`~thermodem.errors.RunNotice` (information: the statistics of a tessellation) as a
    plain line, as a run logs it."""
    import os
    import warnings

    from thermodem.errors import RunNotice

    shown = warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):  # noqa: ANN001, ANN202
        if issubclass(category, RunNotice):
            typer.echo(str(message), err=True)
        elif issubclass(category, RuntimeWarning) and f"{os.sep}thermodem{os.sep}" in filename:
            typer.echo(f"warning: {message}", err=True)
        else:
            shown(message, category, filename, lineno, file, line)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = show
            return fn(*args, **kwargs)
    except ConfigError as exc:
        _told(exc)
        _fail(str(exc), EXIT_INPUT)
    except SimulationError as exc:
        _fail(str(exc), EXIT_SIMULATION)
    except RunInterrupted as exc:
        typer.echo(str(exc), err=True)
        raise typer.Exit(exc.exit_code) from None


def _told(exc: ConfigError) -> None:
    """The warnings computed before a refusal, before its error line (a density in g/cm³
    explains a time step refused for the tiny mass); a run logged them already."""
    for warning in exc.warnings or ():
        typer.echo(f"warning: {warning}", err=True)


def _guarded_mpi(fn, *args, **kwargs):  # noqa: ANN001, ANN002, ANN003, ANN202
    """``_guarded`` on one of several MPI ranks: the errors agreed between the ranks (every
    rank has the same message) are printed by rank 0 only, every rank exits with the same
    code; any other exception cannot be agreed (the other ranks wait in a collective), so
    its rank prints it and aborts the MPI job."""
    import traceback

    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    root = comm.Get_rank() == 0
    try:
        return fn(*args, **kwargs)
    except ConfigError as exc:
        if root:
            _told(exc)
            typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(EXIT_INPUT) from None
    except SimulationError as exc:
        if root:
            typer.echo(f"error: {exc}", err=True)
        raise typer.Exit(EXIT_SIMULATION) from None
    except RunInterrupted as exc:
        if root:
            typer.echo(str(exc), err=True)
        raise typer.Exit(exc.exit_code) from None
    except Exception as exc:  # noqa: BLE001 (a bug or a resource error on this rank only)
        typer.echo(
            f"error on MPI rank {comm.Get_rank()} of {comm.Get_size()}: "
            f"{type(exc).__name__}: {exc}\n{traceback.format_exc()}aborting every rank",
            err=True,
        )
        comm.Abort(EXIT_SIMULATION)


def _mpi_ranks() -> int:
    """The number of MPI ranks of this process (1 without mpiexec; mpi4py not imported)."""
    from thermodem.mpi import world_size

    return world_size()


def _one_rank(fn):  # noqa: ANN001, ANN202
    """A command that does not run a case (validate, etc, export, plot, info, models) under
    ``mpiexec -n P`` (P > 1): rank 0 runs it alone and sends its exit code to the other
    ranks, which exit with it without running anything (one output, one file written, no
    race on ``export -o FILE``); docs/mpi.md. Without MPI: the command itself."""
    import functools

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):  # noqa: ANN002, ANN003, ANN202
        if _mpi_ranks() <= 1:
            return fn(*args, **kwargs)
        import time

        from mpi4py import MPI

        comm = MPI.COMM_WORLD
        tag = 7301
        if comm.Get_rank() != 0:
            request = comm.irecv(source=0, tag=tag)
            while True:  # (a sleeping wait: no core spinning while rank 0 works)
                done, code = request.test()
                if done:
                    raise typer.Exit(int(code))
                time.sleep(0.02)
        code = EXIT_SIMULATION
        try:
            result = fn(*args, **kwargs)
            code = EXIT_OK
            return result
        except typer.Exit as exc:
            code = exc.exit_code
            raise
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else EXIT_SIMULATION
            raise
        finally:
            for rank in range(1, comm.Get_size()):
                comm.send(code, dest=rank, tag=tag)

    return wrapper
