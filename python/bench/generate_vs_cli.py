"""Samples per second of tactex.generate against `tactex datagen tactile` on this machine.

    python python/bench/generate_vs_cli.py --count 64 --reps 5 [--bin target/release/tactex]

Alternates the two, each rep on a fresh seed, and prints the medians and their ratio as a
markdown table (with --out FILE, also written there, headed by the command). Run it on a
release build of both (`cargo build --release`, `pip install ./python`).
"""

import argparse
import datetime
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import tactex

ROOT = Path(__file__).resolve().parents[2]


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--count", type=int, default=64)
    p.add_argument("--reps", type=int, default=5)
    p.add_argument("--bin", default=str(ROOT / "target/release/tactex"))
    p.add_argument("--format", default="npz", choices=["npz", "png"])
    p.add_argument("--out", type=Path)
    a = p.parse_args()
    cli_s, py_s = [], []
    for rep in range(a.reps):
        seed = 1000 + rep
        tmp = Path(tempfile.mkdtemp())
        t = time.perf_counter()
        subprocess.run(
            [a.bin, "datagen", "tactile", "--count", str(a.count), "--seed", str(seed),
             "--format", a.format, "--out", str(tmp / "set")],
            check=True, capture_output=True,
        )
        cli_s.append(time.perf_counter() - t)
        shutil.rmtree(tmp)
        t = time.perf_counter()
        n = sum(1 for _ in tactex.generate(a.count, seed))
        py_s.append(time.perf_counter() - t)
        assert n == a.count
        print(f"rep {rep}: cli {a.count / cli_s[-1]:.2f}/s, python {a.count / py_s[-1]:.2f}/s", file=sys.stderr)
    cli, py = statistics.median(cli_s), statistics.median(py_s)
    table = (
        f"{a.count} default `layer` press sequences (all shape families, the stock Mini), "
        f"{a.reps} alternating reps, {os.cpu_count()} cores; medians.\n\n"
        "| path | s per run | sequences/s |\n|---|---:|---:|\n"
        f"| `tactex datagen tactile --format {a.format}` | {cli:.2f} | {a.count / cli:.2f} |\n"
        f"| `tactex.generate` (in memory) | {py:.2f} | {a.count / py:.2f} |\n\n"
        f"tactex.generate takes {100 * (py / cli - 1):+.1f}% the CLI's time.\n"
    )
    print(table)
    if a.out:
        head = (
            f"_Made on {datetime.date.today()} by `python python/bench/generate_vs_cli.py "
            f"{' '.join(sys.argv[1:])}`._\n\n"
        )
        a.out.parent.mkdir(parents=True, exist_ok=True)
        a.out.write_text(head + table)


if __name__ == "__main__":
    main()
