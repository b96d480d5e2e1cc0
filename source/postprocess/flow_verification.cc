#include <deal.II/base/mpi.h>
#include <deal.II/base/numbers.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/numerics/vector_tools.h>

#include <suspension/postprocess/flow_verification.h>
#include <suspension/postprocess/point_values.h>

#include <cmath>

namespace Suspension::Postprocess
{
  template <int dim>
  ChannelStartupVelocity<dim>::ChannelStartupVelocity(const double driving_force,
                                                      const double viscosity,
                                                      const double density,
                                                      const double half_height)
    : Function<dim>(dim)
    , G(driving_force)
    , mu(viscosity)
    , nu(viscosity / density)
    , h(half_height)
  {}

  template <int dim>
  double ChannelStartupVelocity<dim>::value(const Point<dim> &p,
                                            const unsigned int component) const
  {
    if (component != 0)
      return 0.;
    const double pi  = numbers::PI;
    const double eta = p[dim - 1];
    const double t   = this->get_time();
    double       u   = G / (2. * mu) * (h * h - eta * eta);
    for (unsigned int k = 0; k < 1000; ++k)
      {
        const double n     = 2. * k + 1.;
        const double decay = std::exp(-n * n * pi * pi * nu * t / (4. * h * h));
        const double term  = 16. * G * h * h / (mu * pi * pi * pi) / (n * n * n) * decay;
        if (term < 1e-17 * std::abs(G * h * h / mu) && k > 2)
          break;
        u -= (k % 2 == 0 ? 1. : -1.) * term * std::cos(n * pi * eta / (2. * h));
      }
    return u;
  }

  template <int dim>
  FlowVerification<dim>::FlowVerification(const Parameters::All &parameters)
    : parameters(parameters)
  {
    const auto &v = parameters.verification;
    if (v.exact_solution == Parameters::ExactSolutionType::function)
      {
        exact_velocity = make_function<dim>(v.exact_velocity, dim);
        exact_pressure = make_function<dim>({v.exact_pressure, v.exact_velocity.constants}, 1);
      }
    else if (v.exact_solution == Parameters::ExactSolutionType::channel_startup)
      {
        exact_velocity = std::make_unique<ChannelStartupVelocity<dim>>(
          parameters.flow_driving.pressure_gradient,
          parameters.material.viscosity,
          parameters.material.density,
          parameters.geometry.half_height);
        exact_pressure = std::make_unique<Functions::ZeroFunction<dim>>(1);
      }
  }

  template <int dim>
  bool FlowVerification<dim>::has_exact_solution() const
  {
    return exact_velocity != nullptr;
  }

