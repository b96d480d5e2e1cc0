#pragma once

#include <deal.II/dofs/dof_handler.h>

#include <suspension/solid/transport_operator.h>

namespace Suspension::Solid
{
  /**
   * B where the solid ends. Wherever H(phi) = 0 the stress G H (B - I)
   * vanishes, so B there is free. Setting it to I (the fluid keeps no memory
   * of deformation) has two side effects at the interface: the DG transport
   * mixes I into the solid's B in every cut cell, and material that the
   * numerical diffusion of phi carries across phi = 1/2 - w/2 joins the
   * solid stress-free in its current, deformed shape. Both re-reference the
   * particle's skin: its rest shape drifts towards its deformed shape and
   * rotates with the material (doc/method.md, "Where the solid ends").
   *
   * Here B is instead extended from the solid into the fluid next to it:
   * B is kept at the nodes where phi >= `solid_level` (H = 1: material
   * that carries the full stress); the other nodes of such a cell take the
   * mean of B over the kept ones; then `layers` rings of cells, one after
   * the other, take the mean B of their face neighbours (periodic and
   * hanging ones included) that hold kept nodes or were extended before.
   * Further away B = I, as before. The band 0 < H < 1, which carries a
   * fraction of the stress, so has the strain of the solid next to it
   * instead of deforming like fluid. Where phi is 0 or 1 nothing changes,
   * and no stress appears where H = 0.
   *
   * `relevant` is a vector with every DoF of the ghost cells (one ghost
   * exchange per ring).
   */
  template <int dim>
  void extend_strain_into_fluid(const DoFHandler<dim> &dof_handler,
                                double                 solid_level,
                                double                 fluid_level,
                                unsigned int           layers,
                                VectorType            &solution,
                                VectorType            &relevant);
} // namespace Suspension::Solid
