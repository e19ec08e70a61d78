"""Checks before a run touches an output directory: the output path, the lock of a live
process writing it (``OUT/run.lock``), the checkpoint to continue (readable, loadable, written
for this directory), and the repair of a ``timeseries.csv`` cut by a killed run. Used by
:mod:`thermodem.engine.runner` and :mod:`thermodem.mpi.runner`."""

from __future__ import annotations

import csv
import datetime as _dt
import json
import os
import socket
from collections.abc import Callable
from pathlib import Path
from typing import Any

from thermodem.config.schema import Case
from thermodem.engine.simulation import Simulation
from thermodem.errors import ConfigError, SimulationError
from thermodem.io.checkpoint import Checkpoint, read_checkpoint
from thermodem.io.run_files import STATUS_FILE, Status, _atomic_write_text

LOCK_FILE = "run.lock"


def check_output_path(output: Path) -> None:
    """The output directory can be created: no file on its path, and the first existing
    directory on it is writable (an OSError of the path itself, a name too long, is told as
    such)."""
    try:
        _check_output_path(output)
    except OSError as exc:
        raise ConfigError(
            f"--output {str(output)!r} cannot be used: {exc.strerror or exc}; choose another "
            "--output"
        ) from None


def _check_output_path(output: Path) -> None:
    for parent in (output, *output.parents):
        if not parent.exists():
            continue
        if not parent.is_dir():
            if parent == output:
                raise ConfigError(f"--output {str(output)!r} exists and is not a directory")
            raise ConfigError(
                f"--output {str(output)!r}: {str(parent)!r} is a file, not a directory, so "
                "the output directory cannot be created there; choose another --output"
            )
        if not os.access(parent, os.W_OK | os.X_OK):
            raise ConfigError(
                f"--output {str(output)!r}: the directory {str(parent)!r} is not writable"
            )
        return


def process_start(pid: int) -> str | None:
    """Start time of process ``pid`` (Linux: field 22 of /proc/PID/stat), None if unknown;
    tells a live lock holder from an unrelated process that reuses its pid."""
    try:
        text = Path(f"/proc/{int(pid)}/stat").read_text()
        return text.rsplit(")", 1)[1].split()[19]
    except (OSError, IndexError, ValueError):
        return None


def lock_holder(output: Path) -> dict[str, Any] | None:
    """The live process that holds ``output``'s lock, or None (no lock, or a stale one)."""
    try:
        data = json.loads((output / LOCK_FILE).read_text())
    except FileNotFoundError:
        return None
    except (OSError, ValueError):
        return None  # unreadable: a lock half written by a killed process
    if not isinstance(data, dict) or not isinstance(data.get("pid"), int):
        return None
    pid, host = data["pid"], data.get("host")
    if host not in (None, socket.gethostname()):
        return data  # another machine (a shared file system): cannot tell, assume alive
    if not process_alive(pid):
        return None
    start, now = data.get("start"), process_start(pid)
    if start and now and start != now:
        return None  # the pid belongs to another process now
    return data


def refuse_if_busy(output: Path, what: str) -> None:
    """ConfigError when a live process writes ``output`` (its lock, or an older run's
    ``status.json`` that says running with a live pid)."""
    holder = lock_holder(output)
    if holder is not None:
        pid = holder["pid"]
        raise ConfigError(
            f"{output} is being written by a running thermodem process (pid {pid} on "
            f"{holder.get('host')}, since {holder.get('started')}); {what} refused: wait for "
            f"it to finish, stop it (Ctrl-C, or kill {pid}: it writes a checkpoint), or choose "
            f"another --output (if that process is not thermodem, delete {output / LOCK_FILE})"
        )
    previous = Status.read(output)
    pid = previous.get("pid")
    if previous.get("status") == "running" and pid and pid != os.getpid() and process_alive(pid):
        if previous.get("host") in (None, socket.gethostname()):
            raise ConfigError(
                f"{output} is still being written by a running process (pid {pid}, according "
                f"to its status.json); {what} refused (if pid {pid} is not a thermodem run, "
                f"delete {output / STATUS_FILE})"
            )


