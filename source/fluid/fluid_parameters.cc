// The parameters of the fluid: driving, material, initial velocity, solver.
#include <deal.II/base/utilities.h>

#include <suspension/core/parameter_parsing.h>
#include <suspension/fluid/fluid_parameters.h>

namespace Suspension::Parameters
{
  using namespace dealii;
  using namespace Parsing;

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
                      Patterns::Selection("skew-symmetric|semi-implicit|none"),
                      "Convective term, in the skew-symmetric form "
                      "u.grad u + div(u) u / 2: skew-symmetric (explicit, "
                      "u* = the velocity extrapolated to second order in "
                      "both places; stable to a CFL number of about 0.4 "
                      "with Q2), semi-implicit (u*.grad u + div(u*) u / 2 "
                      "with the new u in the momentum operator, solved "
                      "with GMRES: no CFL limit of its own (one on dt "
                      "times the velocity gradient remains), for 'CFL "
                      "number' up to 1 and beyond; needs 'Momentum "
                      "operator = matrix-free' and 'Solid/Elastic coupling "
                      "= explicit'; doc/method.md) or none (unsteady "
                      "Stokes).");
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
    convection       = prm.get("Convection") == "none"           ? ConvectionForm::none :
                       prm.get("Convection") == "semi-implicit" ? ConvectionForm::semi_implicit :
                                                                  ConvectionForm::skew_symmetric;
    solver_tolerance = prm.get_double("Linear solver tolerance");
    jacobi_momentum  = prm.get("Momentum preconditioner") == "jacobi";
    matrix_free_momentum = prm.get("Momentum operator") == "matrix-free";
    prm.leave_subsection();
    if (mode == VelocityMode::prescribed)
      check_expression("Fluid solver/Prescribed velocity", prescribed_velocity, dim, dim);
    if (convection == ConvectionForm::semi_implicit && !matrix_free_momentum)
      throw InputError("Fluid solver/Convection",
                       "semi-implicit convection needs 'Fluid solver/Momentum "
                       "operator = matrix-free'");
    if (pressure_degree >= velocity_degree)
      throw InputError("Fluid solver/Pressure degree",
                       "must be lower than the velocity degree (" +
                         std::to_string(velocity_degree) + ")");
  }
} // namespace Suspension::Parameters
