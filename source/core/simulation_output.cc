// Simulation: what a run writes and prints (fields, probes, statistics.txt,
// progress, errors and verdicts, the end-of-run summary).
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/solver_control.h>

#include <suspension/core/memory.h>
#include <suspension/core/simulation.h>
#include <suspension/fluid/body_force.h>
#include <suspension/mesh/resolution_check.h>
#include <suspension/postprocess/cell_means.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

namespace Suspension
{
  namespace
  {
    std::string format_duration(const double seconds)
    {
      const long s = std::lround(std::max(0., seconds));
      std::ostringstream out;
      out << s / 3600 << "h" << std::setw(2) << std::setfill('0') << (s / 60) % 60 << "m"
          << std::setw(2) << s % 60 << "s";
      return out.str();
    }
  } // namespace

  template <int dim>
  bool Simulation<dim>::output_due(const double time, const double dt) const
  {
    const auto &o = parameters.output;
    if (o.interval_steps > 0 && fluid.step_number() % o.interval_steps == 0)
      return true;
    if (o.interval_time > 0 && time >= last_output_time + o.interval_time - 1e-9 * dt)
      return true;
    return false;
  }

  template <int dim>
  void Simulation<dim>::write_output()
  {
    TimerOutput::Scope scope(timer, "output");
    last_output_time = fluid.time();
    if (parameters.output.write_vtu)
      {
        std::vector<Postprocess::ExtraField<dim>> extra;
        if (solid)
          extra.push_back({&solid->get_dof_handler(), &solid->get_solution(),
                           solid->component_names()});
        field_output.write(space, fluid.velocity(), fluid.kinematic_pressure(),
                           parameters.material.density, fluid.time(), extra);
      }
    if (solid && parameters.output.write_phi_cells)
      {
        std::ostringstream name;
        name << parameters.output.directory << "/phi_cells_" << std::setw(5) << std::setfill('0')
             << n_outputs << ".txt";
        Postprocess::write_cell_means(solid->get_dof_handler(), solid->get_solution(), 0, "phi",
                                      fluid.time(), name.str());
      }
    ++n_outputs;
    if (probe_report)
      probe_report->sample(fluid.velocity(), fluid.kinematic_pressure(), fluid.time());
  }

  template <int dim>
  void Simulation<dim>::add_statistics_row(const Fluid::StepReport      &r,
                                           const Fluid::FlowDiagnostics &d,
                                           const double                  dt,
                                           const double                  wall_time)
  {
    statistics.add_value("step", fluid.step_number());
    statistics.add_value("time", fluid.time());
    statistics.add_value("dt", dt);
    statistics.add_value("CFL", dt * d.max_speed_over_h);
    statistics.add_value("bulk_velocity", d.bulk_velocity);
    statistics.add_value("minus_dp_dx", r.driving_force);
    statistics.add_value("kinetic_energy", d.kinetic_energy);
    statistics.add_value("div_u_L2", d.divergence_l2);
    statistics.add_value("its_momentum", r.momentum_iterations);
    statistics.add_value("its_projection", r.projection_iterations);
    statistics.add_value("its_mass", r.mass_iterations);
    statistics.add_value("cells", triangulation.n_global_active_cells());
    statistics.add_value("dofs", space.dof_velocity.n_dofs() + space.dof_pressure.n_dofs());
    statistics.add_value("wall_time_step", wall_time);
    for (const auto &c : {"time", "dt", "CFL", "bulk_velocity", "minus_dp_dx",
                          "kinetic_energy", "div_u_L2", "wall_time_step"})
      {
        statistics.set_scientific(c, true);
        statistics.set_precision(c, 8);
      }
  }

  template <int dim>
  void Simulation<dim>::write_tables() const
  {
    if (Utilities::MPI::this_mpi_process(communicator) != 0)
      return;
    std::ofstream stats(parameters.output.directory + "/statistics.txt");
    statistics.write_text(stats, TableHandler::table_with_separate_column_description);
    if (channel_statistics)
      channel_statistics->write(parameters.output.directory);
    if (probe_report)
      probe_report->write(parameters.output.directory);
  }

  template <int dim>
  void Simulation<dim>::sample_statistics(const double driving_force)
  {
    TimerOutput::Scope scope(timer, "statistics");
    std::optional<Postprocess::SolidFields<dim>> solid_fields;
    if (solid)
      solid_fields.emplace(Postprocess::SolidFields<dim>{
        solid->get_dof_handler(), solid->get_solution(), parameters.solid.shear_modulus,
        Solid::StressWeight(parameters.solid)});
    channel_statistics->sample(space, fluid.velocity(), fluid.time(), driving_force,
                               solid_fields ? &*solid_fields : nullptr,
                               contact.get());
  }

  template <int dim>
  void Simulation<dim>::print_progress(const double dt, const Fluid::FlowDiagnostics &d,
                                       const double elapsed) const
  {
    const double t = fluid.time(), end = parameters.time_stepping.end_time;
    pcout << "step " << std::setw(6) << fluid.step_number() << "  t = " << std::scientific
          << std::setprecision(3) << t << " / " << end << "  dt = " << dt << "  CFL "
          << std::fixed << std::setprecision(2) << dt * d.max_speed_over_h << "  ETA "
          << format_duration(t > 0 ? elapsed / t * (end - t) : 0.) << std::defaultfloat
          << std::endl;
  }

