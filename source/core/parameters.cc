#include <deal.II/base/function_parser.h>
#include <deal.II/base/utilities.h>

#include <suspension/core/parameters.h>
#include <suspension/core/parameter_parsing.h>

#include <fstream>
#include <iostream>
#include <sstream>

namespace Suspension::Parameters
{
  using namespace dealii;

  namespace Parsing
  {
    std::vector<std::string> split(const std::string &s, const char sep)
    {
      std::vector<std::string> out;
      if (Utilities::trim(s).empty())
        return out;
      for (const auto &piece : Utilities::split_string_list(s, sep))
        out.push_back(Utilities::trim(piece));
      return out;
    }

    std::vector<double> to_doubles(const std::string &entry,
                                   const std::string &value)
    {
      std::vector<double> out;
      for (const auto &piece : split(value, ','))
        try
          {
            out.push_back(Utilities::string_to_double(piece));
          }
        catch (...)
          {
            throw InputError(entry, "'" + piece + "' is not a number");
          }
      return out;
    }

    /// Throws InputError unless `expression` parses as a function of
    /// x, y[, z], t with `n_components` components.
    void check_expression(const std::string        &entry,
                          const FunctionExpression &f,
                          const unsigned int        n_components,
                          const unsigned int        dim)
    {
      const auto parts = split(f.expression, ';');
      if (parts.size() != n_components)
        throw InputError(entry,
                         "expected " + std::to_string(n_components) +
                           " component(s) separated by ';', found " +
                           std::to_string(parts.size()));
      const auto constants = f.constant_map();
      // deal.II echoes muparser's message to std::cerr before throwing:
      // silence it, the InputError below says it in one line.
      std::ostringstream  muted;
      std::streambuf     *cerr_buffer = std::cerr.rdbuf(muted.rdbuf());
      struct Restore
      {
        std::streambuf *buffer;
        ~Restore() { std::cerr.rdbuf(buffer); }
      } restore{cerr_buffer};
      try
        {
          // FunctionParser parses lazily: evaluate once to find errors now.
          if (dim == 2)
            {
              FunctionParser<2> parser(n_components);
              parser.initialize(variable_names(2), f.expression, constants, true);
              parser.value(Point<2>());
            }
          else
            {
              FunctionParser<3> parser(n_components);
              parser.initialize(variable_names(3), f.expression, constants, true);
              parser.value(Point<3>());
            }
        }
      catch (...)
        {
          throw InputError(entry,
                           "cannot parse '" + f.expression +
                             "' as a function of " + variable_names(dim));
        }
    }

    std::string zero_vector(const unsigned int dim)
    {
      return dim == 2 ? "0; 0" : "0; 0; 0";
    }
  } // namespace Parsing

  using namespace Parsing;

  std::string variable_names(const unsigned int dim)
  {
    return dim == 2 ? "x,y,t" : "x,y,z,t";
  }

  std::map<std::string, double> FunctionExpression::constant_map() const
  {
    std::map<std::string, double> out;
    for (const auto &pair : split(constants, ','))
      {
        const auto kv = split(pair, '=');
        if (kv.size() != 2)
          throw InputError("Function constants",
                           "'" + pair + "' is not of the form name=value");
        try
          {
            out[kv[0]] = Utilities::string_to_double(kv[1]);
          }
        catch (...)
          {
            throw InputError("Function constants",
                             "'" + kv[1] + "' is not a number");
          }
      }
    return out;
  }

  bool FunctionExpression::is_zero() const
  {
    for (const auto &c : split(expression, ';'))
      if (c != "0" && c != "0.0" && c != "0.")
        return false;
    return true;
  }

