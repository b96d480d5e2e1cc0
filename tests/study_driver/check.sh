#!/bin/sh
# The study driver (scripts/study.py) on two tiny cases of the shipped
# study scene (parameters/study_2d_paper.prm at 4 cells per diameter to
# t = 0.3, Re = 7.5, Ca = 0.15, Phi = 0.025 and 0.05, statistics measured
# steady over windows of 0.05 and sampled for 0.05):
# 1. the cases' entries: mu = rho gdot r^2 / Re = 1.5 * 0.01 / 7.5 = 0.002,
#    G = mu gdot / Ca = 0.02, Phi as listed, each in its own directory;
# 2. interrupted: the driver is stopped (SIGTERM, as by a batch system) once the first case has
#    written a checkpoint; run again, it resumes that case from it;
# 3. --max-cases 1 finishes that one case only; run again, it skips it and
#    runs the second; a third run has nothing left to do;
# 4. study.csv holds both cases with the verdict of their stationarity;
# 5. extension: a case that never becomes steady (tolerance 1e-9) stops at
#    End time 0.1 with its last checkpoint; run again with End time 0.15,
#    it goes on from t = 0.1 (not from t = 0), its CPU seconds carried over,
#    and ends at 0.15; a run with End time 0.15 again has nothing to do.
# usage: check.sh SUSPENSION SOURCE_DIRECTORY
exe="$1"; src="$2"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
fail() { echo "FAILED: $*"; exit 1; }
# the shipped study scene on tiny cases (Re = 7.5, Ca = 0.15, level 3);
# always called in a subshell, ( study ... ): exec makes $! the driver itself
driver() {
  exec /usr/bin/python3 "$src/scripts/study.py" "$src/parameters/study_2d_paper.prm" --exe "$exe" \
    --jobs 1 --progress-seconds 1000 \
    --set 'Study/Cases=grid' --set 'Study/Reynolds numbers=7.5' \
    --set 'Study/Capillary numbers=0.15' --set 'Mesh refinement/Maximum level=3' \
    --set 'Output/Interval time=1' --set 'Output/Write phi cells=false' "$@"
}
study() {
  driver --set 'Study/Volume fractions=0.025, 0.05' --set "Study/Directory=study" \
    --set 'Time stepping/End time=0.3' \
    --set 'Statistics/Start time=0.05' --set 'Statistics/Steady state window=0.05' \
    --set 'Statistics/Steady state tolerance=0.05' --set 'Statistics/Sampling time=0.05' \
    --set 'Checkpoint/Interval minutes=0' --set 'Checkpoint/Interval steps=20' "$@"
}
one=study/Re7.5_Ca0.15_Phi0.025; two=study/Re7.5_Ca0.15_Phi0.05

# 2: stop the driver once the first case has a checkpoint
(study) > first.txt 2>&1 &
driver=$!
i=0
while [ ! -d "$one/checkpoint" ] && [ $i -lt 2400 ]; do sleep 0.05; i=$((i + 1)); done
[ -d "$one/checkpoint" ] || fail "no checkpoint of the first case"
kill -TERM $driver; wait $driver
grep -q "study interrupted" first.txt || { cat first.txt; fail "interrupt"; }
echo "interrupted after the first checkpoint of $(basename $one)"

# 1: the entries of the case
for e in "Viscosity *= *0.002 " "Shear modulus *= *0.02 " "Volume fraction *= *0.025 "; do
  grep -q "set $e" "$one/parameters_used.prm" || fail "entry '$e' not in $one/parameters_used.prm"
done
echo "entries of $(basename $one): Viscosity = 0.002, Shear modulus = 0.02, Volume fraction = 0.025"

