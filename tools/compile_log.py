"""Where the test suite's compile time goes: a pytest plugin that logs every Numba compile.

Numba announces each compilation (not the loads from its cache) as a ``numba:compile``
event; this plugin listens to it and appends, per worker process, one JSON line per
top-level compile: the kernel's qualified name, the seconds it took and the test running
at the time. Run the suite with an empty cache and the plugin, then summarise:

    rm -rf /tmp/cold && mkdir /tmp/cold
    THERMODEM_CACHE_DIR=/tmp/cold PYTHONPATH=tools COMPILE_LOG=/tmp/compile_log \\
        .venv/bin/python -m pytest -q -n 2 -p compile_log
    python tools/compile_log.py /tmp/compile_log

The summary prints the total, the kernels by compile time (count and seconds) and the tests
that compiled the most. Compiles in subprocesses (the CLI and MPI tests) are not logged.
Session 16 found with it 57 serial and 8 parallel particle pair pass variants (~6 s and
~11 s each) in 761 s of in-process compilation (docs/STATUS.md).
"""

from __future__ import annotations

import collections
import glob
import json
import os
import sys
import time

DIRECTORY = os.environ.get("COMPILE_LOG", "/tmp/compile_log")


def _install() -> None:
    from numba.core import event

    os.makedirs(DIRECTORY, exist_ok=True)
    path = os.path.join(DIRECTORY, f"{os.getpid()}.jsonl")

    class Listener(event.Listener):
        def __init__(self) -> None:
            self.started: list[float] = []

        def on_start(self, ev: event.Event) -> None:
            self.started.append(time.perf_counter())

        def on_end(self, ev: event.Event) -> None:
            t0 = self.started.pop()
            if self.started:  # (a kernel compiled inside another: counted in the outer)
                return
            func = getattr(ev.data.get("dispatcher"), "py_func", None)
            name = f"{getattr(func, '__module__', '')}.{getattr(func, '__qualname__', func)}"
            test = os.environ.get("PYTEST_CURRENT_TEST", "").split(" ")[0]
            with open(path, "a") as f:
                f.write(json.dumps([name, time.perf_counter() - t0, test]) + "\n")

    event.register("numba:compile", Listener())


def summarise(directory: str) -> None:
    rows = [json.loads(line) for p in glob.glob(f"{directory}/*.jsonl") for line in open(p)]
    print(f"{len(rows)} compiles, {sum(r[1] for r in rows):.0f} s")
    kernels: dict[str, list[float]] = collections.defaultdict(list)
    tests: dict[str, float] = collections.defaultdict(float)
    for name, seconds, test in rows:
        kernels[name].append(seconds)
        tests[test] += seconds
    print("kernels (seconds, compiles):")
    for name, times in sorted(kernels.items(), key=lambda kv: -sum(kv[1]))[:25]:
        print(f"  {sum(times):7.1f} {len(times):4d}  {name}")
    print("tests (seconds):")
    for test, seconds in sorted(tests.items(), key=lambda kv: -kv[1])[:25]:
        print(f"  {seconds:7.1f}  {test}")


if __name__ == "__main__":
    summarise(sys.argv[1] if len(sys.argv) > 1 else DIRECTORY)
elif "pytest" in sys.modules:  # loaded as a plugin (-p compile_log)
    _install()
