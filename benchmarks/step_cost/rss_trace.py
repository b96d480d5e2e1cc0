#!/usr/bin/env python3
"""Resident memory of a run over time: where its peak happens.

    python3 benchmarks/step_cost/rss_trace.py TRACE.log build/suspension FILE.prm [--set ...]

runs the command, samples VmRSS every 0.1 s and writes to TRACE.log a line
"seconds RSS MB" whenever it rose by 20 MB or fell by 200 MB, interleaved
with the run's output lines (as the pipe delivers them).
"""
import subprocess, sys, time, threading, os
out = open(sys.argv[1], "w")
p = subprocess.Popen(sys.argv[2:], stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
t0 = time.time()
def reader():
    for line in p.stdout:
        out.write("%8.2f LOG %s" % (time.time() - t0, line)); out.flush()
threading.Thread(target=reader, daemon=True).start()
peak = 0
while p.poll() is None:
    try:
        for l in open("/proc/%d/status" % p.pid):
            if l.startswith("VmRSS"):
                rss = int(l.split()[1]) // 1024
        if rss > peak + 20 or rss < peak - 200:
            out.write("%8.2f RSS %d MB\n" % (time.time() - t0, rss)); out.flush()
            peak = max(peak, rss) if rss > peak else rss
    except Exception:
        pass
    time.sleep(0.1)
time.sleep(0.5)
out.write("exit %d\n" % p.returncode)