# 3: resume, one case only, then the rest
(study --max-cases 1) > second.txt 2>&1 || { cat second.txt; fail "second run"; }
grep "^  start\|^  done " second.txt | sed 's/: steady from.*/: steady/; s/: NOT STEADY.*/: NOT STEADY/'
grep -q "resumed from" "$one/run.log" || fail "the first case did not resume from its checkpoint"
echo "$(basename $one) resumed from its checkpoint: yes"
[ -f "$two/case_done.json" ] && fail "--max-cases 1 ran the second case too"
(study) > third.txt 2>&1 || { cat third.txt; fail "third run"; }
grep "^study:\|^  start" third.txt | sed "s|$work/||"
grep -q "^  start Re7.5_Ca0.15_Phi0.025" third.txt && fail "the finished case ran again"
(study) > fourth.txt 2>&1 || { cat fourth.txt; fail "fourth run"; }
grep "study:" fourth.txt
grep -q "^  start" fourth.txt && fail "a finished case ran again"

# 4: the table, also written by --collect without running anything
rm study/study.csv
(study --collect) > collect.txt 2>&1 || { cat collect.txt; fail "--collect"; }
grep -q "^  start" collect.txt && fail "--collect ran a case"
grep "collected" collect.txt
/usr/bin/python3 - study/study.csv <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
print("study.csv:", len(rows), "cases")
for r in rows:
    print(f"  {r['case']}: Re {r['Re']}, Ca {r['Ca']}, Phi {r['Phi']}, steady {int(float(r['steady']))}, "
          f"mu_eff/mu = {float(r['viscosity_ratio']):.3f} +- {float(r['viscosity_ratio_error']):.3f}")
PY
for f in mu_eff.png normal_stresses.png profiles.png budget.png; do
  [ -s study/$f ] || fail "study/$f not written"
done
echo "figures written: yes"

# 5: extending a finished, unsteady case to a later End time
extend() {
  driver --set 'Study/Volume fractions=0.025' --set "Study/Directory=extended" \
    --set 'Statistics/Start time=0.02' --set 'Statistics/Steady state window=0.02' \
    --set 'Statistics/Steady state tolerance=1e-9' --set 'Statistics/Sampling time=0.05' \
    --set 'Checkpoint/Interval minutes=10' "$@"
}
case=extended/Re7.5_Ca0.15_Phi0.025
(extend --set 'Time stepping/End time=0.1') > fifth.txt 2>&1 || { cat fifth.txt; fail "run to 0.1"; }
[ -d "$case/checkpoint" ] || fail "the unsteady case kept no checkpoint at its End time"
t1=$(/usr/bin/python3 -c "import json; print(json.load(open('$case/case_done.json'))['time'])")
cpu1=$(/usr/bin/python3 -c "import json; print(json.load(open('$case/case_done.json'))['cpu_seconds'])")
echo "stopped at t = $t1, NOT STEADY: $(grep -c 'NOT STEADY' $case/case_done.json), checkpoint kept: yes"
(extend --set 'Time stepping/End time=0.15') > sixth.txt 2>&1 || { cat sixth.txt; fail "extension"; }
grep "^  extend" sixth.txt
grep -q "resumed from" "$case/run.log" || fail "the extension did not resume from the checkpoint"
/usr/bin/python3 - "$case/case_done.json" "$case/statistics.txt" "$cpu1" <<'PY' || fail "extension record"
import json, sys
record = json.load(open(sys.argv[1]))
times = [float(l.split()[1]) for l in open(sys.argv[2]) if not l.startswith("#")]
steps = [int(l.split()[0]) for l in open(sys.argv[2]) if not l.startswith("#")]
print(f"extended to t = {record['time']:.2f}; statistics.txt from t = {times[0]:.4f} to "
      f"{times[-1]:.2f}, steps increasing: {'yes' if steps == sorted(set(steps)) else 'no'}; "
      f"CPU carried over: {'yes' if record['cpu_seconds'] > float(sys.argv[3]) else 'no'}")
sys.exit(0 if abs(record["time"] - 0.15) < 1e-3 and steps == sorted(set(steps))
         and record["cpu_seconds"] > float(sys.argv[3]) else 1)
PY
(extend --set 'Time stepping/End time=0.15') > seventh.txt 2>&1 || { cat seventh.txt; fail "seventh run"; }
grep -q "^  start\|^  extend" seventh.txt && fail "a finished case ran again"
grep "study:" seventh.txt | tail -1

