"""``thermodem info``: what an output directory holds (status, time reached, frames,
checkpoints, the last row of the time series)."""

from __future__ import annotations

import csv
import math
import os
import socket
from pathlib import Path

from thermodem.engine.run_checks import process_alive
from thermodem.errors import ConfigError
from thermodem.io.checkpoint import list_checkpoints
from thermodem.io.run_files import CHECKPOINT_DIR, FAILED_FILE, TIMESERIES_FILE, Status
from thermodem.io.vtk import PVDWriter


def gas_line(resolved: Path) -> str | None:
    """'gas: ...' from the resolved case of a run with a thermal section, else None."""
    import yaml

    from thermodem.state.gas import GasProperties

    try:
        data = yaml.safe_load(resolved.read_text())
        gas = GasProperties(**data["thermal"]["gas"])
    except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError):
        return None
    return f"gas (thermal.gas): {gas.summary()}"


def output_summary(directory: str | os.PathLike[str]) -> list[str]:
    """Lines describing a finished or running output directory (``thermodem info``)."""
    directory = Path(directory)
    if not directory.is_dir():
        raise ConfigError(f"{str(directory)!r} is not a directory")
    status = Status.read(directory)
    resolved = directory / "case.resolved.yaml"
    if not status and not resolved.exists():
        raise ConfigError(f"{str(directory)!r} is not a thermodem output directory")
    lines = [f"output: {directory}"]
    state = status.get("status", "unknown")
    pid = status.get("pid")
    if state == "running" and pid and status.get("host") in (None, socket.gethostname()):
        if not process_alive(pid):
            state = f"stopped without a final status (process {pid} is gone: killed?)"
        else:
            state = f"running (pid {pid})"
    lines.append(f"status: {state}")
    if status.get("message"):
        lines.append(f"message: {status['message'].splitlines()[0]}")
    if status.get("case"):
        lines.append(f"case: {status['case']}")
    gas = gas_line(resolved)
    if gas:
        lines.append(gas)
    if "time" in status:
        end = status.get("end_time") or math.nan
        frac = 100.0 * status["time"] / end if end else math.nan
        lines.append(
            f"time: {status['time']:.6g} s of {end:g} s ({frac:.1f} %), step "
            f"{status.get('step')} of {status.get('total_steps')}"
        )
        lines.append(f"particles: {status.get('particles')}, contacts: {status.get('contacts')}")
    if status.get("started"):
        lines.append(f"started: {status['started']}, last update: {status.get('updated')}")
    pvd = directory / "particles.pvd"
    if pvd.exists():
        entries = PVDWriter.read(pvd)
        last = f", last at t = {entries[-1][0]:.6g} s" if entries else ""
        lines.append(f"frames: {len(entries)}{last} ({pvd})")
    ckpts = list_checkpoints(directory / CHECKPOINT_DIR)
    if ckpts:
        lines.append(f"checkpoints: {', '.join(p.name for p in ckpts)}")
    if (directory / FAILED_FILE).exists():
        lines.append(f"state at the failure: {directory / FAILED_FILE}")
    ts = directory / TIMESERIES_FILE
    if ts.exists():
        with ts.open(newline="") as f:
            rows = [r for r in csv.reader(f) if r]
        if len(rows) > 1:
            lines.append(f"timeseries: {len(rows) - 1} rows; last row:")
            lines += [f"  {k} = {v}" for k, v in zip(rows[0], rows[-1], strict=False) if v != ""]
    return lines