class RunLock:
    """``OUT/run.lock``: created exclusively (O_EXCL) with this process's pid, host and start
    time; a stale lock (its process gone) is replaced; removed when the run ends."""

    def __init__(self, output: Path) -> None:
        self.output = output
        self.path = output / LOCK_FILE
        self.held = False

    def acquire(self) -> None:
        me = {
            "pid": os.getpid(),
            "host": socket.gethostname(),
            "start": process_start(os.getpid()),
            "started": _dt.datetime.now().isoformat(timespec="seconds"),
        }
        for _ in range(3):
            try:
                fd = os.open(self.path, os.O_CREAT | os.O_EXCL | os.O_WRONLY, 0o644)
            except FileExistsError:
                refuse_if_busy(self.output, "the run")
                self.path.unlink(missing_ok=True)  # stale
                continue
            with os.fdopen(fd, "w") as f:
                f.write(json.dumps(me) + "\n")
            self.held = True
            return
        raise ConfigError(f"could not take the lock {self.path} (another run took it?)")

    def release(self) -> None:
        if self.held:
            self.path.unlink(missing_ok=True)
            self.held = False


def read_newest_checkpoint(checkpoints: list[Path]) -> Checkpoint:
    """The newest checkpoint, read and checked; a damaged one names the older ones."""
    try:
        return read_checkpoint(checkpoints[-1])
    except ConfigError as exc:
        older = [str(p) for p in checkpoints[:-1]]
        hint = (
            f"; an older checkpoint can be continued into a new directory: thermodem run "
            f"--restart {older[-1]} --output NEWDIR"
            if older
            else ""
        )
        raise ConfigError(f"{exc}; nothing was changed in the run directory{hint}") from None


#: Wall keys a restart takes from the changed case (engine/restart.py: the columns that no
#: step changes); the others place the wall, which the checkpoint holds (a wall moves).
WALL_CASE_KEYS = frozenset({"material", "velocity", "angular_velocity", "name", "thermal"})


