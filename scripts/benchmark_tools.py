"""What every benchmark script shares: Debian's matplotlib, the executable,
the number of runs at a time, the scratch directory and the CSV files.

    sys.path.insert(0, os.path.join(REPO, "scripts"))
    from benchmark_tools import plt, SUSPENSION, PARALLEL, work_directory
"""

import csv
import os
import sys

try:
    import matplotlib
except ImportError:  # Debian's matplotlib lives in /usr/bin/python3
    if os.path.realpath(sys.executable) != "/usr/bin/python3" and os.path.exists("/usr/bin/python3"):
        os.execv("/usr/bin/python3", ["/usr/bin/python3"] + sys.argv)
    raise
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402,F401

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
# the executable: $SUSPENSION (the test suite sets it), else the build's
SUSPENSION = os.environ.get("SUSPENSION", os.path.join(REPO, "build", "suspension"))
# runs at a time: $JOBS, else one per core (each run is one MPI rank)
PARALLEL = int(os.environ.get("JOBS", os.cpu_count() or 1))


def work_directory(here, quick):
    """$BENCHMARK_WORK (the test suite points it into the build tree), else
    work/ or, for --quick, work_quick/ next to the script."""
    return os.environ.get("BENCHMARK_WORK", os.path.join(here, "work_quick" if quick else "work"))


def write_csv(rows, path, fields=None):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields or list(rows[0].keys()), extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
