#pragma once

#include <deal.II/base/function.h>

#include <suspension/core/parameters.h>
#include <suspension/core/scene.h>

namespace Suspension
{
  /**
   * Whether the flow can carry phi through the boundary of the box: the
   * normal velocity on a non-periodic face (its boundary velocity, or the
   * prescribed velocity when the flow is prescribed), sampled on a grid of
   * 9^(dim-1) points of every such face at 11 times in [0, end time], is not
   * zero. Then the solid volume changes by what flows in and out, and its
   * drift is no measure of conservation. Leaves the functions at time `now`.
   */
  template <int dim>
  bool velocity_crosses_boundary(const Parameters::All &parameters,
                                 const Scene<dim>      &scene,
                                 Function<dim>         *prescribed_velocity,
                                 double                 now);
} // namespace Suspension
