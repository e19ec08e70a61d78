"""Per-contact VTU frames: one line cell per touching contact, from the centre of particle i
to the centre of particle j (to the contact point for a wall contact), with the arrays of
:func:`thermodem.engine.contacts.contact_data` as cell data (``id_i``, ``normal_force``,
``conductance_direct_conduction``, ...). In ParaView: colour the lines by ``normal_force`` for
the force chains, by ``heat_rate_*`` for the heat paths; a *Tube* filter with the radius
scaled by a cell array draws them as tubes."""

from __future__ import annotations

import os
from pathlib import Path

import meshio
import numpy as np

_VTU_OPTIONS = {"binary": True, "header_type": "UInt64"}


def write_contacts_vtu(
    path: str | os.PathLike[str],
    data: dict[str, np.ndarray],
    centre_i: np.ndarray,
    centre_j: np.ndarray,
) -> None:
    """Write the contacts of ``data`` as line cells from ``centre_i`` to ``centre_j`` ((m, 3)
    each); an empty frame (no contact) is still a valid VTU file."""
    m = int(data["id_i"].shape[0])
    points = np.concatenate([centre_i, centre_j]).reshape(2 * m, 3) if m else np.zeros((0, 3))
    lines = np.stack([np.arange(m), m + np.arange(m)], axis=1).astype(np.int64)
    cell_data = {}
    for name, value in data.items():
        a = np.ascontiguousarray(value)
        if a.dtype == np.int64:
            a = a.astype(np.float64) if np.abs(a).max(initial=0) > 2**31 - 1 else a.astype(np.int32)
        cell_data[name] = [a]
    out = Path(path)
    out.parent.mkdir(parents=True, exist_ok=True)
    if m == 0:  # meshio needs a cell block: one empty vertex block keeps readers happy
        mesh = meshio.Mesh(np.zeros((0, 3)), [("vertex", np.zeros((0, 1), np.int64))])
    else:
        mesh = meshio.Mesh(points, [("line", lines)], cell_data=cell_data)
    meshio.write(out, mesh, file_format="vtu", compression=None, **_VTU_OPTIONS)
