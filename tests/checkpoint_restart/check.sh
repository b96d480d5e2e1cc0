#!/bin/sh
# Checkpoint and restart: a run stopped after M steps (a crash) and resumed
# from its checkpoint at step K must end as the uninterrupted run: the final
# screen summary, statistics.txt, the channel statistics, the probes and the
# .pvd index, compared with numdiff (absolute 1e-10, relative 1e-8).
# Not to the last bit: the resumed mesh is rebuilt from the coarse one, so
# its cells and DoFs are numbered differently and sums and AMG solves round
# differently (the scene solves to 1e-12 to keep that below the tolerance);
# for the same reason the linear iteration counts (its_*) may differ by one
# and are left out, as are the wall times.
# usage: check.sh SUSPENSION MPIEXEC THIS_DIRECTORY [RANKS [RESUME_RANKS]]
# SET='Section/Entry=value' in the environment changes one entry of the
# scene in all three runs.
exe="$1"; mpiexec="$2"; dir="$3"; ranks="${4:-1}"; resume_ranks="${5:-$ranks}"
K=${K:-12}; M=${M:-20} # checkpoint every K steps, stop after M
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1

run() { # RANKS ARGS...
  n="$1"; shift
  if [ "$n" -eq 1 ]; then "$exe" "$@"; else "$mpiexec" -n "$n" "$exe" "$@"; fi
}
fail() { echo "FAILED: $*"; exit 1; }

mkdir whole resumed
(cd whole && run "$ranks" "$dir/scene.prm" ${SET:+--set "$SET"} > screen.txt 2>&1) ||
  { cat whole/screen.txt; fail "uninterrupted run"; }
(cd resumed && run "$ranks" "$dir/scene.prm" ${SET:+--set "$SET"} --set "Checkpoint/Interval steps=$K" \
   --set "Time stepping/Maximum number of steps=$M" > stopped.txt 2>&1) ||
  { cat resumed/stopped.txt; fail "run stopped after $M steps"; }
grep "checkpoint at step" resumed/stopped.txt
(cd resumed && run "$resume_ranks" "$dir/scene.prm" ${SET:+--set "$SET"} --resume > screen.txt 2>&1) ||
  { cat resumed/screen.txt; fail "resumed run"; }
grep "resumed from" resumed/screen.txt | sed "s|$work/||"

# the screen from the final summary on
for d in whole resumed; do sed -n '/final state/,$p' $d/screen.txt > $d/summary.txt; done
# statistics.txt without the columns of wall times, iteration counts and the
# number of limited cells (integers that flip where a value sits within
# round-off of a bound: the DoF order after a load changes sums in the last
# bit; every real-valued column is compared to 1e-8)
for d in whole resumed; do
  awk '/^# [0-9]+: (wall_time|its_|limited_cells)/ { split($2, n, ":"); drop[n[1]] = 1; next }
       /^#/ { print; next }
       { line = ""; for (i = 1; i <= NF; ++i) if (!(i in drop)) line = line " " $i; print line }' \
    $d/output_files/statistics.txt > $d/statistics.txt
done

failures=0
compare() { # NAME FILE_WHOLE FILE_RESUMED
  if numdiff -q -s ' \t\n,;()[]' -a 1e-10 -r 1e-8 "$2" "$3" > /dev/null; then
    echo "$1: same ($(wc -l < "$2") lines)"
  else
    echo "$1: DIFFERENT"; numdiff -s ' \t\n,;()[]' -a 1e-10 -r 1e-8 "$2" "$3" | head -20
    failures=$((failures + 1))
  fi
}
compare "final summary" whole/summary.txt resumed/summary.txt
compare statistics.txt whole/statistics.txt resumed/statistics.txt
grep -v "^<!--\\|^#This file" whole/output_files/solution.pvd > whole/solution.pvd
grep -v "^<!--\\|^#This file" resumed/output_files/solution.pvd > resumed/solution.pvd
compare solution.pvd whole/solution.pvd resumed/solution.pvd
for f in rheology.txt profiles.txt probes.txt; do
  compare $f whole/output_files/$f resumed/output_files/$f
done
[ "$(wc -l < whole/summary.txt)" -gt 3 ] || fail "no final summary"
cmp -s whole/statistics.txt resumed/statistics.txt && echo "statistics.txt: identical to the last digit"
echo "$failures difference(s)"
[ "$failures" -eq 0 ]
