#pragma once

#include <deal.II/base/parameter_handler.h>

#include <suspension/core/parameter_basics.h>

#include <string>
#include <vector>

/// 'Solid' with its seeding and contact force (solid/solid_parameters.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  enum class InitialFraction
  {
    none,
    particles,
    random_particles,
    function
  };

  /// The solid phase: initial fraction, elasticity, DG transport.
  struct Solid
  {
    InitialFraction                  initial_fraction = InitialFraction::none;
    std::vector<std::vector<double>> particles; // centre..., radius
    double                           interface_width = 0.; // in cells; 0: exact cell fractions
    std::string                      fraction_expression;
    std::string                      constants;
    double                           shear_modulus = 0.;
    unsigned int                     degree        = 1;
    bool                             limiter       = true;
    double                           transport_cfl = 0.5;
    /// Explicit integrator of the DG transport: SSP-RK3 (3 stages per
    /// sub-step), SSP-RK2 (2 stages) or SSP-RK(3,2) (3 stages, second
    /// order, twice the forward-Euler bound); the last two with DG 1 only.
    enum class TransportIntegrator
    {
      ssp_rk3,
      ssp_rk2,
      ssp_rk32
    };
    TransportIntegrator              integrator = TransportIntegrator::ssp_rk3;
    double                           elastic_number = 0.5;
    /// semi-implicit: the stress increment dt G phi (grad u B + B grad u^T),
    /// linear in the new velocity, goes into the momentum predictor
    bool                             semi_implicit = false;
    /// stress G H(phi) (B - I): H a smooth step across 1/2 (sharp) or phi
    bool                             sharp_stress        = true;
    double                           stress_weight_width = 0.2;
    /// with THINC: the particle measures read phi from the cut cells'
    /// profiles (else from the DG polynomial, their projection)
    bool                             shape_on_profile    = true;
    double                           interface_compression = 0.; // c of the compressive flux
    double                           interface_thickness   = 0.25; // eps / h of its diffusion
    /// THINC profile of phi in interface cells for the transport fluxes
    bool                             thinc_reconstruction = true;
    double                           thinc_sharpness      = 3.5; // beta, per cell
    bool                             thinc_curvature      = true; // curved profile
    /// the profile's normal: the mean of the cell's vertex normals where
    /// they agree (else Youngs'), or Youngs' everywhere
    bool                             thinc_smoothed_normal = false;
    double                           B_reset_fraction = -1.; // < 0: where H = 0
    double                           interface_relaxation = 0.; // R of B - I at rate R (1 - H)
    /// algebraic sharpening of phi after every `sharpening_interval` steps
    double                           interface_sharpening = 1.; // a; 1: off
    unsigned int                     sharpening_interval  = 1;
    /// force per unit volume of solid, applied as phi g (x, t)
    FunctionExpression               body_force{"", ""};

    /// 'Initial fraction = random particles': filled into `particles` by
    /// All::parse once the box and its periodic faces are known.
    struct Seeding
    {
      unsigned int n_particles     = 0;
      double       volume_fraction = 0.1;
      double       radius          = 0.1;
      double       minimum_gap     = 0.;
      double       wall_clearance  = 0.;
      unsigned int seed            = 1;
      unsigned int attempts        = 10000;
    } seeding;
    /// Short-range repulsion between particles and from walls (Rosti et
    /// al.): f = mu V r (a1/d + a2/d^2) n for gaps dx <= d <= range dx.
    struct Contact
    {
      std::string mode           = "auto"; // auto | on | off
      bool        enabled        = false;  // resolved by All::parse
      double      a1             = 550.;
      double      a2             = 35.;
      double      velocity_scale = 0.;     // 0: the bulk velocity
      double      radius         = 0.;     // 0: the particles' radius
      double      range          = 3.;     // in cells
    } contact;

    bool   seeded                  = false;
    double seeded_volume_fraction  = 0.;
    double seeded_closest_gap      = 0.;
    double seeded_closest_wall     = 0.;

    bool enabled() const { return initial_fraction != InitialFraction::none; }
    bool elastic() const { return enabled() && shear_modulus > 0.; }

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };
} // namespace Suspension::Parameters
