#!/usr/bin/python3
"""Distance of a centroid path (x_c, y_c of statistics.txt) from a reference
polyline (CSV of x, y; '#' comments), e.g. Sugiyama et al. 2011's elastic
disc in the lid-driven cavity.

usage: scripts/path_distance.py STATS REFERENCE.csv [--until T]
Prints the mean and the largest distance of the path's points from the
reference curve (the nearest point on any of its segments).
"""
import argparse
import math

from statistics_table import read_table


def distance_to_polyline(x, y, line):
    best = math.inf
    for (x0, y0), (x1, y1) in zip(line[:-1], line[1:]):
        dx, dy = x1 - x0, y1 - y0
        length2 = dx * dx + dy * dy
        t = 0. if length2 == 0. else max(0., min(1., ((x - x0) * dx + (y - y0) * dy) / length2))
        best = min(best, math.hypot(x - x0 - t * dx, y - y0 - t * dy))
    return best


p = argparse.ArgumentParser()
p.add_argument("statistics")
p.add_argument("reference")
p.add_argument("--until", type=float, default=math.inf)
a = p.parse_args()
table = read_table(a.statistics)
line = [tuple(float(v) for v in row.split(","))
        for row in open(a.reference) if row.strip() and not row.startswith("#")]
d = [distance_to_polyline(x, y, line)
     for t, x, y in zip(table["time"], table["x_c"], table["y_c"]) if t <= a.until]
print(f"{len(d)} points to t = {min(a.until, max(table['time'])):g}: "
      f"mean distance {sum(d) / len(d):.4f}, max {max(d):.4f}")