  template <int dim>
  FlowErrors FlowVerification<dim>::errors(const Fluid::FluidSpace<dim> &space,
                                           const Fluid::VectorType      &velocity,
                                           const Fluid::VectorType      &kinematic_pressure,
                                           const double                  time) const
  {
    exact_velocity->set_time(time);
    exact_pressure->set_time(time);
    const FEValuesExtractors::Vector velocities(0);
    const QGauss<dim>  quadrature(space.fe_velocity.degree + 2);
    FEValues<dim>      fe_u(space.fe_velocity, quadrature,
                       update_values | update_quadrature_points | update_JxW_values);
    FEValues<dim>      fe_p(space.fe_pressure, quadrature, update_values);
    const unsigned int n_q = quadrature.size();
    std::vector<Tensor<1, dim>> u_h(n_q);
    std::vector<double>         p_h(n_q);
    Vector<double>              u_ex(dim);
    const double                rho = parameters.material.density;

    // sums: |e_u|^2, |u|^2, e_p, e_p^2, volume
    std::vector<double> s(5, 0.);
    for (const auto &cell : space.dof_velocity.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_u.reinit(cell);
          fe_p.reinit(Fluid::FluidSpace<dim>::cell_of(cell, space.dof_pressure));
          fe_u[velocities].get_function_values(velocity, u_h);
          fe_p.get_function_values(kinematic_pressure, p_h);
          for (unsigned int q = 0; q < n_q; ++q)
            {
              const auto &x   = fe_u.quadrature_point(q);
              const double JxW = fe_u.JxW(q);
              exact_velocity->vector_value(x, u_ex);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  s[0] += std::pow(u_h[q][d] - u_ex[d], 2) * JxW;
                  s[1] += u_ex[d] * u_ex[d] * JxW;
                }
              const double e_p = rho * p_h[q] - exact_pressure->value(x);
              s[2] += e_p * JxW;
              s[3] += e_p * e_p * JxW;
              s[4] += JxW;
            }
        }
    Utilities::MPI::sum(s, space.communicator(), s);
    FlowErrors e;
    e.velocity_l2          = std::sqrt(s[0]);
    e.velocity_l2_relative = s[1] > 0 ? std::sqrt(s[0] / s[1]) : e.velocity_l2;
    e.pressure_l2          = std::sqrt(std::max(0., s[3] - s[2] * s[2] / s[4]));
    return e;
  }

  namespace
  {
    // Ghia, Ghia & Shin, J. Comput. Phys. 48 (1982) 387-411, Tables I and II,
    // Re = 100: (y, u) on the vertical and (x, v) on the horizontal centre line.
    const double ghia_u[][2] = {
      {0.9766, 0.84123},  {0.9688, 0.78871},  {0.9609, 0.73722},  {0.9531, 0.68717},
      {0.8516, 0.23151},  {0.7344, 0.00332},  {0.6172, -0.13641}, {0.5000, -0.20581},
      {0.4531, -0.21090}, {0.2813, -0.15662}, {0.1719, -0.10150}, {0.1016, -0.06434},
      {0.0703, -0.04775}, {0.0625, -0.04192}, {0.0547, -0.03717}};
    const double ghia_v[][2] = {
      {0.9688, -0.05906}, {0.9609, -0.07391}, {0.9531, -0.08864}, {0.9453, -0.10313},
      {0.9063, -0.16914}, {0.8594, -0.22445}, {0.8047, -0.24533}, {0.5000, 0.05454},
      {0.2344, 0.17527},  {0.2266, 0.17507},  {0.1563, 0.16077},  {0.0938, 0.12317},
      {0.0781, 0.10890},  {0.0703, 0.10091},  {0.0625, 0.09233}};
  } // namespace

  template <int dim>
  CavityComparison
  FlowVerification<dim>::compare_with_ghia(const Fluid::FluidSpace<dim> &space,
                                           const Fluid::VectorType      &velocity) const
  {
    std::vector<Point<dim>> points;
    for (const auto &row : ghia_u)
      {
        Point<dim> p;
        p[0] = 0.5;
        p[1] = row[0];
        if (dim == 3)
          p[2] = 0.5;
        points.push_back(p);
      }
    for (const auto &row : ghia_v)
      {
        Point<dim> p;
        p[0] = row[0];
        p[1] = 0.5;
        if (dim == 3)
          p[2] = 0.5;
        points.push_back(p);
      }
    const auto       values = point_values(space.dof_velocity, velocity, points);
    CavityComparison c;
    const unsigned int n_u = sizeof(ghia_u) / sizeof(ghia_u[0]);
    for (unsigned int k = 0; k < n_u; ++k)
      c.max_u_deviation = std::max(c.max_u_deviation, std::abs(values[k][0] - ghia_u[k][1]));
    for (unsigned int k = 0; k < sizeof(ghia_v) / sizeof(ghia_v[0]); ++k)
      c.max_v_deviation =
        std::max(c.max_v_deviation, std::abs(values[n_u + k][1] - ghia_v[k][1]));
    return c;
  }

  template class FlowVerification<2>;
  template class FlowVerification<3>;
  template class ChannelStartupVelocity<2>;
  template class ChannelStartupVelocity<3>;
} // namespace Suspension::Postprocess
