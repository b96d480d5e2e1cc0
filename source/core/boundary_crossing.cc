#include <suspension/core/boundary_crossing.h>

#include <cmath>

namespace Suspension
{
  template <int dim>
  bool velocity_crosses_boundary(const Parameters::All &parameters,
                                 const Scene<dim>      &scene,
                                 Function<dim>         *prescribed_velocity,
                                 double                 now)
  {
    constexpr unsigned int n = 8; // intervals per face direction
    const auto            &g = parameters.geometry;
    const auto             functions = scene.velocity_boundary_functions();
    const double           end_time  = parameters.time_stepping.end_time;
    bool                   crosses   = false;
    for (unsigned int k = 0; k <= 10 && !crosses; ++k)
      {
        const double t = end_time * k / 10.;
        scene.set_time(t);
        if (prescribed_velocity)
          prescribed_velocity->set_time(t);
        for (unsigned int face = 0; face < 2 * dim && !crosses; ++face)
          {
            const unsigned int normal = face / 2;
            const Function<dim> *u    = prescribed_velocity;
            if (!u)
              {
                const auto f = functions.find(face);
                if (f == functions.end()) // periodic
                  continue;
                u = f->second;
              }
            else if (parameters.boundary_conditions.type[face] == Parameters::BoundaryType::periodic)
              continue;
            for (unsigned int i = 0; i < Utilities::pow(n + 1, dim - 1) && !crosses; ++i)
              {
                Point<dim>   p;
                unsigned int index = i;
                for (unsigned int d = 0; d < dim; ++d)
                  if (d == normal)
                    p[d] = face % 2 ? g.box_upper[d] : g.box_lower[d];
                  else
                    {
                      p[d] = g.box_lower[d] + (g.box_upper[d] - g.box_lower[d]) * (index % (n + 1)) / n;
                      index /= n + 1;
                    }
                // relative to the speed there, or to 1 where it is at rest
                double speed = 0.;
                for (unsigned int d = 0; d < dim; ++d)
                  speed += Utilities::fixed_power<2>(u->value(p, d));
                crosses = std::abs(u->value(p, normal)) > 1e-12 * std::max(1., std::sqrt(speed));
              }
          }
      }
    scene.set_time(now); // as the caller left them
    if (prescribed_velocity)
      prescribed_velocity->set_time(now);
    return crosses;
  }

  template bool velocity_crosses_boundary(const Parameters::All &, const Scene<2> &,
                                          Function<2> *, double);
  template bool velocity_crosses_boundary(const Parameters::All &, const Scene<3> &,
                                          Function<3> *, double);
} // namespace Suspension
