"""What the view costs a run: wall time of `pycram demo` (the thesis demo, and a set-table run)
without a view, with `--rrd` (the recording saved as a file) and with `--view --rrd` (the web
viewer served and streamed into as well), each a whole command in a fresh process.

    MUJOCO_GL=egl .venv/bin/python benchmarks/view.py [--repeat 3] [--skip-set-table]

The variants alternate (A B C A B C ...) so that a change in the machine's load hits them alike;
the medians are printed with each variant's cost relative to no view: of the run itself (the
wall time the demo reports for its run: the speed of the run) and of the whole command (which
also starts Python, imports Rerun -- about 0.5 s -- and writes the trace's pictures). The target of issue 35:
viewing costs a run at most 15 % of its speed. Every run is lock-step, recorded into a temporary
trace database, without the animation (run.gif); the thesis demo with a theft (seed 3), the
set-table run PR2 seed 7. The pictures (start/end.png) are written in every variant.

Numbers depend on the machine's load; run it on an otherwise idle machine for the record.

Measured (idle 2-core machine, load 0.5-1.2, 2026-11-27, the view's writer in its own process):
thesis demo run +11.0 % (--rrd) / +7.6 % (--view --rrd), median of 9, whole command +16.6 % /
+16.3 % (the writer process's and Rerun's start-up); set-table run +4.9 % / +7.1 %, whole command
+6.8 % / +9.8 % (median of 2). With the writer in a thread (before) the thesis run paid +10 to
+18 %. docs/view.md ("What it costs") has the table.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
VARIANTS = {
    "no view": ["--no-rrd"],
    "--rrd": ["--rrd"],
    "--view --rrd": ["--rrd", "--view", "--view-port", "0", "--no-view-wait"],
}
RUNS = {
    "thesis demo (theft, seed 3)": ["--steal", "1", "--seed", "3"],
    "set-table (PR2, seed 7)": ["--scenario", "set-table", "--seed", "7"],
}


_RUN_WALL = re.compile(r"in ([0-9.]+) s of wall time|the whole run took ([0-9.]+) s of wall time")


def _time(args: list[str], folder: Path) -> tuple[float, float]:
    """Wall time [s] of `pycram demo ARGS` in a fresh process, and of the run itself as the demo
    reports it (the plan's wall time for the thesis demo, the whole run's for set-table: without
    starting Python, importing and writing the trace's pictures); raises if the run failed."""
    env = dict(os.environ, MUJOCO_GL=os.environ.get("MUJOCO_GL", "egl"), PYTHONPATH=str(ROOT))
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, "-m", "pycram.apps.cli", "demo", *args],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
    )
    elapsed = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"pycram demo {' '.join(args)} failed ({done.returncode}): {done.stderr[-1500:]}")
    found = _RUN_WALL.search(" ".join(done.stdout.split()))
    if found is None:
        raise RuntimeError(f"pycram demo {' '.join(args)} did not say its wall time: {done.stdout[-800:]}")
    return elapsed, float(found.group(1) or found.group(2))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs of each variant (default 3)")
    parser.add_argument("--skip-set-table", action="store_true", help="only the thesis demo")
    options = parser.parse_args()
    runs = dict(RUNS)
    if options.skip_set_table:
        runs.pop("set-table (PR2, seed 7)")
    with tempfile.TemporaryDirectory(prefix="pycram-view-bench-") as tmp:
        folder = Path(tmp)
        db = f"sqlite:///{folder / 'runs.sqlite3'}"
        for title, run in runs.items():
            times: dict[str, list[float]] = {name: [] for name in VARIANTS}
            runs_: dict[str, list[float]] = {name: [] for name in VARIANTS}
            for i in range(options.repeat):
                for name, variant in VARIANTS.items():
                    out = folder / f"out-{len(times[name])}-{name.replace(' ', '').replace('-', '')}-{i}"
                    args = [*run, "--db", db, "--no-animation", "-q", "-o", str(out), *variant]
                    command, itself = _time(args, folder)
                    times[name].append(command)
                    runs_[name].append(itself)
            for what, table in (("the run itself", runs_), ("the whole command", times)):
                base = statistics.median(table["no view"])
                print(f"{title}: wall time of {what}, median of {options.repeat}")
                for name, values in table.items():
                    median = statistics.median(values)
                    cost = 100.0 * (median - base) / base
                    shown = ", ".join(f"{v:.1f}" for v in values)
                    print(f"  {name:<14} {median:6.1f} s  ({cost:+5.1f} %)   runs: {shown}")


if __name__ == "__main__":
    main()
