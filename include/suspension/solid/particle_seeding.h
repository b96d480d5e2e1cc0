#pragma once

#include <array>
#include <vector>

namespace Suspension
{
  /// What to place: in a box, some directions periodic.
  struct SeedingRequest
  {
    unsigned int          dim = 2;
    std::array<double, 3> lower{}, upper{};
    std::array<bool, 3>   periodic{};
    unsigned int          n_particles     = 0;  // 0: from volume_fraction
    double                volume_fraction = 0.;
    double                radius          = 0.1;
    double                minimum_gap     = 0.;  // between surfaces
    double                wall_clearance  = 0.;  // surface to a wall
    unsigned int          seed            = 1;
    unsigned int          attempts        = 10000; // per particle
  };

  struct SeedingResult
  {
    std::vector<std::vector<double>> particles; // centre..., radius
    double                           volume_fraction = 0.;
    /// closest surface-to-surface gap (minimum image across periodic
    /// faces); +inf for fewer than two particles
    double                           closest_gap = 0.;
    double                           closest_wall = 0.; // surface to wall
  };

  /**
   * Random sequential addition: centres drawn uniformly (a 32-bit Mersenne
   * twister mapped by hand, so a seed gives the same particles with any
   * standard library) and kept if no closer than 2 r + gap to any placed
   * particle (periodic images included) and r + clearance to a wall.
   * Throws std::runtime_error naming what could not be placed after
   * `attempts` draws for one particle. RSA jams near Phi = 0.55 (2D) and
   * 0.38 (3D); denser packings need another method.
   */
  SeedingResult seed_particles(const SeedingRequest &request);

  /// Geometry of a seeded set (for tests): closest gap and wall distance.
  void measure_gaps(const SeedingRequest &request, SeedingResult &result);
} // namespace Suspension
