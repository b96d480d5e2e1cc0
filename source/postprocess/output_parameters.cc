// The parameters of what a run writes and checks: output, statistics, verification.
#include <deal.II/base/utilities.h>

#include <suspension/core/parameter_parsing.h>
#include <suspension/core/parameters.h>

namespace Suspension::Parameters
{
  using namespace dealii;
  using namespace Parsing;

  // ------------------------------------------------------------------ Output
  void Output::declare(ParameterHandler &prm)
  {
    const Output d;
    prm.enter_subsection("Output");
    prm.declare_entry("Directory",
                      d.directory,
                      Patterns::DirectoryName(),
                      "Where every output file goes; created if missing.");
    prm.declare_entry("Write phi cells",
                      "false",
                      Patterns::Bool(),
                      "At each output, also write phi_cells_NNNNN.txt: every "
                      "cell's box, level and mean phi (plain text, drawn by "
                      "scripts/plot_cells.py without ParaView).");
    prm.declare_entry("Write vtu",
                      "true",
                      Patterns::Bool(),
                      "Write .pvtu/.vtu fields (velocity, pressure, "
                      "vorticity, rank, level) and a .pvd index.");
    prm.declare_entry("Patch subdivisions",
                      "0",
                      Patterns::Integer(0, 8),
                      "Subdivisions of each cell in the .vtu files (0: the "
                      "velocity degree, so that Q2 and DG 2 fields are drawn "
                      "with their curvature). 1 writes the vertex values only: "
                      "in 3D 8 instead of 27 points per cell, files a quarter "
                      "the size and half the time to write (doc/performance.md).");
    prm.declare_entry("Interval steps",
                      "0",
                      Patterns::Integer(0),
                      "Write fields and probes every this many steps (0: "
                      "off).");
    prm.declare_entry("Interval time",
                      "0",
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Write fields and probes every this much simulated "
                      "time (0: off). Initial and final states are always "
                      "written.");
    prm.declare_entry("Probe points",
                      "",
                      Patterns::Anything(),
                      "Points where velocity and pressure are recorded at "
                      "every output: coordinates separated by ',', points "
                      "by ';'.");
    prm.declare_entry("Progress interval",
                      std::to_string(d.progress_interval),
                      Patterns::Integer(0),
                      "Print one progress line (step, time, dt, ETA) every "
                      "this many steps (0: never).");
    prm.declare_entry("Statistics interval",
                      std::to_string(d.statistics_interval),
                      Patterns::Integer(1),
                      "Add a row to statistics.txt every this many steps "
                      "(and at the first). A row measures the particle's "
                      "shape on sub-cells when the scene has one particle, "
                      "the most expensive diagnostic of a step; the "
                      "largest area error of the run summary is taken over "
                      "these rows. The time averages of 'Statistics' are "
                      "sampled by their own 'Sample interval'.");
    prm.declare_entry("Timer summary",
                      "true",
                      Patterns::Bool(),
                      "Print the TimerOutput summary at the end.");
    prm.declare_entry("Run header",
                      "true",
                      Patterns::Bool(),
                      "Print first the code version and where the parameters "
                      "as used are recorded (parameters_used.prm, written "
                      "either way). Tests switch it off: both lines change "
                      "with the commit and the machine.");
    prm.leave_subsection();
  }

