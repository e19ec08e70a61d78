"""Threads: which Numba threading layer thermodem uses, and how many threads a run gets.

**Layer.** Numba picks its threading layer at the first parallel kernel from what the machine
has (TBB, then OpenMP, then its own workqueue). Left to itself, a machine with Intel TBB
installed (Debian's ``libtbb12``, conda, the ``tbb`` wheel) runs thermodem on TBB, and a
process that used TBB can spin for minutes in TBB's shutdown at exit (issue 17). thermodem
therefore selects and launches the layer itself when the package is imported, before any
parallel kernel runs (:func:`configure_threading_layer`, called from ``thermodem/__init__.py``):

- ``omp`` (GNU OpenMP, ``libgomp``), the fastest measured;
- ``workqueue`` (Numba's own) when OpenMP cannot be loaded; the run log then says why;
- whatever ``NUMBA_THREADING_LAYER`` names, when the user set it.

With any layer, ``OMP_WAIT_POLICY=passive`` and ``GOMP_SPINCOUNT`` = :data:`SPIN_COUNT` are
set unless the environment sets either: a waiting OpenMP thread spins for about 0.1 ms, then
sleeps. The spin covers the gaps between the parallel regions of a step (waking a sleeping
thread cost 80-140 µs per region on the 2-core VM: the idle virtual core halts), and the
bound keeps 2 threads from becoming many times slower than 1 when another process shares the
cores, which unbounded spinning did; what bounded spinning still loses then, the
:class:`ThreadGovernor` of an automatically chosen count takes back by running on 1 thread
(docs/architecture.md, "Threads").

GNU OpenMP is not fork-safe: a process that forks after a parallel kernel ran must not run
parallel kernels in the child (thermodem itself never forks; ``subprocess`` is fine).

**Count.** Small systems do not pay for threads: without a request (``--threads``,
``Simulation(threads=...)``) a simulation takes 1 thread below :data:`PARALLEL_MIN_PARTICLES`
particles (and :data:`PARALLEL_MIN_PAIRS` listed pairs), and every thread Numba has above
(:func:`choose_threads`). Results do not depend on the thread count (tests/unit/test_threads.py).

**Variants.** On one thread the parallel kernels run as serial twins
(:mod:`thermodem.kernels.variants`: no parfor to compile, no thread launch per call); every
change of the count goes through :func:`apply_threads`, which switches both.
"""

from __future__ import annotations

import os

#: The mean particle count and listed pair count from which 2 threads are faster than 1
#: (tools/measure_threads.py on the 2-core VM, docs/architecture.md "Threads": 2 threads lose
#: 6-14 % at 500-1000 particles and gain from about 2000): below both a simulation runs on 1
#: thread unless told otherwise. The pair threshold is the jammed bed's 2.7 pairs per particle.
PARALLEL_MIN_PARTICLES = 2000
PARALLEL_MIN_PAIRS = 5500

#: GNU OpenMP's spin count of a waiting thread (``GOMP_SPINCOUNT``): about 0.1-0.15 ms on the
#: 2-core VM. Measured there (docs/architecture.md, "Threads"; 50k shared bed, mechanics,
#: 2 threads, M particle-steps/s): sleeping at once 9.5, 3000 9.75, 10000 10.5, 30000 10.9
#: idle; with one busy process beside it 5.8, -, 4.8, 3.7.
SPIN_COUNT = 10000

_layer_note = ""


def configure_threading_layer() -> None:
    """Select the threading layer (``omp``, else ``workqueue``) unless it is already
    launched or the user chose one with ``NUMBA_THREADING_LAYER``."""
    global _layer_note
    import numba

    try:
        numba.threading_layer()
    except ValueError:
        pass  # not launched yet: the choice is still open
    else:
        _layer_note = "launched before thermodem was imported"
        return
    if "OMP_WAIT_POLICY" not in os.environ and "GOMP_SPINCOUNT" not in os.environ:
        # read by libgomp when it loads: a bounded spin, then sleep
        os.environ["OMP_WAIT_POLICY"] = "passive"
        os.environ["GOMP_SPINCOUNT"] = str(SPIN_COUNT)
    chosen = os.environ.get("NUMBA_THREADING_LAYER", "").strip()
    if chosen and chosen.lower() != "default":
        _layer_note = f"set by NUMBA_THREADING_LAYER={chosen}"
        return
    try:
        from numba.np.ufunc import omppool  # noqa: F401 (loads libgomp)

        numba.config.THREADING_LAYER = "omp"
        numba.get_num_threads()  # launch it now (below)
        _layer_note = ""
    except (ImportError, ValueError, OSError) as exc:
        numba.config.THREADING_LAYER = "workqueue"
        _layer_note = (
            f"the OpenMP layer could not be loaded ({exc}); workqueue is slower for small "
            "systems (install the OpenMP runtime, e.g. Debian's libgomp1)"
        )
        numba.get_num_threads()
    # Launched at import: Numba re-reads its configuration from the environment whenever a
    # NUMBA_* variable changed, which would put the layer back to its default before the
    # first parallel kernel; a launched layer stays.


def threading_layer() -> str:
    """The layer in use (launching it if no parallel kernel ran yet), with the reason when it
    is not thermodem's first choice: ``'omp'``, ``'workqueue (the OpenMP layer ...)'``."""
    import numba

    numba.get_num_threads()  # launches the layer
    name = numba.threading_layer()
    return f"{name} ({_layer_note})" if _layer_note else name


