#include <suspension/solid/phi_values.h>

namespace Suspension::Solid
{
  template <int dim>
  PhiValues<dim>::PhiValues(const FiniteElement<dim> &fe,
                            const Quadrature<dim> &quadrature,
                            const UpdateFlags      flags)
    : scalar(fe.base_element(0), quadrature, flags | update_values)
    , system_index(fe.base_element(0).n_dofs_per_cell())
    , dof_indices(fe.n_dofs_per_cell())
    , phi_dofs(system_index.size())
    , phi_at_points(quadrature.size())
  {
    for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
      {
        const auto [component, base_index] = fe.system_to_component_index(i);
        if (component == 0)
          system_index[base_index] = i;
      }
  }

  template <int dim>
  void PhiValues<dim>::reinit(const typename DoFHandler<dim>::active_cell_iterator &cell,
                              const LinearAlgebra::distributed::Vector<double>  &solution)
  {
    scalar.reinit(static_cast<typename Triangulation<dim>::cell_iterator>(cell));
    cell->get_dof_indices(dof_indices);
    for (unsigned int i = 0; i < phi_dofs.size(); ++i)
      phi_dofs[i] = solution(dof_indices[system_index[i]]);
    for (unsigned int q = 0; q < phi_at_points.size(); ++q)
      {
        double value = 0.;
        for (unsigned int i = 0; i < phi_dofs.size(); ++i)
          value += phi_dofs[i] * scalar.shape_value(i, q);
        phi_at_points[q] = value;
      }
  }

  template <int dim>
  void PhiValues<dim>::gradients(std::vector<Tensor<1, dim>> &grad) const
  {
    grad.resize(phi_at_points.size());
    for (unsigned int q = 0; q < grad.size(); ++q)
      {
        grad[q] = Tensor<1, dim>();
        for (unsigned int i = 0; i < phi_dofs.size(); ++i)
          grad[q] += phi_dofs[i] * scalar.shape_grad(i, q);
      }
  }

  template class PhiValues<2>;
  template class PhiValues<3>;
} // namespace Suspension::Solid
