"""HDF5 checkpoints: the complete state of a simulation, written atomically.

File layout (``h5py``)::

    /                  attributes: format = "thermodem-checkpoint", format_version,
                       thermodem_version, kind ("checkpoint" | "interrupted" | "final" |
                       "failed"), step, time, created (ISO time), message, run_id (the
                       run directory it was written for, "" outside a run directory)
    /case_yaml         the resolved case (every default filled in), a UTF-8 string
    /scalars_json      JSON of the scalar state (time, step, ids, ledger, random generator
                       state, pour state, ...)
    /particles/NAME    every particle array in its current memory order
    /pairs/NAME        particle-pair buffers (first `count` rows)
    /walls/NAME        particle-wall pair buffers
    /arrays/NAME       neighbour-list index arrays, reference positions, wall rows, ...
    /thermal/scalars_json, /thermal/arrays/NAME   thermal engine state (if any)

What the state contains is defined in :mod:`thermodem.engine.restart`. A file is written to
``NAME.tmp`` in the same directory and moved over ``NAME`` with :func:`os.replace`, so a run
killed while writing leaves the previous file intact.

A ``failed`` checkpoint holds the state at the moment a :class:`SimulationError` was raised
(in the middle of a step) for inspection; it cannot be restarted from.

Reading checks the file completely before anything uses it (:func:`read_checkpoint`): a
missing attribute, group or dataset, scalars that are not JSON, a stored case that is not
YAML or not a valid case, arrays of inconsistent lengths
(:func:`thermodem.engine.restart.check_state`) each give one ConfigError naming the file.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from thermodem.errors import ConfigError

if TYPE_CHECKING:
    from thermodem.config.schema import Case
    from thermodem.engine.simulation import Simulation

FORMAT = "thermodem-checkpoint"
FORMAT_VERSION = 3  # 2: pair lists with slab groups, no per-pair force rows; 3: the contact
# history laid out from the registry (state/history.py), its layout among the scalars; no
# per-pair dissipation rows; the particles' heat generation accumulators
KINDS = ("checkpoint", "interrupted", "final", "failed")
_NAME = re.compile(r"^checkpoint_(\d+)\.h5$")


def checkpoint_name(step: int) -> str:
    """File name of the checkpoint of ``step`` (sorts by step)."""
    return f"checkpoint_{step:09d}.h5"


def list_checkpoints(directory: str | os.PathLike[str]) -> list[Path]:
    """``checkpoint_*.h5`` files in ``directory``, oldest step first."""
    d = Path(directory)
    if not d.is_dir():
        return []
    found = [(int(m.group(1)), p) for p in d.iterdir() if (m := _NAME.match(p.name))]
    return [p for _, p in sorted(found)]


def _write_group(group: Any, arrays: dict[str, np.ndarray]) -> None:
    for name, value in arrays.items():
        group.create_dataset(name, data=np.asarray(value))


def write_checkpoint(
    sim: Simulation,
    path: str | os.PathLike[str],
    *,
    kind: str = "checkpoint",
    message: str = "",
    fsync: bool = False,
    case_yaml: str | None = None,
    run_id: str = "",
    state: dict | None = None,
) -> Path:
    """Write the complete state of ``sim`` to ``path`` atomically; returns the path.

    ``state``: the state to write if the caller has it already (``sim.state_dict()``; on
    several MPI ranks the state gathered to rank 0, thermodem.mpi.gather).

    ``case_yaml``: the resolved case text if the caller has it already (it is the same for
    every checkpoint of a run and costs more to produce than the arrays of a small case).
    ``run_id``: the identity of the run directory (``status.json``), so that a restart can
    refuse a checkpoint copied in from another run.
    """
    import h5py

    from thermodem import __version__
    from thermodem.config.dump import resolved_case_yaml

    if kind not in KINDS:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if state is None:
        state = sim.state_dict()
    tmp = path.with_name(path.name + ".tmp")
    with h5py.File(tmp, "w") as f:
        f.attrs["format"] = FORMAT
        f.attrs["format_version"] = FORMAT_VERSION
        f.attrs["thermodem_version"] = __version__
        f.attrs["kind"] = kind
        f.attrs["step"] = int(sim.step_count)
        f.attrs["time"] = float(sim.time)
        f.attrs["created"] = _dt.datetime.now().isoformat(timespec="seconds")
        f.attrs["message"] = message
        f.attrs["run_id"] = run_id
        text = h5py.string_dtype("utf-8")
        if case_yaml is None:
            case_yaml = resolved_case_yaml(sim.case)
        f.create_dataset("case_yaml", data=case_yaml, dtype=text)
        f.create_dataset("scalars_json", data=json.dumps(state["scalars"]), dtype=text)
        for group in ("particles", "pairs", "walls", "arrays"):
            _write_group(f.create_group(group), state[group])
        if "thermal" in state:
            g = f.create_group("thermal")
            thermal_json = json.dumps(state["thermal"]["scalars"])
            g.create_dataset("scalars_json", data=thermal_json, dtype=text)
            _write_group(g.create_group("arrays"), state["thermal"]["arrays"])
        if fsync:
            f.flush()
    if fsync:
        fd = os.open(tmp, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)
    os.replace(tmp, path)
    return path


@dataclass
class Checkpoint:
    """A checkpoint read back: the resolved case text, the state and the file attributes."""

    path: Path
    case_yaml: str
    state: dict[str, Any]
    kind: str
    step: int
    time: float
    created: str
    message: str
    run_id: str = ""

    def case(self) -> Case:
        """The case stored in the checkpoint, validated."""
        import yaml

        from thermodem.config.load import case_from_dict

        try:
            data = yaml.safe_load(self.case_yaml)
        except yaml.YAMLError as exc:
            raise ConfigError(
                f"checkpoint {self.path}: the stored case is not valid YAML "
                f"({_yaml_problem(exc)}); the file is damaged"
            ) from None
        return case_from_dict(data, f"{self.path} (stored case)", stored=True)


def _read_group(group: Any) -> dict[str, np.ndarray]:
    return {name: group[name][()] for name in group}


def _text(value: Any) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def _yaml_problem(exc: Exception) -> str:
    """One line for a YAML error: the problem and where."""
    import yaml

    if isinstance(exc, yaml.MarkedYAMLError) and exc.problem_mark is not None:
        mark = exc.problem_mark
        return f"{exc.problem} at line {mark.line + 1}, column {mark.column + 1}"
    return " ".join(str(exc).split())


def _check_case_yaml(text: str, damaged: str) -> None:
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as exc:
        raise ConfigError(
            f"{damaged}: the stored case is not valid YAML ({_yaml_problem(exc)})"
        ) from None
    if not isinstance(data, dict):
        raise ConfigError(f"{damaged}: the stored case is not a mapping of sections")


def read_checkpoint(path: str | os.PathLike[str]) -> Checkpoint:
    """Read a checkpoint file and check it completely (ConfigError with one line if it is
    missing, not a checkpoint, or damaged: a missing group, bad JSON, short arrays)."""
    import h5py

    path = Path(path)
    if path.is_dir():  # (a run's directory given as the checkpoint: "does not exist" misled)
        found = list_checkpoints(path / "checkpoints") or list_checkpoints(path)
        hint = f"e.g. its newest, {found[-1]}" if found else "none is in it"
        raise ConfigError(
            f"checkpoint {str(path)!r} is a directory; allowed: a checkpoint file ({hint}), or "
            f"thermodem restart {path} to continue a run in its own directory"
        )
    if not path.is_file():
        raise ConfigError(f"checkpoint {str(path)!r} does not exist or is not a file")
    try:
        f = h5py.File(path, "r")
    except OSError as exc:
        raise ConfigError(f"checkpoint {str(path)!r} is not a readable HDF5 file: {exc}") from None
    damaged = f"checkpoint {path} is damaged or incomplete"
    with f:
        if _text(f.attrs.get("format", "")) != FORMAT:
            raise ConfigError(f"{path} is not a thermodem checkpoint")
        absent = [
            k for k in ("format_version", "kind", "step", "time", "created") if k not in f.attrs
        ]
        if absent:
            raise ConfigError(f"{damaged}: attribute(s) {', '.join(absent)} missing")
        try:
            version = int(f.attrs["format_version"])
            attrs = {k: f.attrs[k] for k in ("kind", "step", "time", "created")}
            attrs["message"] = f.attrs.get("message", "")
            attrs["run_id"] = f.attrs.get("run_id", "")
        except (KeyError, TypeError, ValueError) as exc:
            raise ConfigError(f"{damaged}: attribute {exc} is missing or wrong") from None
        if version != FORMAT_VERSION:
            raise ConfigError(
                f"{path}: checkpoint format version {version}, this thermodem reads "
                f"{FORMAT_VERSION}"
            )
        required = ("case_yaml", "scalars_json", "particles", "pairs", "walls", "arrays")
        lacking = [name for name in required if name not in f]
        if "thermal" in f:
            lacking += [f"thermal/{n}" for n in ("scalars_json", "arrays") if n not in f["thermal"]]
        if lacking:
            raise ConfigError(f"{damaged}: it has no {', '.join(lacking)}")
        try:
            state: dict[str, Any] = {"scalars": json.loads(_text(f["scalars_json"][()]))}
            for group in ("particles", "pairs", "walls", "arrays"):
                state[group] = _read_group(f[group])
            if "thermal" in f:
                g = f["thermal"]
                state["thermal"] = {
                    "scalars": json.loads(_text(g["scalars_json"][()])),
                    "arrays": _read_group(g["arrays"]),
                }
            case_yaml = _text(f["case_yaml"][()])
        except json.JSONDecodeError as exc:
            raise ConfigError(f"{damaged}: its scalars are not valid JSON ({exc})") from None
        except (KeyError, OSError, TypeError, ValueError) as exc:
            raise ConfigError(f"{damaged}: {exc}") from None
        kind = _text(attrs["kind"])
        if kind not in KINDS:
            raise ConfigError(f"{damaged}: kind {kind!r} is not one of {', '.join(KINDS)}")
    from thermodem.engine.restart import check_state, check_values

    _check_case_yaml(case_yaml, damaged)
    try:
        check_state(state)
        if kind != "failed":  # a failed state may hold the non-finite values that stopped it
            check_values(state)
    except ConfigError as exc:
        raise ConfigError(f"{damaged}: {exc}") from None
    return Checkpoint(
        path=path,
        case_yaml=case_yaml,
        state=state,
        kind=kind,
        step=int(attrs["step"]),
        time=float(attrs["time"]),
        created=_text(attrs["created"]),
        message=_text(attrs["message"]),
        run_id=_text(attrs["run_id"]),
    )


def load_simulation(
    path: str | os.PathLike[str] | Checkpoint,
    threads: int | None = None,
    case: Case | None = None,
) -> Simulation:
    """A new Simulation continuing from a checkpoint.

    ``case`` replaces the stored case (for example with a later ``end_time``); it must have the
    same materials, walls, pour entries and contact history layout, otherwise ConfigError.
    """
    from thermodem.engine.simulation import Simulation

    ckpt = path if isinstance(path, Checkpoint) else read_checkpoint(path)
    if ckpt.kind == "failed":
        raise ConfigError(
            f"{ckpt.path} holds the state at a failure (for inspection) and cannot be "
            "continued; restart from the last good checkpoint instead"
        )
    sim = Simulation(case or ckpt.case(), threads=threads, insert_particles=False)
    sim.load_state(ckpt.state)
    if case is not None and _list_geometry(case) != _list_geometry(ckpt.case()):
        sim._needs_rebuild = True  # (the stored lists are of the old domain or cut-off)
    return sim


def _list_geometry(case: Case) -> tuple[Any, float]:
    """What the neighbour lists are built for besides the particles and the skin (engine/
    restart.py: restore): the domain (its box, the periodic axes) and
    ``neighbors.extra_distance``."""
    return case.domain.model_dump(mode="json"), float(case.neighbors.extra_distance)