def apply_threads(threads: int) -> None:
    """Run the following kernels on ``threads`` Numba threads: the serial twins of the
    parallel kernels on one thread (:mod:`thermodem.kernels.variants`), else the parallel
    kernels with ``numba.set_num_threads(threads)``."""
    import numba

    from thermodem.kernels.variants import set_serial

    numba.set_num_threads(int(threads))
    set_serial(int(threads) == 1)


def available_threads() -> int:
    """Threads Numba has (``NUMBA_NUM_THREADS``, default: the CPU count)."""
    import numba

    return int(numba.config.NUMBA_NUM_THREADS)


#: (the --threads given, the count it was lowered to) when the command line lowered it to
#: the cores the process can use, so that run.log does not say "as requested" of a count the
#: user did not request (set by :func:`note_lowered`, for the next simulation built).
_lowered: tuple[int, int] | None = None


def note_lowered(given: int | None, used: int | None) -> None:
    """Remember that the command line's ``--threads given`` became ``used`` (None: as given)."""
    global _lowered
    _lowered = (given, used) if given is not None and used is not None and given != used else None


def choose_threads(particles: float, pairs: int, requested: int | None = None) -> tuple[int, str]:
    """(thread count, why) for a simulation with ``particles`` particles (mean over the run)
    and ``pairs`` listed pairs; ``requested`` (a user's choice) wins."""
    if requested is not None:
        if _lowered is not None and _lowered[1] == int(requested):
            return int(requested), (
                f"--threads {_lowered[0]} lowered to the {_lowered[1]} core(s) this process can use"
            )
        return int(requested), "as requested"
    most = available_threads()
    n = int(round(particles))
    if most <= 1:
        return 1, f"{n} particles; Numba has 1 thread"
    if particles < PARALLEL_MIN_PARTICLES and pairs < PARALLEL_MIN_PAIRS:
        return 1, (
            f"chosen for {n} particles and {pairs} pairs: below {PARALLEL_MIN_PARTICLES} "
            "particles 1 thread is faster; --threads N to change"
        )
    return most, (
        f"chosen for {n} particles and {pairs} pairs (2 threads pay from about "
        f"{PARALLEL_MIN_PARTICLES} particles); --threads N to change"
    )


class ThreadGovernor:
    """Keeps an automatically chosen thread count (more than one) only while it pays.

    Several threads lose to one when another process holds one of the cores (the threads of a
    parallel region wait for each other) or when the system is too small for them. The
    governor adds up the seconds of the steps (not of outputs between them) in windows of at
    least :attr:`WINDOW_SECONDS` and :attr:`MIN_WINDOW_STEPS` steps, without the window's
    slowest step (a kernel compiled or loaded on its first call, a neighbour-list build); after
    the first window and then every
    :attr:`PERIOD_WINDOWS` windows it runs one window on the other count (1 thread, or back
    to the chosen count) and keeps that count only if it was faster per step by more than
    :attr:`MARGIN`. Results do not depend on the thread count (the kernels' sums run in a
    fixed chunk order, tests/unit/test_threads.py), so switching changes the speed only. A
    count the user asked for is kept (:attr:`active` False), as is one thread.

    :meth:`tick` is called after every step with its duration and returns the count to apply
    when it changes.
    """

    WINDOW_SECONDS = 0.25
    MIN_WINDOW_STEPS = 10
    PERIOD_WINDOWS = 40
    MARGIN = 0.05

    def __init__(self, chosen: int, automatic: bool) -> None:
        self.chosen = int(chosen)
        self.active = automatic and self.chosen > 1
        self.current = self.chosen
        self.switches = 0  # probes and switches back
        self.single_steps = 0  # steps that ran on 1 thread (for the run log)
        self._seconds = 0.0  # the window's step seconds, slowest step and steps so far
        self._slowest = 0.0
        self._steps = 0
        self._reference = 0.0  # seconds per step of the window before a probe
        self._probing = False
        self._windows = self.PERIOD_WINDOWS - 1  # the first probe after one window

    def tick(self, seconds: float) -> int | None:
        """A step took ``seconds``: the thread count to switch to, or None."""
        if not self.active:
            return None
        self._seconds += seconds
        self._slowest = max(self._slowest, seconds)
        self._steps += 1
        if self.current == 1:
            self.single_steps += 1
        if self._seconds < self.WINDOW_SECONDS or self._steps < self.MIN_WINDOW_STEPS:
            return None
        if self._steps > 1:
            per_step = (self._seconds - self._slowest) / (self._steps - 1)
        else:
            per_step = self._seconds
        self._seconds, self._slowest, self._steps = 0.0, 0.0, 0
        other = 1 if self.current == self.chosen else self.chosen
        if self._probing:  # the window just timed ran on the probed count
            self._probing = False
            self._windows = 0
            if per_step < (1.0 - self.MARGIN) * self._reference:
                return None  # the probed count was faster: it stays
            self.current = other
            self.switches += 1
            return self.current
        self._windows += 1
        if self._windows < self.PERIOD_WINDOWS:
            return None
        self._reference = per_step
        self._probing = True
        self.current = other
        self.switches += 1
        return self.current
