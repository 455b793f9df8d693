"""Results-table costs: appends per second at a given table length, memory to load a table.

    PYTHONPATH=. python benchmarks/bench_tables.py [--rows 20000,200000] [--appends 200]

For each length, a synthetic ``results.csv`` with the package's columns (the default parameter
set, distinct run ids and moduli) is written to a temporary folder, then:

* ``append rows/s``: ``append_row`` of one row, repeated (the sweep's path: the table is checked
  once when the sweep opens it, then every finished run appends its row);
* ``load_results RSS``: the peak resident memory a fresh process adds while ``load_results``
  reads the table (pandas DataFrame when pandas is installed), with the CSV's size for scale;
* ``read_sweep_table RSS``: the same for the reader ``analyse`` and ``plot`` use.

Only the standard library and the package are needed; the memory figures use ``resource``
(Linux/macOS).  The script runs against whichever particleShear is on ``PYTHONPATH``, so the same
script measures the code before and after a change.
"""
import argparse
import inspect
import json
import os
import subprocess
import sys
import tempfile
import time


def make_table(path, n):
    """Write ``n`` rows with the package's columns; the file's size in bytes."""
    from particleShear.sweep.table import row_line, table_columns
    cols = table_columns()
    from particleShear.sweep.spec import sweep_parameter_defaults
    base = dict(sweep_parameter_defaults())
    base.update(status="ok", error="", Gp_surface=1.0, Gpp_surface=1.0, Gp_internal=1.0, Gpp_internal=1.0,
                repetition=0, frequency_Hz=1.0, omega=6.283185307179586, dt=1e-5, N_steps=1000,
                seed_entropy=12345678901234567890, package_version="bench", wall_time_s=1.0, output_path="")
    with open(path, "w", encoding="utf-8", newline="") as fh:
        fh.write(row_line({c: c for c in cols}, cols))
        for i in range(n):
            row = dict(base, run_id=f"{i:012x}", spawn_key=[i], Gp_surface=1000.0 + i * 1e-3,
                       Gpp_surface=100.0 + i * 1e-4, wall_time_s=1.0 + i * 1e-6, theMu=0.01 * (1 + i % 5),
                       theAmplitude=0.05 * (1 + i % 7))
            fh.write(row_line(row, cols))
    return os.path.getsize(path), cols, base


def time_appends(path, cols, base, count):
    """Rows per second of ``append_row`` on the table at ``path`` (``count`` appends)."""
    from particleShear.sweep.table import append_row, check_table
    check_table(path, cols)
    kw = {"checked": True} if "checked" in inspect.signature(append_row).parameters else {}
    t0 = time.perf_counter()
    for k in range(count):
        append_row(path, dict(base, run_id=f"a{k:011x}", spawn_key=[10 ** 7 + k]), cols, **kw)
    dt = time.perf_counter() - t0
    return count / dt, dt / count


_CHILD = r"""
import json, resource, sys, warnings
warnings.simplefilter("ignore")
what, path = sys.argv[1], sys.argv[2]
import numpy, particleShear.sweep.schema, particleShear.plot
try:
    import pandas
except ImportError:
    pass
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
if what == "load_results":
    from particleShear.sweep.schema import load_results
    t = load_results(path)
else:
    from particleShear.plot import read_sweep_table
    t = read_sweep_table(path)
    kept = [r.get("theMu") for r in t]                  # touch every row as analyse does
after = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print(json.dumps({"rows": len(t), "rss_kb": after - before}))
"""


def load_rss(path, what):
    """Peak RSS (MB) a fresh process adds while reading the table, and the seconds it takes."""
    t0 = time.perf_counter()
    out = subprocess.run([sys.executable, "-c", _CHILD, what, path], capture_output=True, text=True, check=True,
                         env=dict(os.environ))
    dt = time.perf_counter() - t0
    got = json.loads(out.stdout.strip().splitlines()[-1])
    scale = 1024 if sys.platform != "darwin" else 1024 * 1024
    return got["rss_kb"] / scale, dt, got["rows"]


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rows", default="20000,200000", help="table lengths, comma-separated")
    p.add_argument("--appends", type=int, default=200, help="appends timed per length")
    a = p.parse_args(argv)
    import particleShear
    print(f"particleShear from {os.path.dirname(particleShear.__file__)}")
    with tempfile.TemporaryDirectory() as d:
        for n in [int(x) for x in a.rows.split(",")]:
            path = os.path.join(d, f"results-{n}.csv")
            size, cols, base = make_table(path, n)
            rss, secs, rows = load_rss(path, "load_results")
            rss2, secs2, _ = load_rss(path, "read_sweep_table")
            rate, per = time_appends(path, cols, base, a.appends)
            print(f"{n:>8} rows, {len(cols)} columns, CSV {size / 2 ** 20:7.1f} MB | append {rate:9.1f} rows/s "
                  f"({per * 1e3:7.3f} ms/row) | load_results +{rss:7.1f} MB RSS ({rss / (size / 2 ** 20):4.1f}x CSV, "
                  f"{secs:5.1f} s, {rows} rows) | read_sweep_table +{rss2:7.1f} MB RSS ({secs2:5.1f} s)", flush=True)


if __name__ == "__main__":
    main()
