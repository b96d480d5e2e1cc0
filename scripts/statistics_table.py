"""Reads the text tables the solver writes (statistics.txt, probes.txt):
'# N: name' header lines, then one row of numbers per line."""


def read_table(path):
    """Columns by name: {name: [values...]}."""
    names, rows = [], []
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                names.append(line.split(":", 1)[1].strip())
            elif line.strip():
                rows.append([float(v) for v in line.split()])
    return {n: [r[i] for r in rows] for i, n in enumerate(names)}
