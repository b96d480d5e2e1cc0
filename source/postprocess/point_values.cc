#include <deal.II/base/mpi.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q1.h>

#include <deal.II/lac/la_parallel_vector.h>

#include <suspension/postprocess/point_values.h>

#include <limits>

namespace Suspension::Postprocess
{
  template <int dim, typename VectorType>
  std::vector<Vector<double>>
  point_values(const DoFHandler<dim>         &dof_handler,
               const VectorType              &vector,
               const std::vector<Point<dim>> &points)
  {
    const auto        &fe  = dof_handler.get_fe();
    const unsigned int nc  = fe.n_components();
    const MappingQ1<dim> mapping;
    std::vector<double> sums(points.size() * (nc + 1), 0.);
    // A point on a face between cells (or ranks) belongs to the first
    // locally owned cell that contains it; ranks that share it average.
    std::vector<bool> done(points.size(), false);
    std::vector<Vector<double>> value(1, Vector<double>(nc));
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const auto box = cell->bounding_box();
          for (unsigned int k = 0; k < points.size(); ++k)
            {
              if (done[k])
                continue;
              bool inside = true;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  const double tol = 1e-10 * box.side_length(d);
                  inside = inside && points[k][d] >= box.lower_bound(d) - tol &&
                           points[k][d] <= box.upper_bound(d) + tol;
                }
              if (!inside)
                continue;
              const Point<dim> unit = GeometryInfo<dim>::project_to_unit_cell(
                mapping.transform_real_to_unit_cell(cell, points[k]));
              FEValues<dim> fe_values(mapping, fe, Quadrature<dim>(unit), update_values);
              fe_values.reinit(cell);
              fe_values.get_function_values(vector, value);
              for (unsigned int c = 0; c < nc; ++c)
                sums[k * (nc + 1) + c] = value[0][c];
              sums[k * (nc + 1) + nc] = 1.;
              done[k] = true;
            }
        }
    Utilities::MPI::sum(sums, dof_handler.get_communicator(), sums);
    std::vector<Vector<double>> out(points.size(), Vector<double>(nc));
    for (unsigned int k = 0; k < points.size(); ++k)
      {
        const double count = sums[k * (nc + 1) + nc];
        for (unsigned int c = 0; c < nc; ++c)
          out[k][c] = count > 0 ? sums[k * (nc + 1) + c] / count :
                                  std::numeric_limits<double>::quiet_NaN();
      }
    return out;
  }

  template std::vector<Vector<double>>
  point_values(const DoFHandler<2> &, const Fluid::VectorType &, const std::vector<Point<2>> &);
  template std::vector<Vector<double>>
  point_values(const DoFHandler<3> &, const Fluid::VectorType &, const std::vector<Point<3>> &);
  template std::vector<Vector<double>>
  point_values(const DoFHandler<2> &, const LinearAlgebra::distributed::Vector<double> &,
               const std::vector<Point<2>> &);
  template std::vector<Vector<double>>
  point_values(const DoFHandler<3> &, const LinearAlgebra::distributed::Vector<double> &,
               const std::vector<Point<3>> &);
} // namespace Suspension::Postprocess
