#!/bin/sh
# Crash test: a run killed with SIGKILL, twice, and resumed each time must end
# as the uninterrupted run. The first kill waits for a checkpoint after the
# first to be in the making (checkpoint.tmp/ present: Triangulation::save()
# or state.txt being written), so it hits a checkpoint write; the second
# comes at a moment drawn from [0.5, 3] s after the resume started (any
# phase of the time loop). Compared as in check.sh: the final summary, the
# channel statistics, the probes and the .pvd index (numdiff, absolute
# 1e-10, relative 1e-8).
# usage: kill.sh SUSPENSION THIS_DIRECTORY
exe="$1"; dir="$2"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
fail() { echo "FAILED: $*"; exit 1; }
every="Checkpoint/Interval steps=2" # passed as --set "$every"

mkdir whole killed
(cd whole && "$exe" "$dir/scene.prm" > screen.txt 2>&1) || { cat whole/screen.txt; fail "uninterrupted run"; }

cd killed || exit 1
"$exe" "$dir/scene.prm" --set "$every" > first.txt 2>&1 &
pid=$!
# a complete checkpoint first, then the next one while it is written
while [ ! -f output_files/checkpoint/state.txt ]; do sleep 0.05; kill -0 $pid 2> /dev/null || fail "run ended before a checkpoint"; done
while [ ! -d output_files/checkpoint.tmp ]; do kill -0 $pid 2> /dev/null || fail "run ended before a second checkpoint"; done
kill -KILL $pid; wait $pid 2> /dev/null
echo "killed while checkpoint.tmp/ held: $(ls output_files/checkpoint.tmp 2> /dev/null | tr '\n' ' ')"

"$exe" "$dir/scene.prm" --resume --set "$every" > second.txt 2>&1 &
pid=$!
delay=$(awk 'BEGIN { srand(); printf "%.2f", 0.5 + 2.5 * rand() }')
sleep "$delay"
if kill -KILL $pid 2> /dev/null; then echo "killed $delay s after the first resume"; else echo "the first resume ended before $delay s"; fi
wait $pid 2> /dev/null
grep "resumed from" second.txt | sed "s|$work/||"

"$exe" "$dir/scene.prm" --resume --set "$every" > screen.txt 2>&1 || { cat screen.txt; fail "last resume"; }
grep "resumed from" screen.txt | sed "s|$work/||"
cd ..

for d in whole killed; do sed -n '/final state/,$p' $d/screen.txt > $d/summary.txt; done
[ "$(wc -l < whole/summary.txt)" -gt 3 ] || fail "no final summary"
failures=0
compare() { # NAME FILE_WHOLE FILE_KILLED
  if numdiff -q -s ' \t\n,;()[]' -a 1e-10 -r 1e-8 "$2" "$3" > /dev/null; then
    echo "$1: same ($(wc -l < "$2") lines)"
  else
    echo "$1: DIFFERENT"; numdiff -s ' \t\n,;()[]' -a 1e-10 -r 1e-8 "$2" "$3" | head -20
    failures=$((failures + 1))
  fi
}
compare "final summary" whole/summary.txt killed/summary.txt
for d in whole killed; do grep -v "^<!--\\|^#This file" $d/output_files/solution.pvd > $d/solution.pvd; done
compare solution.pvd whole/solution.pvd killed/solution.pvd
for f in rheology.txt profiles.txt probes.txt; do
  compare $f whole/output_files/$f killed/output_files/$f
done
echo "$failures difference(s)"
[ "$failures" -eq 0 ]
