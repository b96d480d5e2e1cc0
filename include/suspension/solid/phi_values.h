#pragma once

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <vector>

namespace Suspension::Solid
{
  using namespace dealii;

  /// phi (component 0 of the solid's DG system) at the points of a
  /// quadrature, cell by cell. FEValues on the system element would run
  /// its generic vector-valued path over all 1 + n_B components on every
  /// cell; this evaluates phi's own scalar element on phi's DoFs only.
  template <int dim>
  class PhiValues
  {
  public:
    PhiValues(const FiniteElement<dim> &fe, const Quadrature<dim> &quadrature, UpdateFlags flags);

    /// Read phi's DoFs of the cell and evaluate phi at the points.
    void reinit(const typename DoFHandler<dim>::active_cell_iterator   &cell,
                const LinearAlgebra::distributed::Vector<double> &solution);

    /// phi at the points of the last reinit()
    const std::vector<double> &values() const { return phi_at_points; }
    /// grad phi at the points of the last reinit() (needs update_gradients)
    void gradients(std::vector<Tensor<1, dim>> &grad) const;
    /// phi's nodal values (the DoFs) of the last reinit()
    const std::vector<double> &dof_values() const { return phi_dofs; }
    /// the scalar FEValues: JxW, quadrature points
    const FEValues<dim> &fe_values() const { return scalar; }

  private:
    FEValues<dim>                        scalar;
    std::vector<unsigned int>            system_index; // of phi's i-th DoF in the system
    std::vector<types::global_dof_index> dof_indices;
    std::vector<double>                  phi_dofs, phi_at_points;
  };
} // namespace Suspension::Solid
