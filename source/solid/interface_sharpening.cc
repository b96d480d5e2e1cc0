#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>

#include <suspension/solid/interface_sharpening.h>

#include <cmath>

namespace Suspension::Solid
{
  template <int dim>
  void InterfaceSharpening<dim>::reinit(const DoFHandler<dim> &dof_handler)
  {
    communicator           = dof_handler.get_communicator();
    const auto &fe         = dof_handler.get_fe();
    const auto &owned      = dof_handler.locally_owned_dofs();
    FEValues<dim> values(fe, QGauss<dim>(fe.degree + 1), update_values | update_JxW_values);
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    phi_dofs.clear();
    weights.clear();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          values.reinit(cell);
          cell->get_dof_indices(dofs);
          for (unsigned int i = 0; i < fe.n_dofs_per_cell(); ++i)
            if (fe.system_to_component_index(i).first == 0)
              {
                double w = 0.;
                for (unsigned int q = 0; q < values.n_quadrature_points; ++q)
                  w += values.shape_value(i, q) * values.JxW(q);
                phi_dofs.push_back(owned.index_within_set(dofs[i]));
                weights.push_back(w);
              }
        }
  }

  namespace
  {
    double sharpened(const double phi, const double c, const double a)
    {
      if (phi <= 0.)
        return 0.;
      if (phi >= 1.)
        return 1.;
      return phi < c ? std::pow(c, 1. - a) * std::pow(phi, a)
                     : 1. - std::pow(1. - c, 1. - a) * std::pow(1. - phi, a);
    }
  } // namespace

  template <int dim>
  double InterfaceSharpening<dim>::apply(VectorType &solution, const double a) const
  {
    const auto integral = [&](const double c) {
      double sum = 0.;
      for (unsigned int k = 0; k < phi_dofs.size(); ++k)
        sum += weights[k] * sharpened(solution.local_element(phi_dofs[k]), c, a);
      return Utilities::MPI::sum(sum, communicator);
    };
    double target = 0.;
    for (unsigned int k = 0; k < phi_dofs.size(); ++k)
      target += weights[k] * solution.local_element(phi_dofs[k]);
    target = Utilities::MPI::sum(target, communicator);

    // the integral falls as c rises: bisect on c in (0, 1)
    double low = 0.05, high = 0.95;
    for (unsigned int it = 0; it < 40; ++it)
      {
        const double c = 0.5 * (low + high);
        (integral(c) > target ? low : high) = c;
      }
    const double c = 0.5 * (low + high);

    double moved = 0., interface = 0.;
    for (unsigned int k = 0; k < phi_dofs.size(); ++k)
      {
        double &phi = solution.local_element(phi_dofs[k]);
        phi         = sharpened(phi, c, a);
        moved += weights[k] * phi;
        interface += weights[k] * phi * (1. - phi);
      }
    moved     = Utilities::MPI::sum(moved, communicator);
    interface = Utilities::MPI::sum(interface, communicator);
    if (interface > 0.)
      {
        // phi + delta phi (1 - phi) stays in [0, 1] for |delta| <= 1
        const double delta = (target - moved) / interface;
        if (std::abs(delta) <= 1.)
          for (unsigned int k = 0; k < phi_dofs.size(); ++k)
            {
              double &phi = solution.local_element(phi_dofs[k]);
              phi += delta * phi * (1. - phi);
            }
      }
    return c;
  }

  template class InterfaceSharpening<2>;
  template class InterfaceSharpening<3>;
} // namespace Suspension::Solid
