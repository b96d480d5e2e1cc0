#include <deal.II/base/function_parser.h>
#include <deal.II/base/utilities.h>

#include <suspension/core/parameters.h>
#include <suspension/core/particle_seeding.h>

#include <fstream>
#include <iostream>
#include <sstream>

namespace Suspension::Parameters
{
  using namespace dealii;

  namespace
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
  } // namespace

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

  // ---------------------------------------------------------------- Geometry
  void Geometry::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const Geometry d;
    prm.enter_subsection("Geometry");
    prm.declare_entry("Type",
                      "channel",
                      Patterns::Selection("channel|box"),
                      "channel: walls at (wall-normal coordinate) = +-h, "
                      "periodic in x (and y in 3D); the wall-normal "
                      "coordinate is the last one (y in 2D, z in 3D). "
                      "box: a rectangle/box whose faces each take a "
                      "condition from 'Boundary conditions'.");
    prm.declare_entry("Streamwise length",
                      std::to_string(d.streamwise_length),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel length in x (the flow direction).");
    prm.declare_entry("Spanwise length",
                      std::to_string(d.spanwise_length),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel width in y (3D only).");
    prm.declare_entry("Half height",
                      std::to_string(d.half_height),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel half-height h: walls at -h and +h.");
    prm.declare_entry("Box lower corner",
                      dim == 2 ? "0, 0" : "0, 0, 0",
                      Patterns::List(Patterns::Double(), dim, dim),
                      "Lower corner of the box.");
    prm.declare_entry("Box upper corner",
                      dim == 2 ? "1, 1" : "1, 1, 1",
                      Patterns::List(Patterns::Double(), dim, dim),
                      "Upper corner of the box.");
    prm.declare_entry("Subdivisions",
                      "",
                      Patterns::List(Patterns::Integer(1), 0, dim),
                      "Base (coarse) cells per direction, before refinement. "
                      "Empty: as many as give cells of aspect ratio one.");
    prm.leave_subsection();
  }

  void Geometry::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Geometry");
    type = prm.get("Type") == "channel" ? GeometryType::channel :
                                          GeometryType::box;
    streamwise_length = prm.get_double("Streamwise length");
    spanwise_length   = prm.get_double("Spanwise length");
    half_height       = prm.get_double("Half height");
    box_lower = to_doubles("Geometry/Box lower corner", prm.get("Box lower corner"));
    box_upper = to_doubles("Geometry/Box upper corner", prm.get("Box upper corner"));
    subdivisions.clear();
    for (const auto &s : split(prm.get("Subdivisions"), ','))
      subdivisions.push_back(Utilities::string_to_int(s));
    prm.leave_subsection();

    if (type == GeometryType::channel)
      {
        box_lower = {0., -half_height};
        box_upper = {streamwise_length, half_height};
        if (dim == 3)
          {
            box_lower = {0., 0., -half_height};
            box_upper = {streamwise_length, spanwise_length, half_height};
          }
      }
    for (unsigned int d = 0; d < dim; ++d)
      if (!(box_upper[d] > box_lower[d]))
        throw InputError("Geometry/Box upper corner",
                         "must exceed the lower corner in every direction");
    if (!subdivisions.empty() && subdivisions.size() != dim)
      throw InputError("Geometry/Subdivisions",
                       "give one count per direction (" + std::to_string(dim) +
                         ") or leave empty");
    subdivisions_given = !subdivisions.empty();
    if (subdivisions.empty())
      {
        double shortest = box_upper[0] - box_lower[0];
        for (unsigned int d = 1; d < dim; ++d)
          shortest = std::min(shortest, box_upper[d] - box_lower[d]);
        for (unsigned int d = 0; d < dim; ++d)
          subdivisions.push_back(static_cast<unsigned int>(
            std::max(1.0, std::round((box_upper[d] - box_lower[d]) / shortest))));
      }
  }

  // -------------------------------------------------------------------- Mesh
  void Mesh::declare(ParameterHandler &prm)
  {
    const Mesh d;
    prm.enter_subsection("Mesh");
    prm.declare_entry("Global refinements",
                      std::to_string(d.global_refinements),
                      Patterns::Integer(0, 12),
                      "Number of times every base cell is refined.");
    prm.declare_entry("Refinement region",
                      "",
                      Patterns::Anything(),
                      "Function expression of x, y[, z]: cells whose centre "
                      "makes it positive are refined 'Region refinements' "
                      "more times (a hand-made locally refined mesh with "
                      "hanging nodes). Empty: none.");
    prm.declare_entry("Region refinements",
                      std::to_string(d.region_refinements),
                      Patterns::Integer(0, 6),
                      "Extra refinement levels inside 'Refinement region'.");
    prm.leave_subsection();
  }

  void Mesh::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Mesh");
    global_refinements = prm.get_integer("Global refinements");
    refinement_region  = Utilities::trim(prm.get("Refinement region"));
    region_refinements = prm.get_integer("Region refinements");
    prm.leave_subsection();
    if (!refinement_region.empty())
      check_expression("Mesh/Refinement region",
                       {refinement_region, ""},
                       1,
                       dim);
  }

  // ---------------------------------------------------------- MeshRefinement
  void MeshRefinement::declare(ParameterHandler &prm)
  {
    const MeshRefinement d;
    prm.enter_subsection("Mesh refinement");
    prm.declare_entry("Adaptive", d.enabled ? "true" : "false", Patterns::Bool(),
                      "Adapt the mesh to the solid interface (and the velocity) "
                      "during the run. The criteria below combine: each asks "
                      "for a level per cell, the largest wins.");
    prm.declare_entry("Minimum level", std::to_string(d.minimum_level),
                      Patterns::Integer(0, 16),
                      "Coarsest level allowed (refinements of the base mesh). "
                      "Equal to 'Maximum level': a uniform mesh reached "
                      "through the adaptive machinery.");
    prm.declare_entry("Maximum level", std::to_string(d.maximum_level),
                      Patterns::Integer(0, 16),
                      "Finest level: the interface band is refined to it. At "
                      "least 'Mesh/Global refinements'.");
    prm.declare_entry("Interface threshold", "0.001", Patterns::Double(0, 0.5),
                      "A cell belongs to the interface where epsilon < phi < "
                      "1 - epsilon at one of its nodes or quadrature points.");
    prm.declare_entry("Buffer cells", std::to_string(d.buffer_cells),
                      Patterns::Integer(0, 20),
                      "The interface band is widened by this many cells "
                      "(face neighbours) on each side, so that the interface "
                      "stays on the finest level between two adaptations.");
    prm.declare_entry("Solid level", std::to_string(d.solid_level),
                      Patterns::Integer(0, 16),
                      "Level inside the solid (phi > 1/2, B varies there); 0: "
                      "none.");
    prm.declare_entry("Velocity refine fraction", "0", Patterns::Double(0, 1),
                      "Kelly estimator on the velocity: the cells holding this "
                      "fraction of the estimated error are refined one level "
                      "(up to the maximum); 0 switches the estimator off.");
    prm.declare_entry("Velocity coarsen fraction", "0", Patterns::Double(0, 1),
                      "... and those holding this fraction may be coarsened.");
    prm.declare_entry("Region", "", Patterns::Anything(),
                      "Function expression of x, y[, z]: cells whose centre "
                      "makes it positive are kept at 'Region level' at least "
                      "(for example a wall band, abs(y) > 0.8). Empty: none.");
    prm.declare_entry("Region level", std::to_string(d.region_level),
                      Patterns::Integer(0, 16), "Level inside 'Region'.");
    prm.declare_entry("Interval", std::to_string(d.interval), Patterns::Integer(0),
                      "Adapt every this many steps; 0: from the CFL number, "
                      "so that the interface cannot cross 'Buffer fraction' "
                      "of the buffer between two adaptations (doc/method.md).");
    prm.declare_entry("Buffer fraction", "0.5", Patterns::Double(0.05, 1.),
                      "With Interval = 0: adapt once the fastest material "
                      "point may have moved this fraction of 'Buffer cells' "
                      "finest cells. Larger: fewer adaptations, a thinner "
                      "margin before the interface leaves the finest band.");
    prm.declare_entry("Initial cycles", std::to_string(d.initial_cycles),
                      Patterns::Integer(0, 20),
                      "Adapt-and-reinitialise cycles on the initial condition; "
                      "0: maximum level - global refinements + 2.");
    prm.leave_subsection();
  }

  void MeshRefinement::parse(ParameterHandler &prm, const unsigned int dim, const Mesh &mesh)
  {
    prm.enter_subsection("Mesh refinement");
    enabled             = prm.get_bool("Adaptive");
    minimum_level       = prm.get_integer("Minimum level");
    maximum_level       = prm.get_integer("Maximum level");
    interface_threshold = prm.get_double("Interface threshold");
    buffer_cells        = prm.get_integer("Buffer cells");
    solid_level         = prm.get_integer("Solid level");
    refine_fraction     = prm.get_double("Velocity refine fraction");
    coarsen_fraction    = prm.get_double("Velocity coarsen fraction");
    region              = Utilities::trim(prm.get("Region"));
    region_level        = prm.get_integer("Region level");
    interval            = prm.get_integer("Interval");
    buffer_fraction     = prm.get_double("Buffer fraction");
    initial_cycles      = prm.get_integer("Initial cycles");
    prm.leave_subsection();
    if (!enabled)
      return;
    if (maximum_level < mesh.global_refinements)
      throw InputError("Mesh refinement/Maximum level",
                       "must be at least 'Mesh/Global refinements' (" +
                         std::to_string(mesh.global_refinements) + ")");
    if (minimum_level > maximum_level)
      throw InputError("Mesh refinement/Minimum level", "must be at most 'Maximum level'");
    if (solid_level > maximum_level || region_level > maximum_level)
      throw InputError(solid_level > maximum_level ? "Mesh refinement/Solid level" :
                                                     "Mesh refinement/Region level",
                       "must be at most 'Maximum level'");
    if (refine_fraction + coarsen_fraction > 1.)
      throw InputError("Mesh refinement/Velocity coarsen fraction",
                       "refine and coarsen fractions add up to more than 1");
    if (!region.empty())
      check_expression("Mesh refinement/Region", {region, ""}, 1, dim);
    if (!mesh.refinement_region.empty())
      throw InputError("Mesh/Refinement region",
                       "a hand-made region and an adaptive mesh do not mix; use "
                       "'Mesh refinement/Region'");
    if (initial_cycles == 0)
      initial_cycles = maximum_level - std::min(mesh.global_refinements, minimum_level) + 2;
  }

  // ------------------------------------------------------ BoundaryConditions
  BoundaryConditions::BoundaryConditions()
  {
    type.fill(BoundaryType::no_slip);
  }

  std::string BoundaryConditions::face_name(const unsigned int face)
  {
    static const char *names[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
    return names[face];
  }

  void BoundaryConditions::declare(ParameterHandler &prm,
                                   const unsigned int dim)
  {
    prm.enter_subsection("Boundary conditions");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for the velocity expressions below, as "
                      "name=value pairs separated by commas.");
    for (unsigned int f = 0; f < 2 * dim; ++f)
      {
        prm.enter_subsection("Face " + face_name(f));
        prm.declare_entry("Type",
                          "no-slip",
                          Patterns::Selection("no-slip|velocity|periodic"),
                          "no-slip: u = 0; velocity: u given by 'Velocity'; "
                          "periodic: identified with the opposite face (both "
                          "must say so). Ignored for the channel's periodic "
                          "directions, which are always periodic.");
        prm.declare_entry("Velocity",
                          zero_vector(dim),
                          Patterns::Anything(),
                          "Velocity on this face when Type = velocity: one "
                          "expression of x, y[, z], t per component, "
                          "separated by ';'.");
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }

  void BoundaryConditions::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Boundary conditions");
    const std::string constants = prm.get("Function constants");
    for (unsigned int f = 0; f < 2 * dim; ++f)
      {
        prm.enter_subsection("Face " + face_name(f));
        const std::string t = prm.get("Type");
        type[f] = t == "no-slip"  ? BoundaryType::no_slip :
                  t == "velocity" ? BoundaryType::velocity :
                                    BoundaryType::periodic;
        velocity[f] = {prm.get("Velocity"), constants};
        prm.leave_subsection();
        if (type[f] == BoundaryType::velocity)
          check_expression("Boundary conditions/Face " + face_name(f) +
                             "/Velocity",
                           velocity[f],
                           dim,
                           dim);
      }
    prm.leave_subsection();
    for (unsigned int d = 0; d < dim; ++d)
      if ((type[2 * d] == BoundaryType::periodic) !=
          (type[2 * d + 1] == BoundaryType::periodic))
        throw InputError("Boundary conditions/Face " + face_name(2 * d) +
                           "/Type",
                         "periodic faces come in pairs: set both " +
                           face_name(2 * d) + " and " + face_name(2 * d + 1) +
                           " to periodic");
  }

  // ------------------------------------------------------------- FlowDriving
  void FlowDriving::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const FlowDriving d;
    prm.enter_subsection("Flow driving");
    prm.declare_entry("Type",
                      "none",
                      Patterns::Selection(
                        "none|constant flow rate|constant pressure gradient"),
                      "How the flow in x is driven: constant flow rate holds "
                      "the bulk velocity exactly each step by a dynamic mean "
                      "pressure gradient; constant pressure gradient applies "
                      "a fixed one.");
    prm.declare_entry("Bulk velocity",
                      std::to_string(d.bulk_velocity),
                      Patterns::Double(),
                      "Target bulk (volume-averaged streamwise) velocity V_b "
                      "for Type = constant flow rate.");
    prm.declare_entry("Pressure gradient",
                      std::to_string(d.pressure_gradient),
                      Patterns::Double(),
                      "Driving force -dp/dx (positive drives flow in +x) for "
                      "Type = constant pressure gradient.");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for 'Body force', name=value pairs.");
    prm.declare_entry("Body force",
                      zero_vector(dim),
                      Patterns::Anything(),
                      "Body force per unit volume, one expression of x, y[, "
                      "z], t per component separated by ';'.");
    prm.leave_subsection();
  }

  void FlowDriving::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Flow driving");
    const std::string t = prm.get("Type");
    type = t == "none"                  ? FlowDrivingType::none :
           t == "constant flow rate"    ? FlowDrivingType::constant_flow_rate :
                                          FlowDrivingType::constant_pressure_gradient;
    bulk_velocity     = prm.get_double("Bulk velocity");
    pressure_gradient = prm.get_double("Pressure gradient");
    body_force        = {prm.get("Body force"), prm.get("Function constants")};
    prm.leave_subsection();
    check_expression("Flow driving/Body force", body_force, dim, dim);
  }

  // ---------------------------------------------------------------- Material
  void Material::declare(ParameterHandler &prm)
  {
    const Material d;
    prm.enter_subsection("Material");
    prm.declare_entry("Density",
                      std::to_string(d.density),
                      Patterns::Double(1e-300, Patterns::Double::max_double_value),
                      "Density rho, equal in both phases (1 in the "
                      "dimensionless convention).");
    prm.declare_entry("Viscosity",
                      std::to_string(d.viscosity),
                      Patterns::Double(1e-300, Patterns::Double::max_double_value),
                      "Dynamic viscosity mu, equal in both phases (1/Re_b in "
                      "the dimensionless convention h = V_b = rho = 1).");
    prm.leave_subsection();
  }

  void Material::parse(ParameterHandler &prm)
  {
    prm.enter_subsection("Material");
    density   = prm.get_double("Density");
    viscosity = prm.get_double("Viscosity");
    prm.leave_subsection();
  }

  // ------------------------------------------------------- InitialConditions
  void InitialConditions::declare(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Initial conditions");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for 'Velocity', name=value pairs.");
    prm.declare_entry("Velocity",
                      zero_vector(dim),
                      Patterns::Anything(),
                      "Initial velocity, one expression of x, y[, z] (t = 0) "
                      "per component separated by ';'.");
    prm.leave_subsection();
  }

  void InitialConditions::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Initial conditions");
    velocity = {prm.get("Velocity"), prm.get("Function constants")};
    prm.leave_subsection();
    check_expression("Initial conditions/Velocity", velocity, dim, dim);
  }

  // ------------------------------------------------------------- FluidSolver
  void FluidSolver::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const FluidSolver d;
    prm.enter_subsection("Fluid solver");
    prm.declare_entry("Velocity",
                      "navier-stokes",
                      Patterns::Selection("navier-stokes|prescribed"),
                      "navier-stokes: solve for velocity and pressure; "
                      "prescribed: the velocity is 'Prescribed velocity' "
                      "(interpolated into the velocity space) and no "
                      "Navier-Stokes matrix is built.");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for 'Prescribed velocity', name=value pairs.");
    prm.declare_entry("Prescribed velocity",
                      zero_vector(dim),
                      Patterns::Anything(),
                      "Velocity for Velocity = prescribed: one expression of "
                      "x, y[, z], t per component separated by ';'.");
    prm.declare_entry("Velocity degree",
                      std::to_string(d.velocity_degree),
                      Patterns::Integer(2, 4),
                      "Polynomial degree of the continuous (Q_k) velocity.");
    prm.declare_entry("Pressure degree",
                      std::to_string(d.pressure_degree),
                      Patterns::Integer(1, 3),
                      "Polynomial degree of the continuous pressure; must be "
                      "below the velocity degree (inf-sup stability).");
    prm.declare_entry("Projection form",
                      "rotational",
                      Patterns::Selection("rotational|standard"),
                      "Pressure update of the incremental projection: "
                      "rotational (p += psi - mu div u, Guermond-Minev-Shen "
                      "2006) or standard (p += psi).");
    prm.declare_entry("Convection",
                      "skew-symmetric",
                      Patterns::Selection("skew-symmetric|none"),
                      "Convective term, extrapolated explicitly to second "
                      "order: skew-symmetric (u.grad u + div(u) u / 2) or "
                      "none (unsteady Stokes).");
    prm.declare_entry("Linear solver tolerance",
                      "1e-10",
                      Patterns::Double(1e-16, 1e-2),
                      "Relative residual reduction asked of every linear "
                      "solve of the fluid step (momentum, pressure increment, "
                      "pressure mass matrix).");
    prm.declare_entry("Momentum preconditioner",
                      "amg",
                      Patterns::Selection("amg|jacobi"),
                      "Preconditioner of the momentum predictor's CG: amg "
                      "(BoomerAMG, few iterations, a set-up whenever the mesh "
                      "or the time step changes) or jacobi (no set-up; enough "
                      "when the mass term (alpha/dt) M dominates nu K, i.e. "
                      "nu dt / h^2 is small, as in adaptive suspension runs). "
                      "Used with 'Momentum operator = assembled' only.");
    prm.declare_entry("Momentum operator",
                      "matrix-free",
                      Patterns::Selection("assembled|matrix-free"),
                      "How the momentum predictor's (alpha/dt) M + nu K is "
                      "applied: assembled (PETSc matrices M, K and A, "
                      "rebuilt with the mesh and the time step) or "
                      "matrix-free (FEEvaluation on the fly, no velocity "
                      "matrix in memory, CG with the Jacobi preconditioner "
                      "of its diagonal; doc/method.md).");
    prm.leave_subsection();
  }

  void FluidSolver::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Fluid solver");
    mode = prm.get("Velocity") == "prescribed" ? VelocityMode::prescribed :
                                                 VelocityMode::navier_stokes;
    prescribed_velocity = {prm.get("Prescribed velocity"), prm.get("Function constants")};
    velocity_degree  = prm.get_integer("Velocity degree");
    pressure_degree  = prm.get_integer("Pressure degree");
    projection       = prm.get("Projection form") == "rotational" ?
                         ProjectionForm::rotational :
                         ProjectionForm::standard;
    convection       = prm.get("Convection") == "none" ?
                         ConvectionForm::none :
                         ConvectionForm::skew_symmetric;
    solver_tolerance = prm.get_double("Linear solver tolerance");
    jacobi_momentum  = prm.get("Momentum preconditioner") == "jacobi";
    matrix_free_momentum = prm.get("Momentum operator") == "matrix-free";
    prm.leave_subsection();
    if (mode == VelocityMode::prescribed)
      check_expression("Fluid solver/Prescribed velocity", prescribed_velocity, dim, dim);
    if (pressure_degree >= velocity_degree)
      throw InputError("Fluid solver/Pressure degree",
                       "must be lower than the velocity degree (" +
                         std::to_string(velocity_degree) + ")");
  }

  // ------------------------------------------------------------------- Solid
  void Solid::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const Solid d;
    prm.enter_subsection("Solid");
    prm.declare_entry("Initial fraction",
                      "none",
                      Patterns::Selection("none|particles|random particles|function"),
                      "Initial solid volume fraction phi: none (no solid, "
                      "no phi or B is allocated), particles (the list in "
                      "'Particles'), random particles "
                      "(placed as the 'Seeding' subsection asks), or "
                      "function; see 'Interface width' for how the edge is "
                      "represented.");
    prm.declare_entry("Particles",
                      "",
                      Patterns::Anything(),
                      std::string("Particles as centre and radius, ") +
                        (dim == 2 ? "'x, y, r'" : "'x, y, z, r'") +
                        ", separated by ';' (circles in 2D, spheres in 3D).");
    prm.declare_entry("Interface width",
                      std::to_string(d.interface_width),
                      Patterns::Double(0., 20.),
                      "0: the initial phi of every cell has the exact volume "
                      "fraction of the particles as its mean (circle- or "
                      "sphere-cell intersection; an expression: adaptive "
                      "quadrature), the L2 projection of the sharp shape "
                      "within the cell. Positive: a smoothed particle edge of "
                      "this width in cells of the finest level, phi = (1 - "
                      "tanh(2 (|x - c| - r) / (width h))) / 2, interpolated.");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for 'Fraction expression'.");
    prm.declare_entry("Fraction expression",
                      "0",
                      Patterns::Anything(),
                      "Initial phi for Initial fraction = function, an "
                      "expression of x, y[, z].");
    prm.declare_entry("Shear modulus",
                      "0",
                      Patterns::Double(0.),
                      "G of the neo-Hookean solid: stress G phi (B - I). 0: "
                      "phi is a passive tracer and no B is allocated.");
    prm.declare_entry("Degree",
                      std::to_string(d.degree),
                      Patterns::Integer(0, 4),
                      "Polynomial degree of the discontinuous (FE_DGQ) "
                      "phi and B.");
    prm.declare_entry("Limiter",
                      "true",
                      Patterns::Bool(),
                      "Bound-preserving scaling limiter (Zhang & Shu 2010) "
                      "keeping 0 <= phi <= 1 at the nodes and quadrature "
                      "points of every cell, cell averages unchanged.");
    prm.declare_entry("Transport CFL",
                      std::to_string(d.transport_cfl),
                      Patterns::Double(1e-3, 1.),
                      "Sub-step limit of the explicit SSP-RK3 transport: "
                      "dt |u| (2k+1) / h at most this.");
    prm.declare_entry("Elastic number",
                      std::to_string(d.elastic_number),
                      Patterns::Double(1e-3, 100.),
                      "Time-step limit dt sqrt(G / rho) / h of the explicit "
                      "elastic coupling (elastic wave crossing a cell); not "
                      "applied with 'Elastic coupling = semi-implicit'.");
    prm.declare_entry("Elastic coupling", "explicit",
                      Patterns::Selection("explicit|semi-implicit"),
                      "explicit: the stress G phi (B - I) of the transported B "
                      "is a load of the momentum predictor, the step is "
                      "limited by 'Elastic number'. semi-implicit: the "
                      "increment dt G phi (grad du B + B grad du^T) / 2 of the "
                      "velocity correction du = u^{n+1} - u* is carried into the "
                      "predictor (Crank-Nicolson weight), which lifts the "
                      "elastic-wave limit at the price of a momentum matrix "
                      "and preconditioner per step (doc/method.md).");
    prm.declare_entry("Stress weight", "sharp", Patterns::Selection("sharp|phi"),
                      "Share H(phi) of the stress G H(phi) (B - I) a point "
                      "carries. sharp: a smooth step from 0 at phi = 1/2 - w/2 "
                      "to 1 at 1/2 + w/2 ('Stress weight width' w), B reset to "
                      "I wherever H = 0, so the solid ends at phi = 1/2 - w/2 "
                      "and no stress builds up in the diffuse tail of phi. "
                      "phi: the paper's H = phi, B reset only in cells with "
                      "phi < 1e-4 at every node (doc/method.md, 'Where the "
                      "solid ends').");
    prm.declare_entry("Stress weight width", std::to_string(d.stress_weight_width),
                      Patterns::Double(0., 1.),
                      "Range of phi around 1/2 across which the sharp stress "
                      "weight rises from 0 to 1.");
    prm.declare_entry("B reset fraction", "-1", Patterns::Double(-1., 1.),
                      "Sharp stress weight: B is reset to I at the nodes where "
                      "phi is at most this; negative: where H(phi) = 0 (phi <= "
                      "1/2 - w/2). Between it and the weight's lower end B is "
                      "transported but carries no stress.");
    prm.declare_entry("Interface compression", std::to_string(d.interface_compression),
                      Patterns::Double(0., 2.),
                      "c of an interface-compression flux c |u| phi (1 - phi) "
                      "n added to the transport of phi (n = grad phi / |grad "
                      "phi|, towards the solid), which works against the "
                      "widening of the diffuse interface by the DG transport "
                      "(Lax-Friedrichs face flux, bounds kept by the limiter); "
                      "0: off.");
    prm.declare_entry("Interface reconstruction", d.thinc_reconstruction ? "THINC" : "none",
                      Patterns::Selection("none|THINC"),
                      "How the transport sees phi in the cells the interface "
                      "cuts (0 < cell mean < 1). none: the DG polynomial. "
                      "THINC: the profile 1/2 (1 + tanh(beta (n.xi + d))) in "
                      "the unit cell xi, n along the cell's mean gradient of "
                      "phi, d such that its mean is the cell mean, evaluated "
                      "in the fluxes (upwind face values and cell integrals); "
                      "the interface stays about a cell wide (doc/method.md, "
                      "'A sharp interface inside the cell'). Needs "
                      "axis-parallel cells and Degree >= 1.");
    prm.declare_entry("THINC curvature", d.thinc_curvature ? "true" : "false", Patterns::Bool(),
                      "With 'Interface reconstruction = THINC': true, the profile "
                      "follows a curved surface, n.s + c |s_t|^2 in the unit cell "
                      "(c from the divergence of the cell normals averaged at the "
                      "vertices, as THINC/QQ); false, a plane. The curved profile "
                      "keeps a rotating disc round (doc/method.md, 'A curved "
                      "profile').");
    prm.declare_entry("THINC sharpness", std::to_string(d.thinc_sharpness),
                      Patterns::Double(0.1, 20.),
                      "beta of 'Interface reconstruction = THINC': the profile "
                      "rises from 0.12 to 0.88 over 1/beta of a cell.");
    prm.declare_entry("Interface relaxation rate", "0", Patterns::Double(0.),
                      "Sharp stress weight: B - I relaxes towards 0 at the "
                      "rate R (1 - H(phi)) (1/time), which vanishes in the "
                      "solid (H = 1): material in the band 0 < H < 1, which "
                      "carries little stress, does not accumulate strain; 0: "
                      "off.");
    prm.declare_entry("Interface thickness", std::to_string(d.interface_thickness),
                      Patterns::Double(0., 2.),
                      "With 'Interface compression' c > 0: the diffusion eps c "
                      "|u| grad phi that balances the compression, eps this "
                      "many cells, so that phi keeps the profile 1/(1 + "
                      "exp(-d/eps)) across the interface (d: distance from "
                      "phi = 1/2).");
    prm.declare_entry("Interface sharpening", "1", Patterns::Double(1., 4.),
                      "Sharpness a of the algebraic interface sharpening "
                      "(Aliabadi & Tezduyar): after every 'Sharpening "
                      "interval' steps each DG node value of phi is mapped to "
                      "c^(1-a) phi^a below c and 1 - (1-c)^(1-a) (1-phi)^a "
                      "above, c (about 1/2) such that the integral of phi is "
                      "kept. It keeps the diffuse interface from widening "
                      "under the DG transport; 1: off.");
    prm.declare_entry("Sharpening interval", "1", Patterns::Integer(1),
                      "Time steps between two interface sharpenings.");
    prm.declare_entry("Body force", zero_vector(dim), Patterns::Anything(),
                      "Force per unit volume of solid g(x, y[, z], t), one "
                      "expression per component separated by ';', applied as "
                      "phi g: the buoyancy (rho_s - rho_f) g of particles "
                      "heavier than the fluid, or a push that drives particles "
                      "into each other or a wall (uses 'Function constants').");
    prm.enter_subsection("Seeding");
    prm.declare_entry("Number of particles", "0", Patterns::Integer(0),
                      "Particles to place at random (Initial fraction = "
                      "random particles); 0: as many as 'Volume fraction' "
                      "asks for.");
    prm.declare_entry("Volume fraction", "0.1", Patterns::Double(0., 0.74),
                      "Target solid volume fraction Phi (particle volume over "
                      "the box), rounded to a whole number of particles; the "
                      "run reports the actual N and Phi.");
    prm.declare_entry("Radius", "0.1", Patterns::Double(0.),
                      "Radius of every particle.");
    prm.declare_entry("Minimum gap", "0", Patterns::Double(0.),
                      "Smallest surface-to-surface distance between two "
                      "particles (across periodic faces too).");
    prm.declare_entry("Wall clearance", "0", Patterns::Double(0.),
                      "Smallest distance from a particle's surface to a "
                      "wall (non-periodic face).");
    prm.declare_entry("Random seed", "1", Patterns::Integer(0),
                      "Seed of the placement: the same seed gives the same "
                      "particles on every machine.");
    prm.declare_entry("Attempts per particle", "10000", Patterns::Integer(1),
                      "Random draws for one particle before the request is "
                      "rejected as too dense (an error, not a hang).");
    prm.leave_subsection();
    prm.enter_subsection("Contact force");
    prm.declare_entry("Enabled", "auto", Patterns::Selection("auto|on|off"),
                      "Short-range repulsion f = mu V r (a1/d + a2/d^2) n in "
                      "fluid cells where the gap d between two particles, or "
                      "a particle and a no-slip wall, is between dx and "
                      "Range dx (dx the local cell size; n towards the "
                      "nearest surface). auto: on with two or more particles.");
    prm.declare_entry("a1", "550", Patterns::Double(0.),
                      "Coefficient of 1/d (the paper's 550).");
    prm.declare_entry("a2", "35", Patterns::Double(0.),
                      "Coefficient of 1/d^2 (the paper's 35).");
    prm.declare_entry("Velocity scale", "0", Patterns::Double(0.),
                      "V in the force; 0: the bulk velocity of 'Flow "
                      "driving' (a constant-flow-rate channel).");
    prm.declare_entry("Radius", "0", Patterns::Double(0.),
                      "r in the force; 0: the particles' radius.");
    prm.declare_entry("Range", "3", Patterns::Double(1., 20.),
                      "Largest gap that is pushed apart, in cells.");
    prm.leave_subsection();
    prm.leave_subsection();
  }

  void Solid::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Solid");
    const std::string t = prm.get("Initial fraction");
    initial_fraction = t == "none"             ? InitialFraction::none :
                       t == "particles"        ? InitialFraction::particles :
                       t == "random particles" ? InitialFraction::random_particles :
                                                 InitialFraction::function;
    interface_width     = prm.get_double("Interface width");
    constants           = prm.get("Function constants");
    fraction_expression = prm.get("Fraction expression");
    shear_modulus       = prm.get_double("Shear modulus");
    degree              = prm.get_integer("Degree");
    limiter             = prm.get_bool("Limiter");
    transport_cfl       = prm.get_double("Transport CFL");
    elastic_number      = prm.get_double("Elastic number");
    semi_implicit       = prm.get("Elastic coupling") == "semi-implicit";
    sharp_stress        = prm.get("Stress weight") == "sharp";
    stress_weight_width = prm.get_double("Stress weight width");
    interface_compression = prm.get_double("Interface compression");
    interface_thickness   = prm.get_double("Interface thickness");
    thinc_reconstruction  = prm.get("Interface reconstruction") == "THINC";
    thinc_sharpness       = prm.get_double("THINC sharpness");
    thinc_curvature       = prm.get_bool("THINC curvature");
    if (thinc_reconstruction && degree == 0)
      throw InputError("Solid/Interface reconstruction",
                       "THINC needs Degree >= 1 (the profiles reach the ghost cells "
                       "of other ranks through the phi DoFs of a cell); set it to "
                       "none with Degree = 0");
    interface_relaxation  = prm.get_double("Interface relaxation rate");
    B_reset_fraction      = prm.get_double("B reset fraction");
    interface_sharpening  = prm.get_double("Interface sharpening");
    sharpening_interval   = prm.get_integer("Sharpening interval");
    body_force          = {prm.get("Body force"), constants};
    const std::string list = prm.get("Particles");
    prm.enter_subsection("Seeding");
    seeding.n_particles     = prm.get_integer("Number of particles");
    seeding.volume_fraction = prm.get_double("Volume fraction");
    seeding.radius          = prm.get_double("Radius");
    seeding.minimum_gap     = prm.get_double("Minimum gap");
    seeding.wall_clearance  = prm.get_double("Wall clearance");
    seeding.seed            = prm.get_integer("Random seed");
    seeding.attempts        = prm.get_integer("Attempts per particle");
    prm.leave_subsection();
    prm.enter_subsection("Contact force");
    contact.mode           = prm.get("Enabled");
    contact.a1             = prm.get_double("a1");
    contact.a2             = prm.get_double("a2");
    contact.velocity_scale = prm.get_double("Velocity scale");
    contact.radius         = prm.get_double("Radius");
    contact.range          = prm.get_double("Range");
    prm.leave_subsection();
    prm.leave_subsection();
    if (initial_fraction == InitialFraction::random_particles && seeding.radius <= 0)
      throw InputError("Solid/Seeding/Radius", "must be positive");
    check_expression("Solid/Body force", body_force, dim, dim);
    particles.clear();
    for (const auto &p : split(list, ';'))
      {
        particles.push_back(to_doubles("Solid/Particles", p));
        if (particles.back().size() != dim + 1)
          throw InputError("Solid/Particles",
                           "particle '" + p + "' needs " + std::to_string(dim) +
                             " coordinates and a radius");
        if (particles.back().back() <= 0)
          throw InputError("Solid/Particles", "radius of '" + p + "' is not positive");
      }
    if (initial_fraction == InitialFraction::particles && particles.empty())
      throw InputError("Solid/Particles", "Initial fraction = particles needs particles");
    if (initial_fraction == InitialFraction::function)
      check_expression("Solid/Fraction expression", {fraction_expression, constants}, 1, dim);
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
    interval_steps    = prm.get_integer("Interval steps");
    interval_time     = prm.get_double("Interval time");
    progress_interval = prm.get_integer("Progress interval");
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
                      "both means change by less than 'Steady state "
                      "tolerance' from one window to the next, the flow is "
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
                      "two cycles and prints the verdict.");
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
    if (flow_driving.type != FlowDrivingType::none &&
        boundary_conditions.type[0] != BoundaryType::periodic)
      throw InputError("Flow driving/Type",
                       "a mean pressure gradient drives flow in x and needs "
                       "periodic x faces");
  }

  void All::check_particles(const unsigned int dim) const
  {
    // Each particle inside the box; a particle may reach through a periodic
    // face (its image enters on the other side) but not through a wall.
    const auto &g = geometry;
    const auto  name = [](const std::vector<double> &p) {
      std::ostringstream s;
      for (unsigned int i = 0; i < p.size(); ++i)
        s << (i ? ", " : "") << p[i];
      return s.str();
    };
    for (const auto &p : solid.particles)
      for (unsigned int d = 0; d < dim; ++d)
        {
          const bool   periodic = boundary_conditions.type[2 * d] == BoundaryType::periodic;
          const double r        = periodic ? 0. : p[dim];
          if (!(p[d] - r >= g.box_lower[d] && p[d] + r <= g.box_upper[d]))
            throw InputError("Solid/Particles",
                             "the particle '" + name(p) + "' " +
                               (periodic ? "is centred outside the box" :
                                           "does not fit between the walls") +
                               " in direction " + std::to_string(d + 1) + " [" +
                               std::to_string(g.box_lower[d]) + ", " +
                               std::to_string(g.box_upper[d]) + "]");
        }
    for (unsigned int i = 0; i < solid.particles.size(); ++i)
      for (unsigned int j = i + 1; j < solid.particles.size(); ++j)
        {
          const auto &a = solid.particles[i], &b = solid.particles[j];
          double      d2 = 0.;
          for (unsigned int d = 0; d < dim; ++d)
            {
              double dx = a[d] - b[d];
              if (boundary_conditions.type[2 * d] == BoundaryType::periodic)
                {
                  const double period = g.box_upper[d] - g.box_lower[d];
                  dx -= period * std::round(dx / period);
                }
              d2 += dx * dx;
            }
          if (std::sqrt(d2) < a[dim] + b[dim])
            throw InputError("Solid/Particles",
                             "the particles '" + name(a) + "' and '" + name(b) + "' overlap");
        }
  }

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

  void All::resolve_contact_force()
  {
    auto      &c        = solid.contact;
    const bool solved_u = fluid_solver.mode != VelocityMode::prescribed;
    if (c.mode == "on" && !solved_u)
      throw InputError("Solid/Contact force/Enabled",
                       "a prescribed velocity ignores forces; use 'auto' or 'off'");
    // a prescribed velocity needs no force: 'auto' leaves it off
    c.enabled = solid.enabled() && solved_u &&
                (c.mode == "on" || (c.mode == "auto" && solid.particles.size() >= 2));
    if (!c.enabled)
      return;
    if (c.radius == 0.)
      {
        if (solid.particles.empty())
          throw InputError("Solid/Contact force/Radius",
                           "must be given when phi is an expression (no particle list)");
        c.radius = solid.particles.front().back();
      }
    if (c.velocity_scale == 0.)
      {
        if (flow_driving.type != FlowDrivingType::constant_flow_rate)
          throw InputError("Solid/Contact force/Velocity scale",
                           "must be given when there is no constant flow rate "
                           "(its bulk velocity is the default)");
        c.velocity_scale = flow_driving.bulk_velocity;
      }
  }

  void All::seed_solid(const unsigned int dim)
  {
    SeedingRequest q;
    q.dim = dim;
    for (unsigned int d = 0; d < dim; ++d)
      {
        q.lower[d]    = geometry.box_lower[d];
        q.upper[d]    = geometry.box_upper[d];
        q.periodic[d] = boundary_conditions.type[2 * d] == BoundaryType::periodic;
      }
    const auto &s     = solid.seeding;
    q.n_particles     = s.n_particles;
    q.volume_fraction = s.volume_fraction;
    q.radius          = s.radius;
    q.minimum_gap     = s.minimum_gap;
    q.wall_clearance  = s.wall_clearance;
    q.seed            = s.seed;
    q.attempts        = s.attempts;
    SeedingResult result;
    try
      {
        result = seed_particles(q);
      }
    catch (const std::exception &e)
      {
        throw InputError(s.n_particles > 0 ? "Solid/Seeding/Number of particles" :
                                             "Solid/Seeding/Volume fraction",
                         e.what());
      }
    solid.particles              = result.particles;
    solid.initial_fraction       = InitialFraction::particles;
    solid.seeded                 = true;
    solid.seeded_volume_fraction = result.volume_fraction;
    solid.seeded_closest_gap     = result.closest_gap;
    solid.seeded_closest_wall    = result.closest_wall;
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
