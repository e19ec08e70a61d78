"""Communication of an MPI run: reductions, particle rows, migration and the ghost halo.

Everything goes through mpi4py's buffer (uppercase) API on contiguous float64/int64 NumPy
arrays; pickled objects only carry the text of an error message.

- **Reductions** (:func:`allreduce_sum`, ``_max``, ``_min``) of small arrays.
- **Particle rows**: the complete state of a particle (every :class:`Particles` array, plus
  per-particle arrays of the thermal engine) packed into one float64 row (integers are
  exact in float64 below 2^53), :func:`pack_particles` / :func:`unpack_particles`.
- **All-to-all of rows** (:func:`alltoallv_rows`): migration and the ghosts of a rebuild
  (counts by ``Alltoall``, rows by ``Alltoallv``).
- **The halo** (:class:`Halo`): at every step the owners send the moving state of the
  particles other ranks hold as ghosts (``Isend`` / ``Irecv`` of packed buffers).
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from thermodem.kernels.halo import pack_moving, unpack_moving
from thermodem.state.particles import Particles


def _mpi() -> Any:
    from mpi4py import MPI

    return MPI


# ----------------------------------------------------------------------------- reductions
def _allreduce(comm: Any, values: np.ndarray, op: str) -> np.ndarray:
    values = np.ascontiguousarray(values)
    if comm is None:
        return values.copy()
    mpi = _mpi()
    out = np.empty_like(values)
    comm.Allreduce(values, out, op={"sum": mpi.SUM, "max": mpi.MAX, "min": mpi.MIN}[op])
    return out


def allreduce_sum(comm: Any, values: np.ndarray) -> np.ndarray:
    """Element-wise sum over the ranks (a copy with ``comm`` None)."""
    return _allreduce(comm, values, "sum")


def allreduce_max(comm: Any, values: np.ndarray) -> np.ndarray:
    """Element-wise maximum over the ranks."""
    return _allreduce(comm, values, "max")


def allreduce_min(comm: Any, values: np.ndarray) -> np.ndarray:
    """Element-wise minimum over the ranks."""
    return _allreduce(comm, values, "min")


# --------------------------------------------------------------------------- particle rows
def row_layout(p: Particles) -> list[tuple[str, int]]:
    """(field name, columns) of a particle row, in the order of :class:`Particles`."""
    out = []
    for f in fields(p):
        a = getattr(p, f.name)
        out.append((f.name, 1 if a.ndim == 1 else int(a.shape[1])))
    return out


def row_width(p: Particles, extra_widths: tuple[int, ...] = ()) -> int:
    return sum(w for _, w in row_layout(p)) + sum(extra_widths)


def pack_particles(
    p: Particles, index: np.ndarray | slice, extras: tuple[np.ndarray, ...] = ()
) -> np.ndarray:
    """Rows of the particles ``index`` (indices, or a slice: no copy before the packing):
    every Particles array, then the ``extras`` (per particle arrays, 1-D or 2-D)."""
    layout = row_layout(p)
    widths = tuple(1 if e.ndim == 1 else int(e.shape[1]) for e in extras)
    m = p.radius[index].shape[0]
    rows = np.empty((m, row_width(p, widths)))
    c = 0
    for name, w in layout:
        rows[:, c : c + w] = getattr(p, name)[index].reshape(m, w)
        c += w
    for e, w in zip(extras, widths, strict=True):
        rows[:, c : c + w] = e[index].reshape(m, w)
        c += w
    return rows


def unpack_particles(
    rows: np.ndarray, template: Particles, extra_widths: tuple[int, ...] = ()
) -> tuple[Particles, list[np.ndarray]]:
    """Particles (and the extras) of packed rows; ``template`` gives the dtypes and widths."""
    m = rows.shape[0]
    arrays = {}
    c = 0
    for name, w in row_layout(template):
        proto = getattr(template, name)
        block = rows[:, c : c + w]
        if proto.ndim == 1:
            arrays[name] = np.ascontiguousarray(block[:, 0]).astype(proto.dtype)
        else:
            arrays[name] = np.ascontiguousarray(block).astype(proto.dtype).reshape(m, w)
        c += w
    extras = []
    for w in extra_widths:
        block = rows[:, c : c + w]
        extras.append(np.ascontiguousarray(block[:, 0] if w == 1 else block))
        c += w
    return Particles(**arrays), extras


def _fortran(array: np.ndarray) -> bool:
    """A Fortran-ordered (n, k) particle array (the heat rates by mechanism)."""
    return array.ndim == 2 and array.flags.f_contiguous and not array.flags.c_contiguous


def _take(array: np.ndarray, index: np.ndarray | slice) -> np.ndarray:
    """Rows ``index`` of a particle array, copied in the array's own order (the heat rates
    are Fortran-ordered: taken through the transpose, no C copy to convert)."""
    if _fortran(array):
        return np.array(array.T[:, index], order="C").T  # (a copy, also of a slice)
    if isinstance(index, slice):
        return array[index].copy()
    return np.ascontiguousarray(array[index])


def take_particles(p: Particles, index: np.ndarray | slice) -> Particles:
    """A new Particles holding the particles ``index`` (copies; a slice is copied as a block,
    much faster than the same indices as an array)."""
    return Particles(**{f.name: _take(getattr(p, f.name), index) for f in fields(p)})


def take_joined(a: Particles, a_rows: np.ndarray, b: Particles, b_rows: np.ndarray) -> Particles:
    """The particles ``a_rows`` of ``a`` followed by ``b_rows`` of ``b``, each array copied
    once into its new place (a take and a concatenation would copy ``a``'s rows twice)."""
    na, nb = a_rows.shape[0], b_rows.shape[0]
    arrays = {}
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        order = "F" if _fortran(x) else "C"
        out = np.empty((na + nb, *x.shape[1:]), x.dtype, order=order)
        if order == "F":  # (the heat rates by mechanism: column by column, each contiguous;
            # fancy indexing through the transpose was 3x slower)
            for c in range(x.shape[1]):
                np.take(x[:, c], a_rows, out=out[:na, c], mode="clip")
                np.take(y[:, c], b_rows, out=out[na:, c], mode="clip")
        else:
            np.take(x, a_rows, axis=0, out=out[:na], mode="clip")
            np.take(y, b_rows, axis=0, out=out[na:], mode="clip")
        arrays[f.name] = out
    return Particles(**arrays)


def view_particles(p: Particles, rows: slice) -> Particles:
    """The particles ``rows`` as views of ``p``'s arrays (no copy: the caller must not
    change ``p`` while it uses them)."""
    return Particles(**{f.name: getattr(p, f.name)[rows] for f in fields(p)})


def _joined(arrays: list[np.ndarray]) -> np.ndarray:
    if _fortran(arrays[0]):
        return np.ascontiguousarray(np.concatenate([a.T for a in arrays], axis=1)).T
    return np.ascontiguousarray(np.concatenate(arrays))


def concatenate_particles(parts: list[Particles]) -> Particles:
    names = [f.name for f in fields(parts[0])]
    return Particles(**{name: _joined([getattr(q, name) for q in parts]) for name in names})


# ------------------------------------------------------------------------ all-to-all rows
def alltoallv_rows(
    comm: Any, blocks: list[np.ndarray], width: int
) -> tuple[np.ndarray, np.ndarray]:
    """Send ``blocks[r]`` (rows of ``width`` float64) to rank r; returns the received rows
    (in the order of the source ranks) and the number of rows from each source."""
    mpi = _mpi()
    size = comm.Get_size()
    send_rows = np.array([b.shape[0] for b in blocks], np.int64)
    recv_rows = np.empty(size, np.int64)
    comm.Alltoall(send_rows, recv_rows)
    send = (
        np.ascontiguousarray(np.concatenate(blocks)).reshape(-1) if send_rows.sum() else np.zeros(0)
    )
    recv = np.empty(int(recv_rows.sum()) * width)
    sc = send_rows * width
    rc = recv_rows * width
    sd = np.concatenate([[0], np.cumsum(sc)[:-1]])
    rd = np.concatenate([[0], np.cumsum(rc)[:-1]])
    comm.Alltoallv([send, (sc, sd), mpi.DOUBLE], [recv, (rc, rd), mpi.DOUBLE])
    return recv.reshape(-1, width), recv_rows


# -------------------------------------------------------------------------------- the halo
@dataclass
class Halo:
    """Who sends which owned particles to whom every step, and where ghosts land.

    ``send[k] = (rank, local indices of owned particles)``, ``recv[k] = (rank, local indices
    of the ghosts it sends, in its send order)``; the buffers are allocated once per rebuild.
    """

    send: list[tuple[int, np.ndarray]] = field(default_factory=list)
    recv: list[tuple[int, np.ndarray]] = field(default_factory=list)
    width: int = 9
    _send_buffers: list[np.ndarray] = field(default_factory=list)
    _recv_buffers: list[np.ndarray] = field(default_factory=list)
    seconds: float = 0.0
    messages: int = 0
    bytes_sent: int = 0

    def allocate(self, with_temperature: bool) -> None:
        self.width = 10 if with_temperature else 9
        self._send_buffers = [np.empty((idx.shape[0], self.width)) for _, idx in self.send]
        self._recv_buffers = [np.empty((idx.shape[0], self.width)) for _, idx in self.recv]

    @property
    def ghost_count(self) -> int:
        return int(sum(idx.shape[0] for _, idx in self.recv))

    def exchange(self, comm: Any, p: Particles) -> None:
        """Send the moving state of the owned particles in the send lists, receive the
        ghosts' (a collective step of every rank with its neighbours)."""
        import time

        mpi = _mpi()
        t0 = time.perf_counter()
        with_t = self.width == 10
        requests = []
        for (rank, _), buf in zip(self.recv, self._recv_buffers, strict=True):
            requests.append(comm.Irecv([buf, mpi.DOUBLE], source=rank, tag=77))
        for (rank, idx), buf in zip(self.send, self._send_buffers, strict=True):
            pack_moving(p.position, p.velocity, p.angular_velocity, p.temperature, with_t, idx, buf)
            requests.append(comm.Isend([buf, mpi.DOUBLE], dest=rank, tag=77))
            self.bytes_sent += buf.nbytes
        mpi.Request.Waitall(requests)
        for (_, idx), buf in zip(self.recv, self._recv_buffers, strict=True):
            unpack_moving(buf, idx, p.position, p.velocity, p.angular_velocity, p.temperature,
                          with_t)  # fmt: skip
        self.messages += len(requests)
        self.seconds += time.perf_counter() - t0
