#pragma once

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/point.h>
#include <deal.II/dofs/dof_handler.h>

#include <suspension/core/parameters.h>
#include <suspension/solid/transport_operator.h>

namespace Suspension::Solid
{
  /// Exact measure of the intersection of a ball (a disc in 2D) with an
  /// axis-parallel box: in 2D in closed form, in 3D the 2D areas of the
  /// slices integrated over the height by Gauss-Legendre rules between the
  /// heights where a slice's circle passes an edge or a corner of the box
  /// (the integrand is analytic between them; about 1e-13 relative).
  template <int dim>
  double ball_box_intersection(const Point<dim> &centre, double radius, const BoundingBox<dim> &box);

  /// What the initial projection did (for the run's first lines).
  struct InitialFractionReport
  {
    unsigned int cut_cells = 0; // cells the interface passes through
    double       exact_volume = 0.; // of the particles within the box (particles only)
  };

  /**
   * The initial phi with 'Interface width = 0': on each cell the L2
   * projection of the sharp shape (the particles of the scene, with their
   * periodic images, or the indicator 'Fraction expression') onto the DG
   * space of phi, computed with adaptive composite Gauss quadrature, and
   * then shifted by a constant so that the cell mean is the exact volume
   * fraction (particles: ball_box_intersection; an expression: its
   * adaptive quadrature, bisected down to 2^-12 of the cell in 2D and 2^-6
   * in 3D where the indicator changes). Writes component 0 of `solution`
   * (the solid's FESystem), leaves the others. The limiter then keeps
   * 0 <= phi <= 1 without changing the means. Box-shaped (affine) cells.
   */
  template <int dim>
  InitialFractionReport project_initial_fraction(const Parameters::All &parameters,
                                                 const DoFHandler<dim> &dof_handler,
                                                 VectorType            &solution);
} // namespace Suspension::Solid
