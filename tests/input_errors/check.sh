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
  rm -rf should_not_exist # a failed case does not fail the next ones
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
# a checkpoint of an older format (before the reports saved their own parts)
mkdir -p output_files/checkpoint
echo "suspension-checkpoint 1 2D 1 8_coarse_cells FESystem[FE_Q<2>(2)^2] FE_Q<2>(1) no_solid" \
  > output_files/checkpoint/state.txt
expect old_checkpoint     "$dir/../checkpoint_restart/scene.prm" --resume -- "not a checkpoint of this version" "format 2" "rerun the case"
rm -rf output_files
expect bad_option         "$dir/../checkpoint_restart/scene.prm" --resum -- "unknown or incomplete option" "--resum"
expect no_argument                                     -- "no parameter file"
expect empty_file         "$dir/empty.prm"             -- "empty.prm" "sets no entry"
expect particle_outside   "$dir/particle_outside.prm"  -- "particle_outside.prm" "Solid/Particles" "5, 0, 0.1" "outside the box"
expect particle_too_large "$dir/particle_too_large.prm" -- "particle_too_large.prm" "Solid/Particles" "does not fit between the walls"
expect particles_overlap  "$dir/particles_overlap.prm" -- "particles_overlap.prm" "Solid/Particles" "overlap"
expect probe_outside      "$dir/probe_outside.prm"     -- "probe_outside.prm" "Output/Probe points" "outside the box"

expect zero_time_step     "$dir/zero_time_step.prm"    -- "zero_time_step.prm" "Time step"
expect negative_end_time  "$dir/negative_end_time.prm" -- "negative_end_time.prm" "End time"
expect unknown_geometry   "$dir/unknown_geometry.prm"  -- "unknown_geometry.prm" "Type" "cylinder"
expect particle_no_radius "$dir/particle_no_radius.prm" -- "particle_no_radius.prm" "Solid/Particles"
expect subdivisions_count "$dir/subdivisions_count.prm" -- "subdivisions_count.prm" "Subdivisions" "2, 2, 2"
expect periodic_on_wall   "$dir/periodic_on_wall.prm"  -- "periodic_on_wall.prm" "Face y-/Type"
expect degree_zero        "$dir/degree_zero.prm"       -- "degree_zero.prm" "Velocity degree"
expect cfl_out_of_range   "$dir/cfl_out_of_range.prm"  -- "cfl_out_of_range.prm" "CFL number" "0"
expect statistics_bins_zero "$dir/statistics_bins_zero.prm" -- "statistics_bins_zero.prm" "Number of bins"
expect checkpoint_interval_negative "$dir/checkpoint_interval_negative.prm" -- "checkpoint_interval_negative.prm" "Interval steps"
expect negative_radius    "$dir/negative_radius.prm"   -- "negative_radius.prm" "Solid/Particles"
expect zero_density       "$dir/zero_density.prm"      -- "zero_density.prm" "Density"
expect box_inverted       "$dir/box_inverted.prm"      -- "box_inverted.prm" "Box upper corner"
expect probe_one_coordinate "$dir/probe_one_coordinate.prm" -- "probe_one_coordinate.prm" "Output/Probe points"
expect convection_assembled "$dir/convection_assembled.prm" -- "convection_assembled.prm" "Fluid solver/Convection" "matrix-free"
expect convection_elastic_si "$dir/convection_elastic_semi_implicit.prm" -- "convection_elastic_semi_implicit.prm" "Fluid solver/Convection" "Elastic coupling"
expect rk2_with_dg2       "$dir/rk2_with_dg2.prm"      -- "rk2_with_dg2.prm" "Solid/Time integrator" "DG 2"
expect rk32_with_dg2      "$dir/rk32_with_dg2.prm"     -- "rk32_with_dg2.prm" "Solid/Time integrator" "SSP-RK(3,2)" "DG 2"
expect levels_inverted    "$dir/levels_inverted.prm"   -- "levels_inverted.prm" "level"
expect sweep_unknown_entry "$dir/sweep_unknown_entry.prm" -- "sweep_unknown_entry.prm" "Viscosityy"
expect bad_boundary_velocity "$dir/bad_boundary_velocity.prm" -- "bad_boundary_velocity.prm" "Face y+/Velocity"
touch a_file # a regular file where the output directory should go
expect output_directory_is_file "$dir/output_directory_is_file.prm" -- "output_directory_is_file.prm" "Output/Directory" "a_file/output"
rm a_file
expect set_unknown_entry  "$dir/valid.prm" --set Material/Viscosityy=1 -- "Material/Viscosityy"
expect set_out_of_range   "$dir/valid.prm" --set Material/Density=-2 -- "Material/Density" "-2"
expect set_no_value       "$dir/valid.prm" --set Material/Viscosity -- "Material/Viscosity" "Section/Entry=value"
expect too_much_memory    "$dir/too_much_memory.prm" -- "too_much_memory.prm" "Mesh/Global refinements" "1.07e+09 cells" "kB per cell" "available" "more nodes"
expect set_dimension      "$dir/valid.prm" --set Dimension=4 -- "Dimension" "4"
expect directory_as_file  "$dir"                       -- "input_errors" "is a directory"
# a study of a scene that is not a seeded channel suspension, or without cases
expect study_not_channel  "$dir/valid.prm" --list-cases -- "valid.prm" "Geometry/Type" "channel"
expect study_no_reynolds  "$dir/../../parameters/study_2d_paper.prm" --list-cases --set Study/Cases=grid -- "study_2d_paper.prm" "Study/Reynolds numbers" "no Reynolds number"
expect study_bad_cases    "$dir/../../parameters/study_2d_paper.prm" --list-cases --set Study/Cases=papers -- "Study/Cases" "papers"
expect smoothed_normal    "$dir/smoothed_normal_plane.prm" -- "smoothed_normal_plane.prm" "Solid/THINC normal" "THINC curvature"

echo "$failures failure(s)"
[ "$failures" -eq 0 ]