def check_restart_case(ckpt: Checkpoint, case: Case) -> None:
    """Refuse a changed case that a restart would not run as written: static insertion
    entries (lattice, random, list, file: the particles of t = 0, not inserted again; a file
    entry's path aside) or a wall's place (its point, normal, extents, radius...: the
    checkpoint's wall rows hold where it is) unlike the stored case's. The run would continue
    the checkpoint's particles and walls, not the ones the case describes. A wall's material,
    velocity, angular velocity and thermal condition may change (the case's are run). Pour
    entries are compared when the state is loaded."""
    from thermodem.config.dump import case_to_dict
    from thermodem.engine.restart import NO_THERMAL_SECTION

    if case is None:
        return
    with_heat = "thermal" in ckpt.state
    if with_heat and case.thermal is None:
        raise ConfigError(f"{NO_THERMAL_SECTION}; checkpoint {ckpt.path}, nothing was changed")
    # heat that starts at this restart (a checkpoint without heat) takes the temperatures the
    # static entries give (engine/heat_start.py): they may change
    ignored = {"path"} if with_heat else {"path", "temperature", "temperatures"}

    def static(entries: Any) -> tuple[list[int], list[Any]]:
        """(index in ``insertion``, entry without its file path) of every static entry."""
        if not isinstance(entries, list):
            return [], []
        kept = [
            (k, {key: v for key, v in e.items() if key not in ignored} if isinstance(e, dict)
             else e)
            for k, e in enumerate(entries)
            if not (isinstance(e, dict) and e.get("kind") == "pour")
        ]  # fmt: skip
        return [k for k, _ in kept], [e for _, e in kept]

    def placed(walls: Any) -> list[Any]:
        if not isinstance(walls, list):
            return []
        return [
            {k: v for k, v in w.items() if k not in WALL_CASE_KEYS} if isinstance(w, dict) else w
            for w in walls
        ]

    # both through the schema, so that keys a later version added with their defaults compare
    # equal (the stored case of an older checkpoint lacks them)
    mine, theirs = case_to_dict(case), case_to_dict(ckpt.case())
    particles = ckpt.state.get("particles", {})
    n = int(particles["radius"].shape[0]) if "radius" in particles else None
    held = f"the checkpoint's {n} particles" if n is not None else "the checkpoint's particles"
    allowed = (
        "nothing was changed. Allowed: the checkpoint's {what} (as in the case.resolved.yaml "
        "of the run that wrote it), or a new run from t = 0 without --restart"
    )
    where = first_difference(placed(mine.get("walls")), placed(theirs.get("walls")))
    if where is not None:
        head, _, rest = where.partition(".")
        where = f"walls.{head}" + (f".{rest}" if rest else "") if head.isdigit() else "walls"
        raise ConfigError(
            f"{where} differs from the case stored in the checkpoint {ckpt.path}: a wall's "
            "place comes from the checkpoint on a restart (a moving wall has moved since "
            "t = 0), so the run would keep the checkpoint's walls, not the ones this case "
            "describes (a wall's material, velocity, angular velocity and thermal condition "
            "may change); " + allowed.format(what="wall places")
        )
    index, mine_static = static(mine.get("insertion"))
    _, theirs_static = static(theirs.get("insertion"))
    where = first_difference(mine_static, theirs_static)
    if where is None:
        return
    head, _, rest = where.partition(".")
    if head.isdigit() and int(head) < len(index):  # (the entry's index in the case)
        where = f"insertion.{index[int(head)]}" + (f".{rest}" if rest else "")
    else:
        where = "insertion (its static entries: another number of them)"
    raise ConfigError(
        f"{where} differs from the case stored in the checkpoint {ckpt.path}: the particles "
        f"of t = 0 (lattice, random, list, file entries) are not inserted again on a "
        f"restart, so the run would continue {held}, not the ones this case describes; "
        + allowed.format(what="static insertion entries")
    )


def check_restart_start(ckpt: Checkpoint, case: Case) -> None:
    """The checks of ``run CASE --restart CKPT`` before anything is built or written (serial
    and MPI alike): an end time after the checkpoint's time, a case whose t = 0 particles,
    wall places and thermal section fit the checkpoint (:func:`check_restart_case`)."""
    if not case.simulation.end_time > ckpt.time:
        raise ConfigError(
            f"simulation.end_time = {case.simulation.end_time:g} s is not after the "
            f"time of the checkpoint {ckpt.path}, {ckpt.time:.6g} s (step {ckpt.step}): "
            "there is nothing to run; give a later end time in the case or with "
            "--end-time T"
        )
    check_restart_case(ckpt, case)


def restored_simulation(ckpt: Checkpoint, threads: int | None, case: Case) -> Simulation:
    """A simulation continuing from ``ckpt`` (ConfigError for a state that does not load, or
    a changed case whose t = 0 particles differ from the checkpoint's)."""
    check_restart_case(ckpt, case)
    try:
        sim = Simulation.from_checkpoint(ckpt, threads=threads, case=case)
    except ConfigError as exc:
        if str(ckpt.path) in str(exc):
            raise
        raise ConfigError(
            f"checkpoint {ckpt.path}: {exc}; nothing was changed (a checkpoint continues "
            "the case it was written with, or one with the same particles, walls and models)"
        ) from None
    except (KeyError, IndexError, TypeError, ValueError) as exc:
        raise ConfigError(
            f"checkpoint {ckpt.path} cannot be restored ({type(exc).__name__}: {exc}); the file "
            "is damaged or was written by another version"
        ) from None
    check_restored_lists(sim, ckpt)
    return sim


