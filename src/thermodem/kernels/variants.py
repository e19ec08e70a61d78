"""Parallel kernels with a serial twin for one-thread runs.

A kernel compiled with ``parallel=True`` costs more to compile than the same loop compiled
serially (the parfor lowering and fusion: 3 of the particle pair pass's 7 s, 2 of the wall
pass's 3.5 s on a 2-core VM) and each call launches the threading layer even with one thread
(~0.9 µs per call with OpenMP). Small cases run on one thread
(:func:`thermodem.engine.threads.choose_threads`), so for them, and for any run on one
thread, thermodem runs the same Python function compiled with every parallel transformation
off (:data:`NO_PARFORS`): ``prange`` is then ``range`` and the loop order, hence every sum,
is the one of the parallel kernel on one thread (the parallel kernels are written so that
their result does not depend on the thread count; tests check 1 vs 2 threads bit-identical,
and serial vs parallel). ``parallel=False`` would give the same loops but, measured, about
half their speed (:data:`NO_PARFORS`).

:func:`parallel_kernel` replaces ``@njit(cache=True, parallel=True, ...)``. It returns a
:class:`ParallelKernel`, called like the dispatcher; which variant runs follows the thread
count set through :func:`thermodem.engine.threads.apply_threads` (serial iff one thread).
Each variant is compiled on its first call only, and cached on disk under its own name
(``<qualname>__serial``): Numba keys a cached kernel on its file, name, line, bytecode and
closure constants but not on ``parallel``, so two variants with one name would load each
other's machine code.

A :class:`ParallelKernel` is called from Python only (the orchestration); a kernel that
another compiled function calls stays a plain ``njit`` function.
"""

from __future__ import annotations

import types
import warnings
from collections.abc import Callable
from typing import Any

from numba import njit
from numba.core.errors import NumbaPerformanceWarning

#: ``parallel`` option of the twins: Numba's parallel pipeline with every parallel
#: transformation off (no parfor, so no gufunc and no thread launch: the loops run in order
#: on the calling thread). Measured: the twin compiled with ``parallel=False`` ran the
#: particle pair pass about twice as slow as the parallel kernel on one Numba thread (50k
#: shared bed, mechanics: 3.1 against 5.5 M particle-steps/s), compiled this way as fast
#: (5.1-5.2 M; jammed beds of 250-16,000 spheres within the scatter of the parallel kernel
#: on one thread), for ~1.2 s more compile time than ``parallel=False`` on a heated case.
NO_PARFORS = {
    "comprehension": False,
    "reduction": False,
    "inplace_binop": False,
    "setitem": False,
    "numpy": False,
    "stencil": False,
    "fusion": False,
    "prange": False,
}


class _Mode:
    """Which variant runs: the serial one iff ``serial``."""

    serial = False


def set_serial(serial: bool) -> None:
    """Run the serial twins (``True``, a one-thread run) or the parallel kernels."""
    _Mode.serial = bool(serial)


def serial_mode() -> bool:
    """Whether the serial twins run."""
    return _Mode.serial


class ParallelKernel:
    """A ``parallel=True`` dispatcher and its serial twin (made on first use)."""

    def __init__(self, dispatcher: Any, options: dict) -> None:
        self.parallel = dispatcher
        self._serial = None
        self._twin_ready = False  # the twin has run once (compiled or loaded)
        self._options = options
        self.__name__ = dispatcher.py_func.__name__
        self.__qualname__ = dispatcher.py_func.__qualname__
        self.__doc__ = dispatcher.py_func.__doc__

    @property
    def py_func(self) -> Callable:
        """The Python function both variants compile."""
        return self.parallel.py_func

    @property
    def serial(self) -> Any:
        """The serial twin: the same function (code, globals, closure) under the name
        ``<qualname>__serial``, compiled with every parallel transformation off
        (:data:`NO_PARFORS`)."""
        if self._serial is None:
            f = self.parallel.py_func
            twin = types.FunctionType(
                f.__code__, f.__globals__, f.__name__, f.__defaults__, f.__closure__
            )
            twin.__qualname__ = f.__qualname__ + "__serial"
            twin.__module__ = f.__module__
            twin.__doc__ = f.__doc__
            twin.__kwdefaults__ = f.__kwdefaults__
            # a copy: Numba's ParallelOptions pops the keys of the dict it is given, so a
            # shared dict would leave every later twin with all transformations on
            self._serial = njit(cache=True, parallel=dict(NO_PARFORS), **self._options)(twin)
        return self._serial

    def __call__(self, *args: Any) -> Any:
        if _Mode.serial:
            if self._twin_ready:
                return self._serial(*args)
            return self._first_serial_call(args)
        return self.parallel(*args)

    def _first_serial_call(self, args: tuple) -> Any:
        """The twin's first call, which compiles or loads it: without Numba's warning that
        ``parallel`` found nothing to parallelise (the twin asks for exactly that)."""
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumbaPerformanceWarning)
            out = self.serial(*args)
        self._twin_ready = True
        return out

    def __repr__(self) -> str:
        return f"<ParallelKernel {self.__qualname__}>"


def parallel_kernel(**options: Any) -> Callable[[Callable], ParallelKernel]:
    """Decorator: ``@parallel_kernel(error_model="numpy")`` compiles the function with
    ``njit(cache=True, parallel=True, **options)`` and gives it a serial twin (see the module
    docstring)."""

    def wrap(f: Callable) -> ParallelKernel:
        return ParallelKernel(njit(cache=True, parallel=True, **options)(f), options)

    return wrap
