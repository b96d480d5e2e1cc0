#pragma once

#include <deal.II/base/parameter_handler.h>

#include <suspension/core/parameter_basics.h>


/// The fluid: 'Flow driving', 'Material', 'Initial conditions', 'Fluid
/// solver' (fluid/fluid_parameters.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  enum class FlowDrivingType
  {
    none,
    constant_flow_rate,
    constant_pressure_gradient
  };

  struct FlowDriving
  {
    FlowDrivingType    type          = FlowDrivingType::none;
    double             bulk_velocity = 1.;
    double             pressure_gradient = 0.; // driving force -dp/dx
    FunctionExpression body_force{"", ""};

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  struct Material
  {
    double density   = 1.;
    double viscosity = 1.;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };

  struct InitialConditions
  {
    FunctionExpression velocity{"", ""};

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  enum class ProjectionForm
  {
    rotational,
    standard
  };

  enum class ConvectionForm
  {
    skew_symmetric, // explicit, extrapolated to second order
    semi_implicit,  // the extrapolated velocity advects the new one
    none
  };

  enum class VelocityMode
  {
    navier_stokes,
    prescribed
  };

  struct FluidSolver
  {
    VelocityMode       mode = VelocityMode::navier_stokes;
    FunctionExpression prescribed_velocity{"", ""};
    unsigned int   velocity_degree = 2;
    unsigned int   pressure_degree = 1;
    ProjectionForm projection      = ProjectionForm::rotational;
    ConvectionForm convection      = ConvectionForm::skew_symmetric;
    double         solver_tolerance = 1e-10;
    bool           jacobi_momentum  = false; // else BoomerAMG
    bool           matrix_free_momentum = true; // else assembled M, K, A

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };
} // namespace Suspension::Parameters
