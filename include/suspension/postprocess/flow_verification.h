#pragma once

#include <deal.II/base/function.h>

#include <suspension/core/parameters.h>
#include <suspension/core/scene.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/fluid/fluid_space.h>

#include <memory>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /// Errors of one state against the exact solution.
  struct FlowErrors
  {
    double velocity_l2          = 0.;
    double velocity_l2_relative = 0.;
    double pressure_l2          = 0.; // up to the mean
  };

  /// Largest deviation from Ghia et al. (1982), Re = 100, over the
  /// tabulated centre-line points, relative to the lid speed.
  struct CavityComparison
  {
    double max_u_deviation = 0.; // u along x = 1/2
    double max_v_deviation = 0.; // v along y = 1/2
  };

  /**
   * Compares a flow with what is known about it: an exact solution given
   * as expressions, the Fourier-series solution of channel start-up flow,
   * or tabulated reference data.
   */
  template <int dim>
  class FlowVerification
  {
  public:
    FlowVerification(const Parameters::All &parameters);

    bool has_exact_solution() const;

    FlowErrors errors(const Fluid::FluidSpace<dim> &space,
                      const Fluid::VectorType      &velocity,
                      const Fluid::VectorType      &kinematic_pressure,
                      double                        time) const;

    CavityComparison compare_with_ghia(const Fluid::FluidSpace<dim> &space,
                                       const Fluid::VectorType      &velocity) const;

  private:
    const Parameters::All         &parameters;
    std::unique_ptr<Function<dim>> exact_velocity, exact_pressure;
  };

  /**
   * Flow from rest in the channel -h < eta < h under a constant driving
   * force G (per unit volume): u_x = G/(2 mu) (h^2 - eta^2) - sum_k
   * 16 G h^2 / (mu pi^3) (-1)^k / (2k+1)^3 cos((2k+1) pi eta / 2h)
   * exp(-(2k+1)^2 pi^2 nu t / 4h^2), eta the last coordinate.
   */
  template <int dim>
  class ChannelStartupVelocity : public Function<dim>
  {
  public:
    ChannelStartupVelocity(double driving_force, double viscosity, double density,
                           double half_height);
    double value(const Point<dim> &p, unsigned int component = 0) const override;

  private:
    const double G, mu, nu, h;
  };
} // namespace Suspension::Postprocess
