#include <suspension/solid/particle_seeding.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>

namespace Suspension
{
  namespace
  {
    double particle_volume(const unsigned int dim, const double r)
    {
      return dim == 2 ? M_PI * r * r : 4. / 3. * M_PI * r * r * r;
    }

    /// Centre distance with the minimum image in periodic directions.
    double distance(const SeedingRequest &q, const std::vector<double> &a,
                    const std::vector<double> &b)
    {
      double d2 = 0.;
      for (unsigned int d = 0; d < q.dim; ++d)
        {
          double dx = a[d] - b[d];
          if (q.periodic[d])
            {
              const double L = q.upper[d] - q.lower[d];
              dx -= L * std::round(dx / L);
            }
          d2 += dx * dx;
        }
      return std::sqrt(d2);
    }
  } // namespace

  void measure_gaps(const SeedingRequest &q, SeedingResult &result)
  {
    result.closest_gap  = std::numeric_limits<double>::infinity();
    result.closest_wall = std::numeric_limits<double>::infinity();
    const auto &p = result.particles;
    for (std::size_t i = 0; i < p.size(); ++i)
      {
        for (std::size_t j = i + 1; j < p.size(); ++j)
          result.closest_gap =
            std::min(result.closest_gap, distance(q, p[i], p[j]) - p[i][q.dim] - p[j][q.dim]);
        for (unsigned int d = 0; d < q.dim; ++d)
          if (!q.periodic[d])
            result.closest_wall =
              std::min({result.closest_wall, p[i][d] - q.lower[d] - p[i][q.dim],
                        q.upper[d] - p[i][d] - p[i][q.dim]});
      }
  }

  SeedingResult seed_particles(const SeedingRequest &q)
  {
    double box = 1.;
    for (unsigned int d = 0; d < q.dim; ++d)
      box *= q.upper[d] - q.lower[d];
    const double       v = particle_volume(q.dim, q.radius);
    const unsigned int n = q.n_particles > 0 ?
                             q.n_particles :
                             static_cast<unsigned int>(std::lround(q.volume_fraction * box / v));
    if (n == 0)
      throw std::runtime_error("the requested volume fraction gives no particle of this radius");

    std::mt19937 generator(q.seed);
    // uniform in [0, 1) from 32 random bits, the same on every platform
    const auto uniform = [&generator]() { return (generator() + 0.5) / 4294967296.; };

    std::array<double, 3> lo{}, hi{};
    for (unsigned int d = 0; d < q.dim; ++d)
      {
        const double margin = q.periodic[d] ? 0. : q.radius + q.wall_clearance;
        lo[d]               = q.lower[d] + margin;
        hi[d]               = q.upper[d] - margin;
        if (hi[d] <= lo[d])
          throw std::runtime_error("a particle of radius " + std::to_string(q.radius) +
                                   " with the wall clearance does not fit between the walls");
      }

    SeedingResult result;
    const double  closest = 2. * q.radius + q.minimum_gap;
    for (unsigned int k = 0; k < n; ++k)
      {
        bool placed = false;
        for (unsigned int attempt = 0; attempt < q.attempts && !placed; ++attempt)
          {
            std::vector<double> c(q.dim + 1);
            for (unsigned int d = 0; d < q.dim; ++d)
              c[d] = lo[d] + (hi[d] - lo[d]) * uniform();
            c[q.dim] = q.radius;
            placed   = true;
            for (const auto &other : result.particles)
              if (distance(q, c, other) < closest)
                {
                  placed = false;
                  break;
                }
            if (placed)
              result.particles.push_back(c);
          }
        if (!placed)
          {
            std::ostringstream m;
            m << "could place only " << k << " of " << n << " particles (volume fraction "
              << k * v / box << " of " << n * v / box << ") without overlap after " << q.attempts
              << " random draws for the next one; ask for fewer or smaller particles, a "
                 "smaller gap or wall clearance";
            throw std::runtime_error(m.str());
          }
      }
    result.volume_fraction = n * v / box;
    measure_gaps(q, result);
    return result;
  }
} // namespace Suspension