  // ------------------------------------------------------------ TimeStepping
  void TimeStepping::declare(ParameterHandler &prm)
  {
    const TimeStepping d;
    prm.enter_subsection("Time stepping");
    prm.declare_entry("End time",
                      std::to_string(d.end_time),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Time at which the run ends.");
    prm.declare_entry("Time step",
                      "0.01",
                      Patterns::Double(1e-300, Patterns::Double::max_double_value),
                      "Time step; with 'Adaptive time step' the first one.");
    prm.declare_entry("Adaptive time step",
                      "false",
                      Patterns::Bool(),
                      "Choose the time step from 'CFL number'. It is changed "
                      "only when the CFL number leaves [0.5, 1] times the "
                      "target, because a new step size means new matrices.");
    prm.declare_entry("CFL number",
                      std::to_string(d.cfl),
                      Patterns::Double(1e-6, 100.),
                      "Target CFL number max |u| dt k / h (k the velocity "
                      "degree, so h / k is the node spacing) for the "
                      "adaptive time step.");
    prm.declare_entry("Maximum time step",
                      std::to_string(d.maximum_time_step),
                      Patterns::Double(1e-300, Patterns::Double::max_double_value),
                      "Upper bound of the adaptive time step.");
    prm.declare_entry("Transport sub-step cost",
                      "0",
                      Patterns::Double(0., 100.),
                      "Cost of one transport sub-step of phi and B over the "
                      "cost of one fluid step (with its statistics). If "
                      "positive, an adaptive time step of r times the "
                      "transport's largest sub-step tau (ceil(r) sub-steps) "
                      "is cut to 0.99 n tau, n = floor(r) sub-steps, when "
                      "that is cheaper per unit time: r (1 + n c) < "
                      "0.99 n (1 + ceil(r) c), c this value "
                      "(doc/performance.md). 0: off.");
    prm.declare_entry("Steady state tolerance",
                      "0",
                      Patterns::Double(0., 1.),
                      "Stop once max|u^{n+1} - u^n| / (dt max|u|) falls "
                      "below this value (0: run to the end time).");
    prm.declare_entry("Maximum number of steps",
                      "0",
                      Patterns::Integer(0),
                      "Stop after this many steps (0: no limit).");
    prm.leave_subsection();
  }

  void TimeStepping::parse(ParameterHandler &prm)
  {
    prm.enter_subsection("Time stepping");
    end_time          = prm.get_double("End time");
    time_step         = prm.get_double("Time step");
    adaptive          = prm.get_bool("Adaptive time step");
    cfl               = prm.get_double("CFL number");
    maximum_time_step = prm.get_double("Maximum time step");
    substep_cost      = prm.get_double("Transport sub-step cost");
    steady_tolerance  = prm.get_double("Steady state tolerance");
    maximum_steps     = prm.get_integer("Maximum number of steps");
    prm.leave_subsection();
  }

  // -------------------------------------------------------------- Checkpoint
  void Checkpoint::declare(ParameterHandler &prm)
  {
    prm.enter_subsection("Checkpoint");
    prm.declare_entry("Interval steps",
                      "0",
                      Patterns::Integer(0),
                      "Write a checkpoint (mesh, fields, statistics, every "
                      "scalar of the time loop) to <Output directory>/"
                      "checkpoint/ every this many steps (0: off); "
                      "`suspension FILE.prm --resume` continues from it.");
    prm.declare_entry("Interval minutes",
                      "0",
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Also write one once this much wall time has passed "
                      "since the start or the last checkpoint (0: off).");
    prm.leave_subsection();
  }

  void Checkpoint::parse(ParameterHandler &prm)
  {
    prm.enter_subsection("Checkpoint");
    interval_steps   = prm.get_integer("Interval steps");
    interval_minutes = prm.get_double("Interval minutes");
    prm.leave_subsection();
  }

  // --------------------------------------------------------------------- All
  void All::declare(ParameterHandler &prm, const unsigned int dim)
  {
    prm.declare_entry("Dimension",
                      "2",
                      Patterns::Integer(2, 3),
                      "Space dimension of the scene: 2 or 3.");
    Geometry::declare(prm, dim);
    Mesh::declare(prm);
    MeshRefinement::declare(prm);
    BoundaryConditions::declare(prm, dim);
    FlowDriving::declare(prm, dim);
    Material::declare(prm);
    InitialConditions::declare(prm, dim);
    FluidSolver::declare(prm, dim);
    Solid::declare(prm, dim);
    TimeStepping::declare(prm);
    Output::declare(prm);
    Statistics::declare(prm);
    Verification::declare(prm, dim);
    Checkpoint::declare(prm);
    Study::declare(prm);
  }

  void All::parse(ParameterHandler &prm, const unsigned int dim)
  {
    dimension = prm.get_integer("Dimension");
    geometry.parse(prm, dim);
    mesh.parse(prm, dim);
    mesh_refinement.parse(prm, dim, mesh);
    boundary_conditions.parse(prm, dim);
    flow_driving.parse(prm, dim);
    material.parse(prm);
    initial_conditions.parse(prm, dim);
    fluid_solver.parse(prm, dim);
    solid.parse(prm, dim);
    time_stepping.parse(prm);
    output.parse(prm, dim);
    statistics.parse(prm);
    verification.parse(prm, dim);
    checkpoint.parse(prm);
    study.parse(prm);

    // a channel is bounded by its walls: periodic wall faces would make it
    // a periodic box that the channel's statistics and contact take for one
    if (geometry.type == GeometryType::channel &&
        boundary_conditions.type[2 * (dim - 1)] == BoundaryType::periodic)
      throw InputError("Boundary conditions/Face " +
                         BoundaryConditions::face_name(2 * (dim - 1)) + "/Type",
                       "a channel has walls at -h and +h, they cannot be periodic "
                       "(a box periodic in every direction: 'Geometry/Type = box')");
    if (geometry.type == GeometryType::channel)
      for (unsigned int d = 0; d + 1 < dim; ++d)
        boundary_conditions.type[2 * d] = boundary_conditions.type[2 * d + 1] =
          BoundaryType::periodic;
    // p4est cannot make a coarse cell its own periodic neighbour.
    for (unsigned int d = 0; d < dim; ++d)
      if (boundary_conditions.type[2 * d] == BoundaryType::periodic &&
          geometry.subdivisions[d] < 2)
        {
          if (!geometry.subdivisions_given)
            for (auto &n : geometry.subdivisions)
              n *= 2;
          else
            throw InputError("Geometry/Subdivisions",
                             "a periodic direction needs at least 2 base cells");
        }
    if (statistics.enabled && geometry.type != GeometryType::channel)
      throw InputError("Statistics/Enabled",
                       "channel statistics need 'Geometry/Type = channel' "
                       "(walls at -h and +h, periodic otherwise)");
    if (solid.initial_fraction == InitialFraction::random_particles)
      seed_solid(dim);
    else
      check_particles(dim);
    check_probes(dim);
    resolve_contact_force();
    if (fluid_solver.convection == ConvectionForm::semi_implicit && solid.semi_implicit &&
        solid.elastic())
      throw InputError("Fluid solver/Convection",
                       "semi-implicit convection is not combined with 'Solid/Elastic "
                       "coupling = semi-implicit' (its assembled step matrix has no "
                       "convective part)");
    if (flow_driving.type != FlowDrivingType::none &&
        boundary_conditions.type[0] != BoundaryType::periodic)
      throw InputError("Flow driving/Type",
                       "a mean pressure gradient drives flow in x and needs "
                       "periodic x faces");
  }

  unsigned int read_dimension(const std::string &filename)
  {
    ParameterHandler prm;
    prm.declare_entry("Dimension", "2", Patterns::Integer(2, 3), "");
    prm.parse_input(filename, "", /*skip_undefined=*/true);
    return prm.get_integer("Dimension");
  }

  All read(const std::string &filename, const unsigned int dim,
           const std::vector<std::pair<std::string, std::string>> &overrides)
  {
    {
      // an empty scene would silently run every default
      std::ifstream in(filename);
      std::string   line;
      bool          sets_something = false;
      while (!sets_something && std::getline(in, line))
        {
          const auto start = line.find_first_not_of(" \t\r");
          sets_something   = start != std::string::npos && line[start] != '#';
        }
      if (!sets_something)
        throw std::runtime_error("the file sets no entry (an empty scene would run every "
                                 "default); 'suspension --print-parameters' lists them");
    }
    ParameterHandler prm;
    All::declare(prm, dim);
    prm.parse_input(filename);
    for (const auto &[path, value] : overrides)
      {
        const auto parts = Utilities::split_string_list(path, '/');
        for (unsigned int i = 0; i + 1 < parts.size(); ++i)
          prm.enter_subsection(parts[i]);
        try
          {
            prm.set(parts.back(), value);
          }
        catch (const ParameterHandler::ExcEntryUndeclared &)
          {
            throw InputError(path, "is not an entry (--set 'Section/Entry=value'; "
                                   "'suspension --print-parameters' lists them)");
          }
        catch (const ParameterHandler::ExcValueDoesNotMatchPattern &e)
          {
            std::ostringstream why; // names the pattern
            e.print_info(why);
            throw InputError(path, "cannot be set to '" + value + "': " + why.str());
          }
        catch (...)
          {
            throw InputError(path, "cannot be set to '" + value + "'");
          }
        for (unsigned int i = 0; i + 1 < parts.size(); ++i)
          prm.leave_subsection();
      }
    All all;
    all.parse(prm, dim);
    all.input_file = filename;
    all.overrides  = overrides;
    std::ostringstream used;
    prm.print_parameters(used, ParameterHandler::PRM | ParameterHandler::KeepDeclarationOrder);
    all.parameters_used = used.str();
    return all;
  }
} // namespace Suspension::Parameters
