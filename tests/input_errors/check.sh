#!/bin/sh
# Bad input must give exactly one line on stderr that names the file and the
# offending entry, a non-zero exit code, and no output files.
# usage: check.sh SUSPENSION_EXECUTABLE THIS_DIRECTORY
exe="$1"; dir="$2"
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
cd "$work" || exit 1
failures=0

# expect NAME ARGS... -- PATTERN...: run, then check every pattern in stderr
expect() {
  name="$1"; shift
  args=""
  while [ "$1" != "--" ]; do args="$args $1"; shift; done; shift
  "$exe" $args > stdout 2> stderr
  code=$?
  lines=$(wc -l < stderr)
  ok=yes
  [ "$code" -ne 0 ] || { echo "$name: exit code 0"; ok=no; }
  [ "$lines" -eq 1 ] || { echo "$name: $lines lines on stderr, expected 1"; ok=no; }
  for pattern in "$@"; do
    grep -q -- "$pattern" stderr || { echo "$name: stderr lacks '$pattern'"; ok=no; }
  done
  [ ! -e should_not_exist ] || { echo "$name: output directory was created"; ok=no; }
  echo "$name: $(cat stderr)"
  [ $ok = yes ] || failures=$((failures + 1))
}

expect unknown_entry      "$dir/unknown_entry.prm"     -- "unknown_entry.prm" "Viscosityy"
expect out_of_range       "$dir/out_of_range.prm"      -- "out_of_range.prm" "Viscosity" "-1"
expect bad_expression     "$dir/bad_expression.prm"    -- "bad_expression.prm" "Initial conditions/Velocity"
expect unpaired_periodic  "$dir/unpaired_periodic.prm" -- "unpaired_periodic.prm" "Face x-/Type" "pairs"
expect bad_dimension      "$dir/bad_dimension.prm"     -- "bad_dimension.prm" "Dimension"
expect missing_file       "$dir/no_such_file.prm"      -- "no_such_file.prm" "cannot read"
expect too_dense          "$dir/too_dense.prm"         -- "too_dense.prm" "Solid/Seeding/Volume fraction" "could place only"
expect statistics_box     "$dir/statistics_not_channel.prm" -- "statistics_not_channel.prm" "Statistics/Enabled" "channel"
expect no_checkpoint       "$dir/../checkpoint_restart/scene.prm" --resume -- "no checkpoint" "output_files/checkpoint"
expect bad_option         "$dir/../checkpoint_restart/scene.prm" --resum -- "unknown or incomplete option" "--resum"
expect no_argument                                     -- "no parameter file"
expect empty_file         "$dir/empty.prm"             -- "empty.prm" "sets no entry"
expect particle_outside   "$dir/particle_outside.prm"  -- "particle_outside.prm" "Solid/Particles" "5, 0, 0.1" "outside the box"
expect particle_too_large "$dir/particle_too_large.prm" -- "particle_too_large.prm" "Solid/Particles" "does not fit between the walls"
expect particles_overlap  "$dir/particles_overlap.prm" -- "particles_overlap.prm" "Solid/Particles" "overlap"
expect probe_outside      "$dir/probe_outside.prm"     -- "probe_outside.prm" "Output/Probe points" "outside the box"

echo "$failures failure(s)"
[ "$failures" -eq 0 ]
