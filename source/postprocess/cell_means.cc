#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_values.h>

#include <suspension/postprocess/cell_means.h>

#include <fstream>
#include <iomanip>

namespace Suspension::Postprocess
{
  template <int dim>
  void write_cell_means(const DoFHandler<dim>                            &dof_handler,
                        const LinearAlgebra::distributed::Vector<double> &vector,
                        const unsigned int                                component,
                        const std::string                                &name,
                        const double                                      time,
                        const std::string                                &filename)
  {
    const auto       &fe = dof_handler.get_fe();
    const QGauss<dim> quadrature(fe.degree + 1);
    FEValues<dim>     fe_values(fe, quadrature, update_values | update_JxW_values);
    const FEValuesExtractors::Scalar extract(component);
    std::vector<double>              values(quadrature.size());
    std::vector<double>              rows; // 2 dim + 2 numbers per cell
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[extract].get_function_values(vector, values);
          double integral = 0., measure = 0.;
          for (const unsigned int q : fe_values.quadrature_point_indices())
            {
              integral += values[q] * fe_values.JxW(q);
              measure += fe_values.JxW(q);
            }
          const auto box = cell->bounding_box();
          for (unsigned int d = 0; d < dim; ++d)
            rows.push_back(box.lower_bound(d));
          for (unsigned int d = 0; d < dim; ++d)
            rows.push_back(box.upper_bound(d));
          rows.push_back(cell->level());
          rows.push_back(integral / measure);
        }
    const MPI_Comm comm     = dof_handler.get_communicator();
    const auto     gathered = Utilities::MPI::gather(comm, rows, 0);
    if (Utilities::MPI::this_mpi_process(comm) != 0)
      return;
    std::ofstream out(filename);
    static const char *axes[] = {"x", "y", "z"};
    out << "# time " << std::setprecision(10) << time << "\n#";
    for (const char *bound : {"_min", "_max"})
      for (unsigned int d = 0; d < dim; ++d)
        out << ' ' << axes[d] << bound;
    out << " level " << name << "_mean\n" << std::setprecision(8);
    const unsigned int width = 2 * dim + 2;
    for (const auto &part : gathered)
      for (std::size_t i = 0; i + width <= part.size(); i += width)
        {
          for (unsigned int k = 0; k < width; ++k)
            out << (k ? " " : "") << part[i + k];
          out << '\n';
        }
  }

  template void write_cell_means<2>(const DoFHandler<2> &, const LinearAlgebra::distributed::Vector<double> &,
                                    unsigned int, const std::string &, double, const std::string &);
  template void write_cell_means<3>(const DoFHandler<3> &, const LinearAlgebra::distributed::Vector<double> &,
                                    unsigned int, const std::string &, double, const std::string &);
} // namespace Suspension::Postprocess
