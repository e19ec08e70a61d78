"""Serial twins of the parallel kernels (kernels/variants.py).

On one thread the parallel kernels run compiled without ``parallel``; the result must be the
one of the parallel kernel (tests/unit/test_threads.py compares whole runs on 1 thread, now
serial, with 2 threads, bit for bit). Here: the twin is a separate compiled function with a
cache entry of its own (Numba does not key its cache on ``parallel``: with one name the
twins would load each other's machine code), it keeps a factory's closure constants, the
thread count switches the variant, and serial and parallel give identical sums.
"""

from __future__ import annotations

import os

import numba
import numpy as np
import pytest
from numba import prange

from thermodem.engine.threads import apply_threads
from thermodem.kernels import variants as V


@V.parallel_kernel(error_model="numpy")
def _chunk_sums(values, out):
    chunk = 64
    for c in prange(out.shape[0]):
        total = 0.0
        for k in range(c * chunk, min(values.shape[0], (c + 1) * chunk)):
            total += values[k] * values[k]
        out[c] = total


def _scaled(factor):
    @V.parallel_kernel()
    def scale(values, out):
        for k in prange(values.shape[0]):
            out[k] = factor * values[k]

    return scale


@pytest.fixture
def restore_threads():
    previous = numba.get_num_threads()
    yield
    apply_threads(previous)


@pytest.mark.filterwarnings("ignore::numba.core.errors.NumbaPerformanceWarning")
def test_serial_twin_is_its_own_compiled_function(restore_threads):
    values = np.random.default_rng(3).random(1000)
    parallel = np.zeros(16)
    serial = np.zeros(16)
    _chunk_sums.parallel(values, parallel)
    _chunk_sums.serial(values, serial)
    assert np.array_equal(parallel, serial)
    expected = [np.sum(values[c * 64 : (c + 1) * 64] ** 2) for c in range(16)]
    np.testing.assert_allclose(serial, expected, rtol=1e-14)
    assert _chunk_sums.serial is not _chunk_sums.parallel
    # Numba's parallel pipeline with every parallel transformation off: no parfor, the
    # loops in order on the calling thread (kernels/variants.py: NO_PARFORS)
    # Numba's ParallelOptions pops the keys of the dict it gets: each twin has its own copy
    # and the module's dict keeps every switch (a shared, emptied dict turned every twin
    # after the first into a full parallel kernel)
    assert len(V.NO_PARFORS) == 8 and not any(V.NO_PARFORS.values())
    assert _chunk_sums.serial.targetoptions["parallel"] is not V.NO_PARFORS
    assert _chunk_sums.parallel.targetoptions["parallel"]
    # their own cache entries (index files named after the qualname)
    assert _chunk_sums.serial.py_func.__qualname__ == "_chunk_sums__serial"
    names = {d._cache._impl.filename_base for d in (_chunk_sums.serial, _chunk_sums.parallel)}
    assert len(names) == 2


def test_twin_keeps_the_closure_constants():
    values = np.arange(5.0)
    out = np.zeros(5)
    double, triple = _scaled(2.0), _scaled(3.0)
    double.serial(values, out)
    assert np.array_equal(out, 2.0 * values)
    triple.serial(values, out)
    assert np.array_equal(out, 3.0 * values)
    triple.parallel(values, out)
    assert np.array_equal(out, 3.0 * values)


@pytest.mark.skipif(numba.config.NUMBA_NUM_THREADS < 2, reason="Numba has fewer than 2 threads")
def test_thread_count_switches_the_variant(restore_threads):
    values = np.ones(10)
    apply_threads(1)
    assert V.serial_mode() and numba.get_num_threads() == 1
    apply_threads(2)
    assert not V.serial_mode() and numba.get_num_threads() == 2
    twin = _scaled(5.0)
    out = np.zeros(10)
    twin(values, out)  # two threads: the parallel kernel compiles, the twin does not
    assert twin._serial is None and twin.parallel.signatures
    apply_threads(1)
    twin(values, out)
    assert twin._serial is not None and twin._serial.signatures
    assert np.array_equal(out, 5.0 * values)


def test_twin_compiles_without_a_warning(restore_threads):
    """The twin asks Numba's parallel pipeline for no parallel transformation, and Numba
    warns when it finds none: a user must not see that warning (the first call hides it)."""
    import warnings

    from numba.core.errors import NumbaPerformanceWarning

    factor = float(np.random.default_rng().uniform(1.0, 2.0))  # a new closure: compiled now
    kernel = _scaled(factor)
    values = np.arange(4.0)
    out = np.zeros(4)
    apply_threads(1)
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        kernel(values, out)
    assert np.array_equal(out, factor * values)
    assert not [w for w in seen if issubclass(w.category, NumbaPerformanceWarning)]


@pytest.mark.filterwarnings("ignore::numba.core.errors.NumbaPerformanceWarning")
def test_every_twin_compiles_without_a_parfor(tmp_path):
    """Compiled fresh in a subprocess (an empty cache, so the parfor diagnostics exist):
    two kernels' twins, one after the other, have no parfor; the parallel kernels do."""
    import subprocess
    import sys
    import textwrap

    script = textwrap.dedent(
        """
        import numpy as np
        from numba import prange
        from thermodem.kernels import variants as V

        @V.parallel_kernel()
        def first(values, out):
            for k in prange(values.shape[0]):
                out[k] = 2.0 * values[k]

        @V.parallel_kernel()
        def second(values, out):
            for k in prange(values.shape[0]):
                out[k] = 3.0 * values[k]

        values, out = np.arange(100.0), np.zeros(100)
        for kernel in (first, second):
            kernel.serial(values, out)
            kernel.parallel(values, out)
            counts = []
            for variant in (kernel.serial, kernel.parallel):
                metadata = variant.get_metadata(variant.signatures[0])
                counts.append(len(metadata["parfor_diagnostics"].initial_parfors))
            print(kernel.__name__, *counts)
        """
    )
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache")}
    path = tmp_path / "twins.py"  # a file: Numba caches no function defined in ``-c``
    path.write_text(script)
    done = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["first", "0", "1", "second", "0", "1"]