  template <int dim>
  void Simulation<dim>::report_seeding() const
  {
    if (parameters.solid.seeded)
      {
        const auto &s = parameters.solid;
        pcout << "  seeded " << s.particles.size() << " particles of radius " << s.seeding.radius
              << ": volume fraction " << std::setprecision(6) << s.seeded_volume_fraction
              << " (asked " << (s.seeding.n_particles > 0 ? "N = " : "Phi = ")
              << (s.seeding.n_particles > 0 ? double(s.seeding.n_particles) :
                                              s.seeding.volume_fraction)
              << "), closest gap " << s.seeded_closest_gap << " (at least "
              << s.seeding.minimum_gap << "), closest wall " << s.seeded_closest_wall
              << " (at least " << s.seeding.wall_clearance << ")" << std::defaultfloat
              << std::endl;
        // Phi is met to half a particle's volume fraction (N is a whole number)
        const double one = s.seeded_volume_fraction / s.particles.size();
        const bool   as_asked =
          s.seeding.n_particles > 0 ?
            s.particles.size() == s.seeding.n_particles :
            std::abs(s.seeded_volume_fraction - s.seeding.volume_fraction) <= 0.5 * one + 1e-12;
        pcout << "  N and Phi as asked: " << (as_asked ? "yes" : "no")
              << ", no overlap and wall clearance kept: "
              << (s.seeded_closest_gap >= s.seeding.minimum_gap &&
                      s.seeded_closest_wall >= s.seeding.wall_clearance ?
                    "yes" :
                    "no")
              << std::endl;
      }
  }

  /// The end of a run: the last output and every report.
  template <int dim>
  RunSummary Simulation<dim>::finish(const double dt)
  {
    const auto &diagnostics = flow_diagnostics;
    if (steady)
      pcout << "  steady state reached" << std::endl;
    if (sampled_enough())
      pcout << "  statistics complete: 'Statistics/Sampling time' of steady flow sampled by t = "
            << fluid.time() << std::endl;
    if (last_output_time != fluid.time())
      write_output();
    write_tables();

    pcout << "  final state: kinetic energy " << std::scientific << std::setprecision(6)
          << diagnostics.kinetic_energy;
    if (parameters.flow_driving.type != Parameters::FlowDrivingType::none)
      pcout << ", bulk velocity " << diagnostics.bulk_velocity << ", -dp/dx "
            << last_driving_force;
    pcout << std::defaultfloat << std::endl;
    if (probe_report && pcout.is_active())
      probe_report->report(pcout.get_stream());
    if (mesh_report && pcout.is_active())
      mesh_report->report(pcout.get_stream(), triangulation.n_global_active_cells());
    if (solid_report)
      solid_report->report(pcout, solid_diagnostics, fluid.velocity(), fluid.time());
    if (solid && parameters.time_stepping.substep_cost > 0.)
      pcout << "  time step fitted to the transport: " << steps_run << " steps, "
            << transport_substeps_run << " transport sub-steps since the start (or resume)" << std::endl;
    if (contact_report && pcout.is_active())
      contact_report->report(pcout.get_stream());
    verification_report.report_errors(pcout, fluid.velocity(), fluid.kinematic_pressure(),
                                      fluid.time(), steady);
    verification_report.report_verdicts(pcout, last_driving_force, steady);
    if (channel_statistics && pcout.is_active())
      channel_statistics->print_summary(pcout.get_stream(), parameters.verification.tolerance,
                                        !solid);
    verification_report.report_reference(pcout, fluid.velocity());

    if (parameters.output.timer_summary)
      pcout << "  "
            << memory_line(space.dof_velocity.n_dofs(), initial_memory_estimate, communicator)
            << std::endl;
    if (parameters.output.timer_summary)
      {
        // where the memory goes (the largest rank's), by part: what issue
        // 14 cut (the solid's MatrixFree without quadrature points, no
        // scratch vectors of all DoFs; the fluid's work vectors shared)
        const auto print_parts = [&](const std::string &what, const auto &parts) {
          std::ostringstream line;
          line << "  of which the " << what << " (MB, largest rank):" << std::fixed
               << std::setprecision(0);
          for (const auto &[name, bytes] : parts)
            line << " " << name.substr(name.find(' ') + 1) << " "
                 << Utilities::MPI::max(double(bytes), communicator) / 1e6 << ",";
          std::string text = line.str();
          text.pop_back();
          pcout << text << std::endl;
        };
        print_parts("fluid", fluid.memory_by_part());
        if (solid)
          print_parts("solid", solid->memory_by_part());
      }

    RunSummary summary;
    summary.final_errors = verification_report.last_errors();
    summary.errors       = verification_report.history();
    if (solid_report)
      {
        summary.phi_l1_error        = solid_report->phi_l1_error();
        summary.phi_cell_l1_error   = solid_report->phi_cell_l1_error();
        summary.deformation_history = solid_report->deformation_history();
      }
    if (solid && parameters.solid.particles.size() == 1)
      {
        const auto shape    = solid->particle_shape(space, fluid.velocity());
        summary.deformation = shape.taylor_deformation;
        summary.inclination = shape.inclination;
        summary.deformation_B = shape.taylor_deformation_B;
        summary.inclination_B = shape.inclination_B;
      }
    double h = std::numeric_limits<double>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        h = std::min(h, cell->minimum_vertex_distance());
    summary.smallest_cell = Utilities::MPI::min(h, communicator);
    summary.time_step     = dt;
    summary.n_steps       = fluid.step_number();
    summary.n_dofs        = space.dof_velocity.n_dofs() + space.dof_pressure.n_dofs();
    summary.n_cells       = triangulation.n_global_active_cells();
    return summary;
  }

  template class Simulation<2>;
  template class Simulation<3>;
} // namespace Suspension
