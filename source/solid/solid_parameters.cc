// The parameters of the solid phase, and the checks and seeding of its particles.
#include <deal.II/base/utilities.h>

#include <suspension/core/parameter_parsing.h>
#include <suspension/core/parameters.h>
#include <suspension/solid/particle_seeding.h>

#include <cmath>

namespace Suspension::Parameters
{
  using namespace dealii;
  using namespace Parsing;

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
                      "Sub-step limit of the explicit SSP-RK transport: "
                      "dt |u| (2k+1) / h at most this (with SSP-RK2, 0.8 "
                      "times this; with SSP-RK(3,2), 1.41 times).");
    prm.declare_entry("Time integrator",
                      "SSP-RK3",
                      Patterns::Selection("SSP-RK3|SSP-RK2|SSP-RK(3,2)"),
                      "Explicit integrator of the DG transport of phi and B: "
                      "SSP-RK3 (Shu & Osher; 3 stages per sub-step), "
                      "SSP-RK2 (Heun; 2 stages) or SSP-RK(3,2) (Spiteri & "
                      "Ruuth; 3 stages of half a sub-step each, second "
                      "order, strong-stability preserving with coefficient "
                      "2). The second-order ones only with Degree = 1 (with "
                      "DG 2 they are not L2-stable). Their sub-steps sit at "
                      "the same fraction of each one's linear limit for DG 1 "
                      "(dt |u| 3 / h <= 1.23, 1 and 1.76, "
                      "benchmarks/transport_integrator/stability.py): "
                      "'Transport CFL' times 1, 0.8 and 1.41.");
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
    prm.declare_entry("Shape measure", d.shape_on_profile ? "profile" : "polynomial",
                      Patterns::Selection("profile|polynomial"),
                      "With 'Interface reconstruction = THINC': which phi a "
                      "particle's measures (centroid, D, inclination, "
                      "area(phi >= 1/2) and their sub-cell versions in "
                      "statistics.txt) read in the cells the interface cuts. "
                      "profile: the THINC profile the transport carries, on "
                      "24 x 24 (8 x 8 x 8) sub-cells; polynomial: its "
                      "projection onto the cell's DG polynomial, at the Gauss "
                      "points (sessions 9 to 17). The stress weight H(phi) "
                      "reads the polynomial either way (doc/method.md, 'The "
                      "shape of the interface the transport carries').");
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
    prm.declare_entry("THINC normal", d.thinc_smoothed_normal ? "smoothed" : "Youngs",
                      Patterns::Selection("Youngs|smoothed"),
                      "With 'Interface reconstruction = THINC': the normal n of "
                      "the profile. Youngs: the mean gradient of the multilinear "
                      "interpolant of the vertex averages of the cell means (a "
                      "3^dim stencil). smoothed (needs 'THINC curvature'): where "
                      "the unit normals averaged at the cell's vertices agree "
                      "(the length of their mean at least 0.995: radii of "
                      "curvature above about 5 cells), their mean, a 5^dim "
                      "stencil; elsewhere (corners, thin features) Youngs'. "
                      "Keeps a rotating disc round (D 0.0007 instead of 0.0016 "
                      "at 16 cells per diameter; doc/method.md, 'The normal of "
                      "the profile').");
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
    {
      const std::string name = prm.get("Time integrator");
      integrator = name == "SSP-RK2"     ? TransportIntegrator::ssp_rk2 :
                   name == "SSP-RK(3,2)" ? TransportIntegrator::ssp_rk32 :
                                           TransportIntegrator::ssp_rk3;
    }
    elastic_number      = prm.get_double("Elastic number");
    semi_implicit       = prm.get("Elastic coupling") == "semi-implicit";
    sharp_stress        = prm.get("Stress weight") == "sharp";
    stress_weight_width = prm.get_double("Stress weight width");
    shape_on_profile    = prm.get("Shape measure") == "profile";
    interface_compression = prm.get_double("Interface compression");
    interface_thickness   = prm.get_double("Interface thickness");
    thinc_reconstruction  = prm.get("Interface reconstruction") == "THINC";
    thinc_sharpness       = prm.get_double("THINC sharpness");
    thinc_curvature       = prm.get_bool("THINC curvature");
    thinc_smoothed_normal = prm.get("THINC normal") == "smoothed";
    if (thinc_smoothed_normal && !thinc_curvature)
      throw InputError("Solid/THINC normal",
                       "smoothed takes the normals averaged at the vertices that "
                       "'THINC curvature' computes; set 'THINC curvature = true' "
                       "or 'THINC normal = Youngs'");
    if (thinc_reconstruction && degree == 0)
      throw InputError("Solid/Interface reconstruction",
                       "THINC needs Degree >= 1 (the profiles reach the ghost cells "
                       "of other ranks through the phi DoFs of a cell); set it to "
                       "none with Degree = 0");
    if (integrator != TransportIntegrator::ssp_rk3 && degree > 1)
      throw InputError("Solid/Time integrator",
                       prm.get("Time integrator") + " is not L2-stable with DG " +
                         std::to_string(degree) +
                         " (Cockburn & Shu: degree k needs an order k + 1 Runge-Kutta "
                         "method); use SSP-RK3 or Degree = 1");
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

  // ------------------------------------------------ All: the solid's checks
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
} // namespace Suspension::Parameters