def check_restored_lists(sim: Simulation, ckpt: Checkpoint) -> None:
    """What the first list builds after a restart would refuse, checked before any step: the
    neighbour lists of the restored particles with the case's domain, skin and extra distance
    (neighbor_list.check_next_build: a periodic axis shorter than two cells), the thermal
    range pair set and neighbourhood spheres (thermal_terms.check_ranges,
    check_neighbourhood_range). A changed case (a shorter domain, a larger neighbors.skin)
    met them at the first rebuild, as a failed run (exit 1); now a ConfigError naming the key
    (exit 2) while nothing is written. An unchanged case passes (its run passed them)."""
    from thermodem.engine.neighbor_list import check_next_build

    try:
        check_next_build(sim)
        th, p = sim.thermal, sim.particles
        if th is not None and p.count:
            r_max = float(p.radius.max())
            if th.range_set is not None:
                th.check_ranges(r_max)
            if th.field_provider.neighbourhood is not None:
                th.field_provider.check_neighbourhood_range(r_max)
    except (SimulationError, ConfigError) as exc:
        raise ConfigError(
            f"{exc} (met while the restart from {ckpt.path} was set up, before any step; "
            "nothing was changed)"
        ) from None


def case_without_end_time(text: str) -> Any:
    import yaml

    data = yaml.safe_load(text)
    if isinstance(data, dict) and isinstance(data.get("simulation"), dict):
        data["simulation"].pop("end_time", None)
    return data


def first_difference(a: Any, b: Any, path: str = "") -> str | None:
    """Key path of the first difference between two plain-data trees ('' for the root)."""
    if isinstance(a, dict) and isinstance(b, dict):
        for key in list(a) + [k for k in b if k not in a]:
            if key not in a or key not in b:
                return f"{path}{key}"
            found = first_difference(a[key], b[key], f"{path}{key}.")
            if found is not None:
                return found
        return None
    if isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            return path.rstrip(".") or "(the whole case)"
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            found = first_difference(x, y, f"{path}{k}.")
            if found is not None:
                return found
        return None
    return None if a == b else (path.rstrip(".") or "(the whole case)")


def all_differences(a: Any, b: Any, path: str = "") -> list[tuple[str, Any, Any]]:
    """Every difference between two plain-data trees: (key path, value in ``a``, value in
    ``b``), a key present on one side only with ``None`` on the other, a list of scalars (a
    vector) or lists of other lengths as one difference of the whole list
    (:func:`first_difference` finds the first only)."""
    if isinstance(a, dict) and isinstance(b, dict):
        out: list[tuple[str, Any, Any]] = []
        for key in list(a) + [k for k in b if k not in a]:
            out += all_differences(a.get(key), b.get(key), f"{path}{key}.")
        return out
    if (
        isinstance(a, list)
        and isinstance(b, list)
        and len(a) == len(b)
        and any(isinstance(v, dict | list) for v in a + b)  # (not a vector)
    ):
        out = []
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            out += all_differences(x, y, f"{path}{k}.")
        return out
    return [] if a == b else [(path.rstrip(".") or "(the whole case)", a, b)]


#: Lines of the changes a restart lists before "and N more".
CHANGES_SHOWN = 20


def _shown(value: Any) -> str:
    if value is None:
        return "(none)"
    if isinstance(value, dict):
        return "(a section)"
    text = str(value)
    if isinstance(value, list) and len(text) > 60:
        return f"(a list of {len(value)})"
    return text


def restart_changes(ckpt: Checkpoint, case: Case) -> list[str]:
    """The lines that list what ``case`` changes against the case stored in ``ckpt`` (``run
    CASE --restart CKPT``: these are applied; the ones a restart cannot apply were refused
    by :func:`check_restart_case`), one per key with the old and new value, at most
    :data:`CHANGES_SHOWN` and then 'and N more'. A file entry's path is left out (its
    particles come from the checkpoint); the end time and the output settings are listed."""
    from thermodem.config.dump import case_to_dict

    changes = [
        (key, old, new)
        for key, old, new in all_differences(case_to_dict(ckpt.case()), case_to_dict(case))
        if not (key.startswith("insertion.") and key.endswith(".path"))
    ]
    lines = [
        f"changed from the checkpoint's case: {key} {_shown(old)} -> {_shown(new)}"
        for key, old, new in changes[:CHANGES_SHOWN]
    ]
    if len(changes) > CHANGES_SHOWN:
        lines.append(f"changed from the checkpoint's case: and {len(changes) - CHANGES_SHOWN} more")
    return lines


