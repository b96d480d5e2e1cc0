// Simulation: construction, set-up, the time loop and the steps it calls.
#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/solver_control.h>

#include <suspension/core/memory.h>
#include <suspension/core/simulation.h>
#include <suspension/fluid/body_force.h>
#include <suspension/mesh/resolution_check.h>
#include <suspension/postprocess/cell_means.h>
#include <suspension/postprocess/point_values.h>

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
    double seconds_since(const std::chrono::steady_clock::time_point start)
    {
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  } // namespace

  template <int dim>
  Simulation<dim>::Simulation(const Parameters::All &parameters, MPI_Comm communicator)
    : parameters(parameters)
    , communicator(communicator)
    , pcout(std::cout, Utilities::MPI::this_mpi_process(communicator) == 0)
    , timer(communicator, pcout,
            parameters.output.timer_summary ? TimerOutput::summary : TimerOutput::never,
            TimerOutput::wall_times)
    , triangulation(communicator,
                    Triangulation<dim>::limit_level_difference_at_vertices,
                    parallel::distributed::Triangulation<dim>::default_setting)
    , scene(parameters)
    , adaptor(parameters, triangulation)
    , space(triangulation, parameters.fluid_solver.velocity_degree,
            parameters.fluid_solver.pressure_degree)
    , fluid(parameters, scene, space, operators)
    , verification_report(parameters, space)
    , field_output(parameters.output.directory, parameters.output.patch_subdivisions)
    , checkpoint(parameters, communicator)
  {
    fluid.set_timer(timer);
    operators.jacobi_momentum = parameters.fluid_solver.jacobi_momentum;
    operators.matrix_free_momentum = parameters.fluid_solver.matrix_free_momentum;
    operators.step_matrix     = parameters.solid.semi_implicit && parameters.solid.elastic();
    if (parameters.fluid_solver.mode == Parameters::VelocityMode::prescribed)
      prescribed_velocity = make_function<dim>(parameters.fluid_solver.prescribed_velocity, dim);
    if (parameters.solid.enabled())
      {
        solid = std::make_unique<Solid::SolidPhase<dim>>(parameters, triangulation);
        solid_report = std::make_unique<Postprocess::SolidReport<dim>>(parameters, *solid, space);
      }
    if (parameters.solid.contact.enabled)
      {
        contact = std::make_unique<Solid::ContactForce<dim>>(parameters, scene.no_slip_walls(),
                                                             scene.periods(), scene.lower_corner(),
                                                             scene.upper_corner());
        contact_report = std::make_unique<Postprocess::ContactReport>(parameters);
      }
    if (adaptor.enabled())
      mesh_report = std::make_unique<Postprocess::MeshReport>(solid != nullptr);
    if (!parameters.output.probe_points.empty())
      probe_report = std::make_unique<Postprocess::ProbeReport<dim>>(parameters, space, solid.get());
    if (parameters.statistics.enabled)
      channel_statistics =
        std::make_unique<Postprocess::ChannelStatistics<dim>>(parameters, communicator);
    if (!parameters.flow_driving.body_force.is_zero())
      body_force = std::make_unique<Fluid::BodyForce<dim>>(
        make_function<dim>(parameters.flow_driving.body_force, dim));
  }

  template <int dim>
  void Simulation<dim>::setup()
  {
    TimerOutput::Scope scope(timer, "setup (mesh, DoFs, matrices)");
    const bool fields_on_mesh = create_initial_mesh();
    if (!fields_on_mesh)
      space.setup(scene);
    // a prescribed velocity needs the velocity space, but no matrix
    if (!prescribed_velocity)
      operators.reinit(space);
    fluid.initialize(prescribed_velocity.get());
    if (solid && !fields_on_mesh)
      solid->setup(space, adaptor.finest_cell_size());
    smallest_cell_size = smallest_cell();
    release_free_memory(); // what the initial refinement cycles left behind
    initial_memory_estimate =
      estimate_memory(parameters, triangulation.n_global_active_cells(), communicator).bytes_per_rank;
  }

  template <int dim>
  bool Simulation<dim>::create_initial_mesh()
  {
    scene.create_mesh(triangulation);
    if (!adaptor.enabled())
      return false;
    // Refine towards the initial interface: set phi on the current mesh,
    // flag, refine, and again, until nothing changes; the space and the
    // solid of the last cycle are those of the final mesh (not built twice).
    for (unsigned int cycle = 0; cycle < parameters.mesh_refinement.initial_cycles; ++cycle)
      {
        space.setup(scene);
        if (solid)
          solid->setup(space, adaptor.finest_cell_size());
        if (!adaptor.flag(solid.get(), space, nullptr, 0.))
          return true;
        triangulation.execute_coarsening_and_refinement();
        while (adaptor.flag_periodic_hanging_faces())
          triangulation.execute_coarsening_and_refinement();
        // before the refined mesh's fields are built
        check_memory_of_refined_mesh(parameters, triangulation.n_global_active_cells(), communicator);
      }
    return false;
  }

  template <int dim>
  bool Simulation<dim>::adapt_mesh()
  {
    TimerOutput::Scope scope(timer, "mesh adaptation");
    TimerOutput::Scope flagging(timer, "mesh: flag cells");
    if (!adaptor.flag(solid.get(), space, prescribed_velocity ? nullptr : &fluid.velocity(),
                      fluid.time()))
      return false;
    flagging.stop();
    do
      change_mesh_with_fields();
    while (adaptor.flag_periodic_hanging_faces());
    return true;
  }

  template <int dim>
  void Simulation<dim>::change_mesh_with_fields()
  {
    {
      TimerOutput::Scope scope(timer, "mesh: refine and repartition");
      fluid.prepare_for_mesh_change();
      if (solid)
        solid->prepare_for_mesh_change();
      triangulation.execute_coarsening_and_refinement();
    }
    {
      TimerOutput::Scope scope(timer, "mesh: DoFs, constraints, matrices");
      space.setup(scene);
      if (!prescribed_velocity)
        operators.reinit(space);
    }
    {
      TimerOutput::Scope scope(timer, "mesh: transfer fluid fields");
      fluid.finish_mesh_change(prescribed_velocity.get());
    }
    if (solid)
      {
        TimerOutput::Scope scope(timer, "mesh: transfer solid fields");
        solid->finish_mesh_change(space);
      }
    smallest_cell_size = smallest_cell();
    release_free_memory(); // the old mesh's fields and the transfer's buffers
  }

  template <int dim>
  double Simulation<dim>::smallest_cell() const
  {
    double h = std::numeric_limits<double>::max();
    for (const auto &cell : triangulation.active_cell_iterators())
      if (cell->is_locally_owned())
        h = std::min(h, cell->minimum_vertex_distance());
    return Utilities::MPI::min(h, communicator);
  }

  template <int dim>
  double Simulation<dim>::choose_time_step(const double dt, const double time,
                                           const Fluid::FlowDiagnostics &d) const
  {
    const auto &ts   = parameters.time_stepping;
    double      next = dt;
    if (ts.adaptive && d.max_speed_over_h > 0.)
      {
        // A new step size means a new momentum matrix and preconditioner:
        // change only when the CFL number leaves [0.5, 1] x target.
        const double cfl = dt * d.max_speed_over_h;
        if (cfl > ts.cfl || cfl < 0.5 * ts.cfl)
          next = std::min(ts.maximum_time_step, 0.9 * ts.cfl / d.max_speed_over_h);
      }
    // The explicit elastic stress: an elastic wave may not cross a cell.
    // Stretched material is stiffer: the increment of G (B - I) under a
    // velocity gradient is G (grad u B + B grad u^T), so the wave speed is
    // sqrt(G lambda_max(B) / rho).
    // Like the CFL step, it is cut with a margin (0.9) rather than followed
    // step by step: each new dt costs a new momentum matrix.
    if (solid && parameters.solid.elastic() && !prescribed_velocity &&
        !parameters.solid.semi_implicit)
      {
        const double elastic = parameters.solid.elastic_number * smallest_cell_size /
                               std::sqrt(parameters.solid.shear_modulus *
                                         std::max(1., solid_diagnostics.wave_stiffness) /
                                         parameters.material.density);
        if (next > elastic)
          next = 0.9 * elastic;
      }
    if (ts.adaptive && solid && ts.substep_cost > 0.)
      next = fit_to_transport_substeps(next, d.max_speed_over_h);
    // A collapsing step means the flow blew up without (yet) a NaN.
    if (next < 1e-6 * ts.time_step)
      {
        std::ostringstream message;
        message << "the time step collapsed to " << std::scientific << std::setprecision(3) << next
                << " at t = " << time << " (kinetic energy " << d.kinetic_energy
                << "): the flow is unstable; reduce 'Time stepping/CFL number' or "
                   "'Solid/Elastic number', or refine the mesh";
        throw std::runtime_error(message.str());
      }
    // Land exactly on report times and on the end time.
    std::vector<double> targets = parameters.verification.report_times;
    targets.push_back(ts.end_time);
    for (const double target : targets)
      if (target > time + 1e-12 * next && target < time + next * (1. + 1e-3))
        return target - time;
    return next;
  }

  template <int dim>
  double Simulation<dim>::fit_to_transport_substeps(const double dt,
                                                    const double speed_over_h) const
  {
    // A step of r transport limits tau costs F + ceil(r) T for r tau of
    // time; the shorter one, s = 0.99 n tau with n = floor(r), costs
    // F + n T for s. Per unit time (c = T / F) the shorter one is cheaper
    // when r (1 + n c) < 0.99 n (1 + ceil(r) c). It is 1 % below n tau so
    // that the CFL hysteresis keeps it while the speed rises by up to 1 %.
    // Comparing with s itself, not with n tau, means that a step cut once
    // is never cut again for the same speed (r = 0.99 n fails the test).
    const double tau = solid->max_substep(speed_over_h);
    const double r   = dt / tau;
    const double n   = std::floor(r);
    if (n < 1. || r - n < 1e-9 * r)
      return dt;
    const double c = parameters.time_stepping.substep_cost;
    if (r * (1. + n * c) < 0.99 * n * (1. + (n + 1.) * c))
      return 0.99 * n * tau;
    return dt;
  }

  template <int dim>
  void Simulation<dim>::update_contact_force()
  {
    if (!contact)
      return;
    TimerOutput::Scope scope(timer, "contact force");
    contact_report->observe(contact->update(*solid));
  }

  template <int dim>
  double Simulation<dim>::start()
  {
    const bool resuming = parameters.checkpoint.resume;
    double     dt       = parameters.time_stepping.time_step;
    if (resuming)
      dt = resume(); // first: without a checkpoint, stop before writing anything
    // (the output directory exists: write_run_record() made it)
    if (!resuming)
      setup();
    pcout << "  " << dim << "D, " << triangulation.n_global_active_cells() << " cells, "
          << space.dof_velocity.n_dofs() << " velocity + " << space.dof_pressure.n_dofs()
          << " pressure DoFs" << std::endl;
    for (const auto &warning : resolution_warnings(parameters, triangulation, adaptor.finest_cell_size()))
      pcout << "  " << warning << std::endl;
    report_seeding();
    if (solid && !resuming && solid->initial_fraction_report().cut_cells > 0)
      {
        const auto        &r = solid->initial_fraction_report();
        std::ostringstream line;
        line << "  initial phi: cell means = exact volume fractions, " << r.cut_cells
             << " cut cells";
        if (r.exact_volume > 0.)
          {
            const double volume = solid->diagnostics().volume;
            line << "; volume " << std::scientific << std::setprecision(10) << volume
                 << ", of the particles " << r.exact_volume << std::setprecision(1)
                 << " (relative difference " << std::abs(volume / r.exact_volume - 1.) << ")";
          }
        pcout << line.str() << std::endl;
      }

    if (body_force)
      sources.push_back(body_force.get());
    if (solid && solid->pushes_fluid())
      sources.push_back(solid.get());
    if (contact)
      sources.push_back(contact.get());
    if (solid)
      solid_diagnostics = solid->diagnostics();

    flow_diagnostics = fluid.compute_diagnostics();
    if (!resuming)
      write_output();
    run_start = std::chrono::steady_clock::now();
    return dt;
  }

  template <int dim>
  double Simulation<dim>::elapsed() const
  {
    return wall_time_before +
           std::chrono::duration<double>(std::chrono::steady_clock::now() - run_start).count();
  }

  template <int dim>
  bool Simulation<dim>::running() const
  {
    const auto &ts = parameters.time_stepping;
    return fluid.time() < ts.end_time * (1. - 1e-12) && !steady && !sampled_enough() &&
           (ts.maximum_steps == 0 || fluid.step_number() < ts.maximum_steps);
  }

  template <int dim>
  bool Simulation<dim>::sampled_enough() const
  {
    return channel_statistics && channel_statistics->complete();
  }

  template <int dim>
  Fluid::StepReport Simulation<dim>::advance(const double dt)
  {
    if (prescribed_velocity)
      {
        // the velocity is known: transport only, no Navier-Stokes step
        const Fluid::VectorType u_begin = fluid.velocity();
        fluid.prescribe(dt, *prescribed_velocity);
        if (solid)
          {
            TimerOutput::Scope scope(timer, "solid transport");
            solid_diagnostics =
              solid->advance(dt, flow_diagnostics.max_speed_over_h, u_begin, fluid.velocity());
          }
        return Fluid::StepReport();
      }
    if (solid)
      {
        TimerOutput::Scope scope(timer, "solid transport");
        solid_diagnostics = solid->advance(dt, flow_diagnostics.max_speed_over_h, fluid.velocity(),
                                           fluid.extrapolated_velocity(dt));
      }
    update_contact_force();
    return fluid.advance(dt, sources);
  }

  template <int dim>
  void Simulation<dim>::check_flow()
  {
    {
      TimerOutput::Scope scope(timer, "diagnostics");
      flow_diagnostics = fluid.compute_diagnostics();
    }
    if (!std::isfinite(flow_diagnostics.kinetic_energy))
      throw std::runtime_error("the velocity is not finite (NaN or Inf) at t = " +
                               std::to_string(fluid.time()) +
                               "; reduce the time step or the CFL number");
    const double tolerance = parameters.time_stepping.steady_tolerance;
    steady = tolerance > 0 && fluid.relative_change_rate() < tolerance;
  }

  template <int dim>
  void Simulation<dim>::record_step(const Fluid::StepReport &report, const double dt,
                                    const double wall_time)
  {
    ++steps_run;
    if (solid)
      transport_substeps_run += solid_diagnostics.substeps;
    // a row every 'Output/Statistics interval' steps, and at the first
    statistics_row = (fluid.step_number() - 1) % parameters.output.statistics_interval == 0;
    if (statistics_row)
      {
        TimerOutput::Scope scope(timer, "statistics row");
        add_statistics_row(report, flow_diagnostics, dt, wall_time);
        if (solid_report)
          solid_report->add_columns(statistics, solid_diagnostics, fluid.velocity());
        if (contact_report)
          contact_report->add_columns(statistics);
      }
    if (channel_statistics && channel_statistics->due(fluid.time(), fluid.step_number()))
      sample_statistics(report.driving_force);
    last_driving_force = report.driving_force;
  }

  template <int dim>
  void Simulation<dim>::adapt_if_due(const double dt)
  {
    if (!adaptor.enabled())
      return;
    const MeshLevels levels = adaptor.levels(solid.get());
    bool       adapted      = false;
    const auto adapt_start  = std::chrono::steady_clock::now();
    // The band of finest cells is due to move once the interface may have
    // crossed its buffer: at the interface's own speed (a disc in a
    // cavity moves at a fraction of the lid's speed), unless the velocity
    // is refined too (Kelly), which follows the fastest fluid.
    const double speed = solid && adaptor.follows_interface_only() ?
                           solid->interface_speed(adaptor.interface_threshold()) :
                           flow_diagnostics.max_speed;
    if (adaptor.due(speed * dt, levels))
      adapted = adapt_mesh();
    if (adapted)
      {
        flow_diagnostics = fluid.compute_diagnostics();
        if (solid)
          solid_diagnostics = solid->diagnostics();
      }
    mesh_report->record(statistics, statistics_row, levels, adapted,
                        std::chrono::duration<double>(std::chrono::steady_clock::now() -
                                                      adapt_start)
                          .count());
  }

  template <int dim>
  void Simulation<dim>::report_at_times(const double dt)
  {
    for (const double t : parameters.verification.report_times)
      if (std::abs(t - fluid.time()) < 1e-9 * dt)
        {
          verification_report.report_errors(pcout, fluid.velocity(), fluid.kinematic_pressure(),
                                            fluid.time(), false);
          if (solid_report)
            solid_report->report_at(pcout, fluid.velocity(), fluid.time());
        }
  }

  template <int dim>
  void Simulation<dim>::write_if_due(const double dt)
  {
    if (output_due(fluid.time(), dt))
      {
        write_output();
        write_tables();
      }
    const auto &o = parameters.output;
    if (o.progress_interval > 0 && fluid.step_number() % o.progress_interval == 0)
      {
        print_progress(dt, flow_diagnostics, elapsed());
        write_tables();
      }
    if (checkpoint.enabled() && checkpoint.due(fluid.step_number()))
      write_checkpoint(dt, elapsed());
  }

  template <int dim>
  void Simulation<dim>::write_last_state()
  {
    // the state that failed, for a look in ParaView; a second failure
    // while writing must not hide the first
    try
      {
        write_output();
        write_tables();
      }
    catch (...)
      {}
  }

  /// The time step as a sequence of calls; any failure writes the last
  /// state once, here, and propagates as one line.
  template <int dim>
  RunSummary Simulation<dim>::run()
  {
    double dt = start();
    try
      {
        while (running())
          {
            const auto step_start = std::chrono::steady_clock::now();
            dt                    = choose_time_step(dt, fluid.time(), flow_diagnostics);
            const auto report     = advance(dt); // transport, forces, fluid
            check_flow();
            // statistics of the step on its own mesh, then the mesh for the next
            record_step(report, dt, seconds_since(step_start));
            adapt_if_due(dt);
            report_at_times(dt);
            write_if_due(dt); // output, progress, checkpoint
          }
        // a run that reached its End time before its statistics were
        // complete can go on to a later one (--resume with a larger End
        // time, as scripts/study extends a case): its last state is kept
        if (checkpoint.enabled() && !sampled_enough() &&
            fluid.time() >= parameters.time_stepping.end_time * (1. - 1e-12))
          write_checkpoint(dt, elapsed());
      }
    catch (const SolverControl::NoConvergence &e)
      {
        write_last_state();
        throw std::runtime_error(
          "a linear solver diverged at t = " + std::to_string(fluid.time() + dt) + " (residual " +
          std::to_string(e.last_residual) +
          "); reduce the time step or the CFL number; the last state was written");
      }
    catch (...)
      {
        write_last_state();
        throw;
      }
    return finish(dt);
  }

  template class Simulation<2>;
  template class Simulation<3>;
} // namespace Suspension
