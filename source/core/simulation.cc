#include <deal.II/base/mpi.h>
#include <deal.II/base/utilities.h>
#include <deal.II/lac/solver_control.h>

#include <boost/archive/text_iarchive.hpp>
#include <boost/archive/text_oarchive.hpp>
#include <boost/serialization/string.hpp>
#include <boost/serialization/utility.hpp>
#include <boost/serialization/vector.hpp>

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
    std::string format_duration(const double seconds)
    {
      const long s = std::lround(std::max(0., seconds));
      std::ostringstream out;
      out << s / 3600 << "h" << std::setw(2) << std::setfill('0') << (s / 60) % 60 << "m"
          << std::setw(2) << s % 60 << "s";
      return out.str();
    }

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
    , field_output(parameters.output.directory)
    , verification(parameters)
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
    create_initial_mesh();
    space.setup(scene);
    // a prescribed velocity needs the velocity space, but no matrix
    if (!prescribed_velocity)
      operators.reinit(space);
    fluid.initialize(prescribed_velocity.get());
    if (solid)
      solid->setup(space, adaptor.finest_cell_size());
    smallest_cell_size = smallest_cell();
  }

  template <int dim>
  void Simulation<dim>::create_initial_mesh()
  {
    scene.create_mesh(triangulation);
    if (!adaptor.enabled())
      return;
    // Refine towards the initial interface: set phi on the current mesh,
    // flag, refine, and again, until nothing changes.
    for (unsigned int cycle = 0; cycle < parameters.mesh_refinement.initial_cycles; ++cycle)
      {
        space.setup(scene);
        if (solid)
          solid->setup(space, adaptor.finest_cell_size());
        if (!adaptor.flag(solid.get(), space, nullptr, 0.))
          break;
        triangulation.execute_coarsening_and_refinement();
        while (adaptor.flag_periodic_hanging_faces())
          triangulation.execute_coarsening_and_refinement();
      }
  }

  template <int dim>
  double Simulation<dim>::resume()
  {
    TimerOutput::Scope scope(timer, "setup (mesh, DoFs, matrices)");
    const std::string path  = checkpoint.find();
    const std::string state = checkpoint.read_state();
    scene.create_coarse_mesh(triangulation);
    // Before p4est reads a mesh it cannot hold, and before fields are read
    // into elements of another size: the header (checkpoint_header()) must
    // match but for the rank count.
    const auto without_ranks = [](const std::string &header) {
      std::istringstream in(header);
      std::string        word, result;
      for (unsigned int i = 0; in >> word; ++i)
        if (i == 2 || i > 3) // not the tag, the format or the rank count
          result += (result.empty() ? "" : " ") + word;
      return result;
    };
    const std::string saved = state.substr(0, state.find('\n'));
    if (saved.rfind("suspension-checkpoint 1 ", 0) != 0)
      throw std::runtime_error("--resume: '" + path + "/state.txt' is not a checkpoint of "
                               "this version of suspension");
    if (without_ranks(saved) != without_ranks(checkpoint_header()))
      throw std::runtime_error("--resume: the checkpoint in '" + path + "' was written for '" +
                               without_ranks(saved) + "', the parameter file gives '" +
                               without_ranks(checkpoint_header()) +
                               "' (dimension, coarse cells, elements): resume with the file "
                               "the checkpoint was written with");
    checkpoint.load_mesh(triangulation);
    space.setup(scene);
    if (!prescribed_velocity)
      operators.reinit(space);
    // in the order of write_checkpoint()
    fluid.resume_from_checkpoint();
    if (solid)
      solid->resume_from_checkpoint(space);
    smallest_cell_size = smallest_cell();
    return load_state(state, path);
  }

  template <int dim>
  void Simulation<dim>::write_checkpoint(const double dt, const double wall_time)
  {
    TimerOutput::Scope scope(timer, "checkpoint");
    // the order of deserialization in resume()
    fluid.prepare_for_checkpoint();
    if (solid)
      solid->prepare_for_checkpoint();
    const auto report = checkpoint.write(triangulation, save_state(dt, wall_time));
    fluid.checkpoint_written();
    if (solid)
      solid->checkpoint_written();
    // formatted apart, so that the screen's stream keeps its precision
    std::ostringstream line;
    line << "  checkpoint at step " << fluid.step_number() << ", t = " << fluid.time() << ": "
         << std::fixed << std::setprecision(2) << report.bytes / 1e6 << " MB in "
         << report.seconds << " s";
    pcout << line.str() << std::endl;
  }

  namespace
  {
    /// Sizes a checkpoint must match: same mesh, same discretisation.
    template <int dim>
    std::vector<unsigned long long> sizes(const Triangulation<dim>      &tria,
                                          const Fluid::FluidSpace<dim>  &space,
                                          const Solid::SolidPhase<dim>  *solid)
    {
      return {tria.n_global_active_cells(), space.dof_velocity.n_dofs(),
              space.dof_pressure.n_dofs(), solid ? solid->get_dof_handler().n_dofs() : 0};
    }
  } // namespace

  template <int dim>
  std::string Simulation<dim>::checkpoint_header() const
  {
    std::ostringstream line;
    line << "suspension-checkpoint 1 " << dim << "D " << Utilities::MPI::n_mpi_processes(communicator)
         << " " << triangulation.n_cells(0) << "_coarse_cells " << space.fe_velocity.get_name()
         << " " << space.fe_pressure.get_name() << " "
         << (solid ? solid->get_fe().get_name() : std::string("no_solid"));
    return line.str();
  }

  template <int dim>
  std::string Simulation<dim>::save_state(const double dt, const double wall_time) const
  {
    const auto part = [](const auto &object) {
      std::ostringstream out;
      object.save(out);
      return out.str();
    };
    std::vector<double> errors; // time, then the FlowErrors, per report
    for (const auto &[t, e] : error_history)
      errors.insert(errors.end(), {t, e.velocity_l2, e.velocity_l2_relative, e.pressure_l2});

    // a line resume() reads before the mesh, then a boost archive
    std::ostringstream out;
    out << checkpoint_header() << "\n";
    {
      boost::archive::text_oarchive archive(out);
      archive << sizes(triangulation, space, solid.get());
      archive << part(fluid) << (solid ? part(*solid) : std::string()) << part(adaptor)
              << part(field_output)
              << (channel_statistics ? part(*channel_statistics) : std::string());
      const unsigned long long worst = worst_coarse_interface;
      archive << dt << wall_time << last_output_time << last_driving_force << worst
              << n_adaptations << n_outputs
              << (contact_report ? part(*contact_report) : std::string()) << last_probe_values << errors << last_errors.velocity_l2
              << last_errors.velocity_l2_relative << last_errors.pressure_l2;
      archive << statistics << probes;
    }
    return out.str();
  }

  template <int dim>
  double Simulation<dim>::load_state(const std::string &state, const std::string &path)
  {
    const auto part = [](auto &object, const std::string &text) {
      std::istringstream in(text);
      object.load(in);
    };
    std::istringstream in(state);
    std::string        header;
    std::getline(in, header);
    const std::string ranks = Utilities::split_string_list(header, ' ')[3];
    boost::archive::text_iarchive   archive(in);
    std::vector<unsigned long long> saved;
    archive >> saved;
    if (saved != sizes(triangulation, space, solid.get()))
      throw std::runtime_error(
        "--resume: the checkpoint in '" + path + "' has " + std::to_string(saved[0]) +
        " cells and " + std::to_string(saved[1]) + " + " + std::to_string(saved[2]) + " + " +
        std::to_string(saved[3]) +
        " DoFs, the parameter file gives another mesh or discretisation: resume with the file "
        "the checkpoint was written with");

    std::string fluid_state, solid_state, adaptor_state, output_state, statistics_state;
    archive >> fluid_state >> solid_state >> adaptor_state >> output_state >> statistics_state;
    part(fluid, fluid_state);
    if (solid)
      part(*solid, solid_state);
    part(adaptor, adaptor_state);
    part(field_output, output_state);
    if (channel_statistics)
      {
        if (statistics_state.empty())
          throw std::runtime_error("--resume: the checkpoint in '" + path +
                                   "' has no channel statistics ('Statistics/Enabled' was false)");
        part(*channel_statistics, statistics_state);
      }

    double              dt = 0.;
    unsigned long long  worst = 0;
    std::vector<double> errors;
    std::string         contact_state;
    archive >> dt >> wall_time_before >> last_output_time >> last_driving_force >> worst >>
      n_adaptations >> n_outputs >> contact_state >> last_probe_values >>
      errors >> last_errors.velocity_l2 >> last_errors.velocity_l2_relative >>
      last_errors.pressure_l2;
    worst_coarse_interface = worst;
    if (contact_report)
      part(*contact_report, contact_state);
    error_history.clear();
    for (std::size_t i = 0; i + 3 < errors.size(); i += 4)
      error_history.emplace_back(errors[i],
                                 Postprocess::FlowErrors{errors[i + 1], errors[i + 2], errors[i + 3]});
    archive >> statistics >> probes;

    std::ostringstream line;
    line << "  resumed from '" << path << "' (written on " << ranks << " rank"
         << (ranks != "1" ? "s" : "") << ") at step " << fluid.step_number() << ", t = "
         << fluid.time();
    pcout << line.str() << std::endl;
    return dt;
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
    ++n_adaptations;
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
  }

  template <int dim>
  void Simulation<dim>::add_mesh_statistics(const MeshLevels &levels, const bool adapted,
                                            const double adapt_time)
  {
    // levels and counts of the mesh the step ran on; adapted: a new one
    // for the next step
    statistics.add_value("level_min", levels.min_level);
    statistics.add_value("level_max", levels.max_level);
    statistics.add_value("cells_finest", static_cast<unsigned long long>(levels.cells_on_finest));
    if (solid)
      statistics.add_value("coarse_interface_cells",
                           static_cast<unsigned long long>(levels.coarse_interface_cells));
    statistics.add_value("adapted", adapted ? 1 : 0);
    statistics.add_value("wall_time_adapt", adapt_time);
    statistics.set_scientific("wall_time_adapt", true);
    statistics.set_precision("wall_time_adapt", 4);
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
    write_probes();
  }

  template <int dim>
  void Simulation<dim>::write_probes()
  {
    const auto &coordinates = parameters.output.probe_points;
    if (coordinates.empty())
      return;
    std::vector<Point<dim>> points;
    for (const auto &c : coordinates)
      {
        Point<dim> p;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = c[d];
        points.push_back(p);
      }
    const auto u = Postprocess::point_values(space.dof_velocity, fluid.velocity(), points);
    const auto p = Postprocess::point_values(space.dof_pressure, fluid.kinematic_pressure(), points);
    static const char *names[] = {"u_x", "u_y", "u_z"};
    last_probe_values.clear();
    for (unsigned int k = 0; k < points.size(); ++k)
      {
        std::ostringstream line;
        line << "  probe " << k << " at (" << points[k] << "): u = (" << std::scientific
             << std::setprecision(6);
        for (unsigned int d = 0; d < dim; ++d)
          line << (d > 0 ? ", " : "") << u[k][d];
        line << "), p = " << parameters.material.density * p[k][0];
        if (solid)
          {
            const auto names  = solid->component_names();
            const auto values = solid->values_at({points[k]});
            for (unsigned int c = 0; c < names.size(); ++c)
              {
                line << ", " << names[c] << " = " << values[0][c];
                probes.add_value(names[c], values[0][c]);
                probes.set_scientific(names[c], true);
                probes.set_precision(names[c], 12);
              }
          }
        last_probe_values.push_back(line.str());
        probes.add_value("time", fluid.time());
        probes.add_value("probe", k);
        for (unsigned int d = 0; d < dim; ++d)
          probes.add_value("x" + std::to_string(d), points[k][d]);
        for (unsigned int d = 0; d < dim; ++d)
          probes.add_value(names[d], u[k][d]);
        probes.add_value("p", parameters.material.density * p[k][0]);
      }
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
  void Simulation<dim>::update_contact_force()
  {
    if (!contact)
      return;
    TimerOutput::Scope scope(timer, "contact force");
    contact_report->observe(contact->update(*solid));
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
    if (!parameters.output.probe_points.empty())
      {
        std::ofstream out(parameters.output.directory + "/probes.txt");
        TableHandler  copy = probes;
        for (const auto &c : {"time", "x0", "x1", "x2", "u_x", "u_y", "u_z", "p"})
          if (dim == 3 || (std::string(c) != "x2" && std::string(c) != "u_z"))
            {
              copy.set_scientific(c, true);
              copy.set_precision(c, 10);
            }
        copy.write_text(out, TableHandler::table_with_separate_column_description);
      }
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
  void Simulation<dim>::report_errors(const double time, const bool steady)
  {
    if (!verification.has_exact_solution())
      return;
    last_errors = verification.errors(space, fluid.velocity(), fluid.kinematic_pressure(), time);
    error_history.emplace_back(time, last_errors);
    std::ostringstream when;
    when << "t = " << std::setprecision(6) << time;
    // the step at which a steady state is detected may differ by one
    // between platforms or rank counts: do not print it
    pcout << "  " << (steady ? std::string("steady state") : when.str())
          << ": velocity L2 error " << std::scientific << std::setprecision(3)
          << last_errors.velocity_l2 << " (relative " << last_errors.velocity_l2_relative
          << "), pressure L2 error " << last_errors.pressure_l2 << std::defaultfloat
          << std::endl;
  }

  template <int dim>
  void Simulation<dim>::report_verdicts(const bool steady)
  {
    const double tolerance = parameters.verification.tolerance;
    const auto   verdict   = [&](const double value) { return value <= tolerance ? "yes" : "no"; };
    if (tolerance > 0 && verification.has_exact_solution())
      pcout << "  velocity relative L2 error <= " << tolerance << ": "
            << verdict(last_errors.velocity_l2_relative) << std::endl;

    // In a channel at constant flow rate, -dp/dx over its laminar value
    // 3 mu V_b / h^2 is the effective viscosity ratio.
    const auto &driving = parameters.flow_driving;
    if (parameters.geometry.type == Parameters::GeometryType::channel &&
        driving.type == Parameters::FlowDrivingType::constant_flow_rate && steady)
      {
        const double h       = parameters.geometry.half_height;
        const double laminar = 3. * parameters.material.viscosity * driving.bulk_velocity / (h * h);
        const double ratio   = last_driving_force / laminar;
        pcout << "  -dp/dx = " << std::setprecision(8) << last_driving_force
              << ", laminar 3 mu V_b / h^2 = " << laminar << ", ratio " << ratio
              << std::defaultfloat << std::endl;
        if (tolerance > 0)
          pcout << "  |ratio - 1| <= " << tolerance << ": " << verdict(std::abs(ratio - 1.))
                << std::endl;
      }
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
    add_statistics_row(report, flow_diagnostics, dt, wall_time);
    if (solid_report)
      solid_report->add_columns(statistics, solid_diagnostics, fluid.velocity());
    if (contact_report)
      contact_report->add_columns(statistics);
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
    worst_coarse_interface  = std::max(worst_coarse_interface, levels.coarse_interface_cells);
    bool       adapted      = false;
    const auto adapt_start  = std::chrono::steady_clock::now();
    if (adaptor.due(flow_diagnostics.max_speed * dt))
      adapted = adapt_mesh();
    if (adapted)
      {
        flow_diagnostics = fluid.compute_diagnostics();
        if (solid)
          solid_diagnostics = solid->diagnostics();
      }
    add_mesh_statistics(levels, adapted,
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
          report_errors(fluid.time(), false);
          if (solid_report)
            solid_report->report_probes(pcout, fluid.time());
          if (solid && parameters.solid.particles.size() == 1)
            {
              const auto shape = solid->particle_shape(space, fluid.velocity());
              deformation_history.push_back(
                {fluid.time(), shape.taylor_deformation, shape.taylor_deformation_B});
              pcout << "  t = " << fluid.time() << ": " << Postprocess::describe(shape) << std::endl;
            }
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
    for (const auto &line : last_probe_values)
      pcout << line << std::endl;
    if (adaptor.enabled())
      {
        pcout << "  mesh: " << n_adaptations << " adaptations, now "
              << triangulation.n_global_active_cells() << " cells";
        if (solid)
          pcout << "; interface cells below the finest level, most in any step: "
                << worst_coarse_interface;
        pcout << std::endl;
      }
    if (solid_report)
      solid_report->report(pcout, solid_diagnostics, fluid.velocity(), fluid.time());
    if (contact_report && pcout.is_active())
      contact_report->report(pcout.get_stream());
    report_errors(fluid.time(), steady);
    report_verdicts(steady);
    if (channel_statistics && pcout.is_active())
      channel_statistics->print_summary(pcout.get_stream(), parameters.verification.tolerance,
                                        !solid);
    if (parameters.verification.reference_data == Parameters::ReferenceData::ghia_re100)
      {
        const auto c = verification.compare_with_ghia(space, fluid.velocity());
        pcout << "  Ghia et al. (1982), Re = 100: max |u - u_ref| on x = 1/2: " << std::fixed
              << std::setprecision(3) << c.max_u_deviation << ", max |v - v_ref| on y = 1/2: "
              << c.max_v_deviation << std::defaultfloat << std::endl;
        pcout << "  within 2% of the lid speed: "
              << (std::max(c.max_u_deviation, c.max_v_deviation) <= 0.02 ? "yes" : "no")
              << std::endl;
      }

    if (parameters.output.timer_summary)
      pcout << "  "
            << memory_line(space.dof_velocity.n_dofs(),
                           estimate_memory(parameters, communicator).bytes_per_rank, communicator)
            << std::endl;

    RunSummary summary;
    summary.final_errors = last_errors;
    summary.errors       = error_history;
    if (solid_report)
      {
        summary.phi_l1_error      = solid_report->phi_l1_error();
        summary.phi_cell_l1_error = solid_report->phi_cell_l1_error();
      }
    summary.deformation_history = deformation_history;
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