  void Output::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Output");
    directory         = prm.get("Directory");
    write_vtu         = prm.get_bool("Write vtu");
    write_phi_cells   = prm.get_bool("Write phi cells");
    patch_subdivisions = prm.get_integer("Patch subdivisions");
    interval_steps    = prm.get_integer("Interval steps");
    interval_time     = prm.get_double("Interval time");
    progress_interval = prm.get_integer("Progress interval");
    statistics_interval = prm.get_integer("Statistics interval");
    timer_summary     = prm.get_bool("Timer summary");
    run_header        = prm.get_bool("Run header");
    const std::string points = prm.get("Probe points");
    prm.leave_subsection();
    probe_points.clear();
    for (const auto &p : split(points, ';'))
      {
        probe_points.push_back(to_doubles("Output/Probe points", p));
        if (probe_points.back().size() != dim)
          throw InputError("Output/Probe points",
                           "point '" + p + "' does not have " +
                             std::to_string(dim) + " coordinates");
      }
  }

  // -------------------------------------------------------------- Statistics
  void Statistics::declare(ParameterHandler &prm)
  {
    const Statistics d;
    prm.enter_subsection("Statistics");
    prm.declare_entry("Enabled", d.enabled ? "true" : "false", Patterns::Bool(),
                      "Accumulate channel statistics (wall-normal profiles, "
                      "effective viscosity, N1, N2, shear-stress budget) and "
                      "write profiles.txt and rheology.txt to the output "
                      "directory. Channel geometry only.");
    prm.declare_entry("Start time", std::to_string(d.start_time),
                      Patterns::Double(0.),
                      "Samples are taken from this time on (after the "
                      "start-up transient).");
    prm.declare_entry("Sample interval", std::to_string(d.sample_interval),
                      Patterns::Integer(1),
                      "Take a sample every this many time steps.");
    prm.declare_entry("Number of bins", std::to_string(d.n_bins),
                      Patterns::Integer(2),
                      "Wall-normal bins of equal width across the whole "
                      "channel (-h to h); even, so that the two halves fold "
                      "onto each other bin by bin. Best a divisor of the "
                      "number of cells across the channel, so that no cell "
                      "straddles two bins (the run notes it if one does).");
    prm.declare_entry("Steady state window", std::to_string(d.steady_window),
                      Patterns::Double(0.),
                      "0: the flow is taken as statistically steady from "
                      "'Start time' on. > 0: measured instead: from 'Start "
                      "time' on, the samples' effective viscosity and the "
                      "solid's mean distance from the walls are averaged over "
                      "the last two windows of this length (time units); once "
                      "each mean changes by less than 'Steady state "
                      "tolerance' from one window to the next, or by less "
                      "than two standard errors of the difference (the "
                      "windows' own scatter, by blocking), the flow is "
                      "steady, the sums start again from that sample, and the "
                      "run prints the criterion with its result. A run that "
                      "ends before says so and calls its numbers provisional.");
    prm.declare_entry("Steady state tolerance", std::to_string(d.steady_tolerance),
                      Patterns::Double(0.),
                      "Relative change between the two windows' means below "
                      "which the flow counts as steady (see 'Steady state "
                      "window').");
    prm.declare_entry("Sampling time", std::to_string(d.sampling_time),
                      Patterns::Double(0.),
                      "0: sample until 'Time stepping/End time'. > 0: end the "
                      "run once the statistics cover this much steady time "
                      "('End time' stays the limit).");
    prm.leave_subsection();
  }

  void Statistics::parse(ParameterHandler &prm)
  {
    prm.enter_subsection("Statistics");
    enabled         = prm.get_bool("Enabled");
    start_time      = prm.get_double("Start time");
    sample_interval = prm.get_integer("Sample interval");
    n_bins          = prm.get_integer("Number of bins");
    steady_window    = prm.get_double("Steady state window");
    steady_tolerance = prm.get_double("Steady state tolerance");
    sampling_time    = prm.get_double("Sampling time");
    prm.leave_subsection();
    if (enabled && steady_window > 0 && !(steady_tolerance > 0))
      throw InputError("Statistics/Steady state tolerance",
                       "must be positive when 'Steady state window' is set");
    if (enabled && n_bins % 2 != 0)
      throw InputError("Statistics/Number of bins",
                       "must be even, so that the two channel halves fold "
                       "onto each other bin by bin");
  }

  // ------------------------------------------------------------ Verification
  void Verification::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const Verification d;
    prm.enter_subsection("Verification");
    prm.declare_entry("Exact solution",
                      "none",
                      Patterns::Selection("none|function|channel start-up"),
                      "Solution the run is compared with: 'function' takes "
                      "'Exact velocity' and 'Exact pressure'; 'channel "
                      "start-up' is the Fourier-series solution of flow "
                      "from rest under a constant pressure gradient.");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for the exact-solution expressions.");
    prm.declare_entry("Exact velocity",
                      zero_vector(dim),
                      Patterns::Anything(),
                      "Exact velocity, one expression of x, y[, z], t per "
                      "component separated by ';'.");
    prm.declare_entry("Exact solid fraction",
                      "",
                      Patterns::Anything(),
                      "If set, the final phi is compared with this "
                      "expression of x, y[, z] (L1 error), e.g. the initial "
                      "shape after a full revolution.");
    prm.declare_entry("Exact solid at probes",
                      "",
                      Patterns::Anything(),
                      "If set, phi and the entries of B (order: B_11, B_22, "
                      "[B_33,] B_12, [B_13, B_23]) expected at the probe "
                      "points at the end, separated by ';'; the largest "
                      "relative difference is printed and checked against "
                      "'Tolerance'.");
    prm.declare_entry("Exact pressure",
                      "0",
                      Patterns::Anything(),
                      "Exact pressure (compared up to its mean).");
    prm.declare_entry("Report times",
                      "",
                      Patterns::List(Patterns::Double(0.)),
                      "Times at which errors are printed, in addition to "
                      "the end of the run.");
    prm.declare_entry("Reference data",
                      "none",
                      Patterns::Selection("none|Ghia Re100"),
                      "Published data the final state is compared with: "
                      "Ghia, Ghia & Shin (1982) lid-driven cavity centre "
                      "lines at Re = 100 (unit square, lid at y = 1).");
    prm.declare_entry("Tolerance",
                      "0",
                      Patterns::Double(0.),
                      "If positive, the final relative velocity error (and, "
                      "for a channel at constant flow rate, the relative "
                      "deviation of -dp/dx from the laminar 3 mu V_b / h^2) "
                      "is checked against it and the verdict printed.");
    prm.declare_entry("Minimum velocity rate",
                      "0",
                      Patterns::Double(0.),
                      "If positive, a study checks that the velocity L2 "
                      "error falls at least at this rate between its last "
                      "two cycles, and from every cycle to the next (finite), "
                      "and prints the verdict.");
    prm.declare_entry("Minimum pressure rate",
                      "0",
                      Patterns::Double(0.),
                      "The same for the pressure L2 error.");
    prm.declare_entry("Sweep entry",
                      "",
                      Patterns::Anything(),
                      "Run the scene once per value in 'Sweep values' of this "
                      "entry (a path such as 'Solid/Shear modulus') and print "
                      "the single particle's final deformation per value.");
    prm.declare_entry("Sweep values",
                      "",
                      Patterns::Anything(),
                      "Values for 'Sweep entry', separated by ','.");
    prm.declare_entry("Sweep expected deformation",
                      "",
                      Patterns::Anything(),
                      "Expected Taylor deformation D as a function of x, the "
                      "swept value; with 'Tolerance' the relative deviation "
                      "of the last run (the finest, by convention) is "
                      "checked.");
    prm.declare_entry("Sweep agreement",
                      "0",
                      Patterns::Double(0),
                      "If positive: the last run's D must agree with the "
                      "first run's to this relative difference (e.g. an "
                      "adaptive run against a uniform one).");
    prm.declare_entry("Sweep deformation measure",
                      "shape",
                      Patterns::Selection("shape|material"),
                      "The Taylor deformation that 'Tolerance' and 'Steady "
                      "tolerance' judge: shape (the moments of H(phi), the "
                      "particle's outline) or material (the stretch of the "
                      "material, (L - S)/(L + S) with L^2, S^2 the eigenvalues "
                      "of the mean of B where H(phi) = 1; equal to the shape's "
                      "for a uniformly deformed particle that came from a "
                      "circle or sphere).");
    prm.declare_entry("Steady tolerance",
                      "0",
                      Patterns::Double(0),
                      "If positive: the single particle's D (the 'Sweep "
                      "deformation measure') at the end of each run must "
                      "differ from its value at the first 'Report times' entry "
                      "by at most this relative amount.");
    prm.declare_entry("Area tolerance",
                      "0",
                      Patterns::Double(0.),
                      "If positive, with a single particle: the largest "
                      "|area(phi >= 1/2) / int phi(0) - 1| over every step "
                      "of the run (area(phi >= 1/2) as statistics.txt's "
                      "solid_area: on the THINC profile with 'Solid/Shape "
                      "measure = profile') is printed at the end and "
                      "checked against this (verdict printed).");
    prm.declare_entry("Sweep minimum cell reduction",
                      "0",
                      Patterns::Double(0),
                      "If positive: the first run's final cell count over "
                      "the last run's must be at least this.");
    prm.declare_entry("Refinement cycles",
                      "1",
                      Patterns::Integer(1, 8),
                      "Repeat the run this many times, one global "
                      "refinement more each time, and print a convergence "
                      "table.");
    prm.declare_entry("Time step cycles",
                      "1",
                      Patterns::Integer(1, 8),
                      "Repeat the run this many times, halving the time step "
                      "each time, and print a convergence table.");
    prm.leave_subsection();
  }

  void Verification::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Verification");
    const std::string t = prm.get("Exact solution");
    exact_solution = t == "none"     ? ExactSolutionType::none :
                     t == "function" ? ExactSolutionType::function :
                                       ExactSolutionType::channel_startup;
    exact_velocity = {prm.get("Exact velocity"), prm.get("Function constants")};
    exact_pressure = prm.get("Exact pressure");
    exact_fraction = Utilities::trim(prm.get("Exact solid fraction"));
    exact_solid_at_probes = Utilities::trim(prm.get("Exact solid at probes"));
    report_times   = to_doubles("Verification/Report times",
                              prm.get("Report times"));
    reference_data = prm.get("Reference data") == "none" ?
                       ReferenceData::none :
                       ReferenceData::ghia_re100;
    tolerance         = prm.get_double("Tolerance");
    minimum_velocity_rate = prm.get_double("Minimum velocity rate");
    minimum_pressure_rate = prm.get_double("Minimum pressure rate");
    refinement_cycles = prm.get_integer("Refinement cycles");
    sweep_entry       = Utilities::trim(prm.get("Sweep entry"));
    sweep_values      = split(prm.get("Sweep values"), ',');
    sweep_expected_deformation = Utilities::trim(prm.get("Sweep expected deformation"));
    sweep_agreement            = prm.get_double("Sweep agreement");
    sweep_cell_reduction       = prm.get_double("Sweep minimum cell reduction");
    area_tolerance             = prm.get_double("Area tolerance");
    sweep_material_deformation = prm.get("Sweep deformation measure") == "material";
    steady_tolerance           = prm.get_double("Steady tolerance");
    time_step_cycles  = prm.get_integer("Time step cycles");
    prm.leave_subsection();
    if (exact_solution == ExactSolutionType::function)
      {
        check_expression("Verification/Exact velocity", exact_velocity, dim, dim);
        check_expression("Verification/Exact pressure",
                         {exact_pressure, exact_velocity.constants},
                         1,
                         dim);
      }
    if (!exact_solid_at_probes.empty())
      check_expression("Verification/Exact solid at probes",
                       {exact_solid_at_probes, exact_velocity.constants}, 1 + dim * (dim + 1) / 2, dim);
    if (!exact_fraction.empty())
      check_expression("Verification/Exact solid fraction",
                       {exact_fraction, exact_velocity.constants}, 1, dim);
    if (!sweep_entry.empty() && sweep_values.empty())
      throw InputError("Verification/Sweep values", "a sweep needs values");
    if (refinement_cycles > 1 && time_step_cycles > 1)
      throw InputError("Verification/Time step cycles",
                       "a study refines either the mesh or the time step, "
                       "not both");
  }

  // ------------------------------------------------ All: the probes' check
  void All::check_probes(const unsigned int dim) const
  {
    for (const auto &p : output.probe_points)
      for (unsigned int d = 0; d < dim; ++d)
        if (!(p[d] >= geometry.box_lower[d] && p[d] <= geometry.box_upper[d]))
          throw InputError("Output/Probe points",
                           "the point with coordinate " + std::to_string(p[d]) +
                             " in direction " + std::to_string(d + 1) +
                             " lies outside the box");
  }
} // namespace Suspension::Parameters
