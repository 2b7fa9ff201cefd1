"""Overhead of recording runs: the language benchmarks' workloads with recording off and on.

    .venv/bin/python benchmarks/recording_overhead.py [--repeat N] [--db URL]

Workloads (as in the language benchmarks): `seq` of 1,000 steps, `par` of 100 branches, and ten
`pursue`s whose waiting loser is evaporated. `benchmarks/language.py --record` prints every
language figure (wake latency, evaporation latency, idle monitors' CPU too) with recording off
and on.
Each is timed `repeat` times with recording off, then on (a `pycram.trace.Recorder` attached,
its writer committing in the background to a temporary SQLite file unless `--db` is given);
the medians and the means are printed with the relative overheads. The target is at most 10 %.

The median is the cost a plan sees in its steps (the recorder's per-task callbacks). The mean
also contains the writer thread's share of the interpreter: it competes for the GIL while it
writes a batch, so under a sustained stream of empty tasks (hundreds of thousands per second,
far more than any robot plan creates) the iterations that overlap a batch are slower. The final
flush in `finish()` happens after the plan returned and is printed separately. Objects alive
after start-up are frozen (`gc.freeze()`), so that a full garbage collection -- ~100 ms with
SQLAlchemy loaded -- does not land in a random iteration of either mode.
"""

from __future__ import annotations

import argparse
import gc
import statistics
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from pycram.core.runtime.workers import shutdown_idle_workers  # noqa: E402
from pycram.fluent import Fluent  # noqa: E402
from pycram.language import par, pursue, seq  # noqa: E402


def _noop() -> None:
    return None


def seq_1000() -> None:
    seq(*[_noop] * 1000)


def par_100() -> None:
    par(*[_noop] * 100)


def pursue_10() -> None:
    """Ten pursues whose loser waits on a fluent and is evaporated (evaporated rows)."""
    for _ in range(10):
        pursue(lambda: Fluent().wait_for(), _noop)


WORKLOADS: dict[str, Callable[[], None]] = {"seq 1,000": seq_1000, "par 100": par_100, "pursue ×10": pursue_10}


def _time(fn: Callable[[], None], repeat: int) -> list[float]:
    fn()  # warm up (worker threads, caches)
    times = []
    for _ in range(repeat):
        started = time.perf_counter()
        fn()
        times.append(time.perf_counter() - started)
    return times


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=60)
    parser.add_argument("--db", default=None, help="SQLAlchemy URL (default: a temporary SQLite file)")
    args = parser.parse_args(argv)
    from pycram.trace import Recorder

    with tempfile.TemporaryDirectory() as folder:
        url = args.db or f"sqlite:///{Path(folder) / 'overhead.sqlite3'}"
        Recorder(url, plan="warm-up").start().finish()  # SQLAlchemy and the driver fully loaded
        gc.collect()
        gc.freeze()  # start-up objects out of the collector's way: a full collection otherwise
        #              takes ~100 ms here and lands in a random iteration of either mode
        print(f"recording into {url}; median of {args.repeat} runs each")
        print(
            f"{'workload':<12} {'median off':>10} {'on [ms]':>8} {'overhead':>9}   "
            f"{'mean off':>8} {'on [ms]':>8} {'overhead':>9}"
        )
        worst = 0.0
        for name, fn in WORKLOADS.items():
            off, on = [], []
            for _ in range(6):  # interleave off/on blocks against drift
                off += _time(fn, args.repeat // 6 or 1)
                recorder = Recorder(url, plan=f"overhead {name}").start()
                on += _time(fn, args.repeat // 6 or 1)
                started = time.perf_counter()
                recorder.finish("succeeded")
                flush = time.perf_counter() - started
            m_off, m_on = statistics.median(off), statistics.median(on)
            a_off, a_on = statistics.mean(off), statistics.mean(on)
            overhead = (m_on - m_off) / m_off
            worst = max(worst, overhead)
            print(
                f"{name:<12} {m_off * 1e3:>10.2f} {m_on * 1e3:>8.2f} {overhead:>+9.1%}   "
                f"{a_off * 1e3:>8.2f} {a_on * 1e3:>8.2f} {(a_on - a_off) / a_off:>+9.1%}"
                f"   (final flush {flush * 1e3:.0f} ms)"
            )
        shutdown_idle_workers()
        print(f"worst median overhead {worst:+.1%} (target: at most +10 %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
