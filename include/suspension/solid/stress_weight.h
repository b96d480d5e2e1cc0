#pragma once

#include <suspension/solid/solid_parameters.h>

#include <algorithm>

namespace Suspension::Solid
{
  /**
   * How much of the neo-Hookean stress G (B - I) a point with solid
   * fraction phi carries: tau = G H(phi) (B - I).
   *
   * `sharp` (default): H is the cubic smooth step from 0 at
   * phi = 1/2 - w/2 to 1 at phi = 1/2 + w/2 (w = 'Stress weight width'),
   * and B is reset to I wherever H = 0. At a steady state every sheared
   * point that carries stress hardens until it stops shearing, so the
   * solid ends where H switches on: here at phi = 1/2 - w/2, not in the
   * diffuse tail of phi (doc/method.md, "Where the solid ends").
   * `phi`: the paper's H = phi, B reset only in cells with phi < 1e-4 at
   * every node; kept for comparison.
   * Both are the paper's model where phi is 0 or 1.
   */
  struct StressWeight
  {
    bool   sharp = true;
    double lower = 0.4, upper = 0.6;
    double reset = 0.4; // B = I at nodes with phi at most this

    explicit StressWeight(const Parameters::Solid &solid)
      : sharp(solid.sharp_stress)
      , lower(0.5 - 0.5 * solid.stress_weight_width)
      , upper(0.5 + 0.5 * solid.stress_weight_width)
      , reset(solid.B_reset_fraction >= 0. ? solid.B_reset_fraction : lower)
    {}

    double operator()(const double phi) const
    {
      if (!sharp)
        return phi;
      if (phi <= lower)
        return 0.;
      if (phi >= upper)
        return 1.;
      const double s = (phi - lower) / (upper - lower);
      return s * s * (3. - 2. * s);
    }

    /// True where B is reset to I after a step (the point carries no stress
    /// and keeps no memory of deformation).
    bool resets_B(const double phi) const { return sharp && phi <= reset; }
  };
} // namespace Suspension::Solid