def check_checkpoint_belongs(ckpt: Checkpoint, output: Path, status: dict[str, Any]) -> None:
    """Refuse a checkpoint that was not written for ``output``: another run_id than the
    directory's ``status.json``, or a stored case that differs from ``case.resolved.yaml``
    (the end time aside, which a restart may change)."""
    import yaml

    own = status.get("run_id")
    if own and ckpt.run_id and own != ckpt.run_id:
        raise ConfigError(
            f"checkpoint {ckpt.path} was written by another run (run_id {ckpt.run_id}, this "
            f"directory's is {own}: copied in from elsewhere?); restart refused, nothing was "
            f"changed. To continue it in a new directory: thermodem run --restart {ckpt.path} "
            "--output NEWDIR"
        )
    resolved = output / "case.resolved.yaml"
    if not resolved.exists():
        return
    try:
        mine = case_without_end_time(resolved.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise ConfigError(f"{resolved} cannot be read ({exc}); restart refused") from None
    try:
        stored = case_without_end_time(ckpt.case_yaml)
    except yaml.YAMLError as exc:
        raise ConfigError(
            f"checkpoint {ckpt.path}: the stored case is not valid YAML ({exc})"
        ) from None
    where = first_difference(mine, stored)
    if where is not None:
        raise ConfigError(
            f"checkpoint {ckpt.path} holds another case than {resolved} (they differ at "
            f"{where}): it belongs to another run; restart refused, nothing was changed. To "
            f"continue it with its own case in a new directory: thermodem run --restart "
            f"{ckpt.path} --output NEWDIR"
        )


def timeseries_repair(path: Path) -> Callable[[], str] | None:
    """A repair of ``timeseries.csv`` to do at a restart, or None: its last row is dropped
    when it is incomplete (no line end, fewer cells than the header, or a time or step that is
    not a number: a run killed while writing it). A damaged row before the last is an error
    (the file was edited or broken otherwise)."""
    if not path.exists():
        return None
    raw = path.read_bytes()
    text = raw.decode("utf-8", errors="replace")
    lines = text.split("\n")
    complete = text.endswith("\n")
    body = lines[:-1] if complete else lines
    if len(body) < 2:
        return None
    header = next(csv.reader([body[0]]), [])

    def problem(row: str) -> str | None:
        cells = next(csv.reader([row]), [])
        if len(cells) != len(header):
            return f"{len(cells)} of {len(header)} values"
        try:
            float(cells[0])
            int(cells[1])
        except (ValueError, IndexError):
            return "its time or step is not a number"
        return None

    for k, row in enumerate(body[1:-1], start=2):
        why = problem(row)
        if why is not None:
            raise ConfigError(
                f"{path}, line {k}: damaged row ({why}); restart refused, nothing was changed: "
                "repair or move the file away (the restart then writes the rows after the "
                "checkpoint only)"
            )
    last = len(body)
    why = "no line end" if not complete else problem(body[-1])
    if why is None:
        return None

    def repair() -> str:
        _atomic_write_text(path, "\n".join(body[:-1]) + "\n")
        return (
            f"{path}: its last row (line {last}) was incomplete ({why}; the run was stopped "
            "while writing it); dropped it, the restart writes the rows after the checkpoint "
            "again"
        )

    return repair


def process_alive(pid: int) -> bool:
    try:
        os.kill(int(pid), 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError, ValueError):
        return True
    return True
