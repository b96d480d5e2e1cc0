#include <deal.II/base/utilities.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <suspension/postprocess/field_output.h>

#include <fstream>
#include <iomanip>
#include <istream>
#include <ostream>

namespace Suspension::Postprocess
{
  namespace
  {
    /// curl u: a scalar in 2D, a vector in 3D.
    template <int dim>
    class Vorticity : public DataPostprocessor<dim>
    {
    public:
      void evaluate_vector_field(const DataPostprocessorInputs::Vector<dim> &inputs,
                                 std::vector<Vector<double>> &computed) const override
      {
        for (unsigned int q = 0; q < computed.size(); ++q)
          {
            const auto &g = inputs.solution_gradients[q];
            if (dim == 2)
              computed[q](0) = g[1][0] - g[0][1];
            else
              for (unsigned int c = 0; c < dim; ++c)
                {
                  const unsigned int a = (c + 1) % dim, b = (c + 2) % dim;
                  computed[q](c) = g[b][a] - g[a][b];
                }
          }
      }
      std::vector<std::string> get_names() const override
      {
        return std::vector<std::string>(dim == 2 ? 1 : dim, "vorticity");
      }
      std::vector<DataComponentInterpretation::DataComponentInterpretation>
      get_data_component_interpretation() const override
      {
        return std::vector<DataComponentInterpretation::DataComponentInterpretation>(
          dim == 2 ? 1 : dim,
          dim == 2 ? DataComponentInterpretation::component_is_scalar :
                     DataComponentInterpretation::component_is_part_of_vector);
      }
      UpdateFlags get_needed_update_flags() const override
      {
        return update_gradients;
      }
    };

    /// p = rho P: the solver works with the kinematic pressure P.
    template <int dim>
    class ScaledPressure : public DataPostprocessorScalar<dim>
    {
    public:
      explicit ScaledPressure(const double density)
        : DataPostprocessorScalar<dim>("pressure", update_values)
        , density(density)
      {}
      void evaluate_scalar_field(const DataPostprocessorInputs::Scalar<dim> &inputs,
                                 std::vector<Vector<double>> &computed) const override
      {
        for (unsigned int q = 0; q < computed.size(); ++q)
          computed[q](0) = density * inputs.solution_values[q];
      }

    private:
      const double density;
    };
  } // namespace

  template <int dim>
  FieldOutput<dim>::FieldOutput(const std::string &directory, const unsigned int subdivisions)
    : directory(directory)
    , subdivisions(subdivisions)
  {}

  template <int dim>
  void FieldOutput<dim>::write(const Fluid::FluidSpace<dim> &space,
                               const Fluid::VectorType      &velocity,
                               const Fluid::VectorType      &kinematic_pressure,
                               const double                  density,
                               const double                  time,
                               const std::vector<ExtraField<dim>> &extra_fields)
  {
    const auto &tria = space.triangulation;
    DataOut<dim> data_out;
    // zlib at its default level took more time than a time step
    DataOutBase::VtkFlags vtk_flags;
    vtk_flags.compression_level = DataOutBase::VtkFlags::best_speed;
    data_out.set_flags(vtk_flags);
    data_out.attach_triangulation(tria);

    data_out.add_data_vector(space.dof_velocity,
                             velocity,
                             std::vector<std::string>(dim, "velocity"),
                             std::vector<DataComponentInterpretation::DataComponentInterpretation>(
                               dim, DataComponentInterpretation::component_is_part_of_vector));
    Vorticity<dim> vorticity;
    data_out.add_data_vector(space.dof_velocity, velocity, vorticity);

    ScaledPressure<dim> pressure(density);
    data_out.add_data_vector(space.dof_pressure, kinematic_pressure, pressure);

    for (const auto &field : extra_fields)
      data_out.add_data_vector(*field.dof_handler, *field.vector, field.names);

    Vector<float> rank(tria.n_active_cells()), level(tria.n_active_cells());
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          rank(cell->active_cell_index())  = tria.locally_owned_subdomain();
          level(cell->active_cell_index()) = cell->level();
        }
    data_out.add_data_vector(rank, "rank");
    data_out.add_data_vector(level, "level");
    data_out.build_patches(subdivisions > 0 ? subdivisions : space.fe_velocity.degree);

    const std::string name = data_out.write_vtu_with_pvtu_record(
      directory + "/", "solution", counter++, tria.get_communicator(), 5, 8);
    records.emplace_back(time, name);
    if (Utilities::MPI::this_mpi_process(tria.get_communicator()) == 0)
      {
        std::ofstream pvd(directory + "/solution.pvd");
        DataOutBase::write_pvd_record(pvd, records);
      }
  }

  template <int dim>
  void FieldOutput<dim>::save(std::ostream &out) const
  {
    // file names have no white space (they are built from "solution")
    out << "FieldOutput " << counter << " " << records.size() << std::setprecision(17);
    for (const auto &[time, name] : records)
      out << " " << time << " " << name;
    out << "\n";
  }

  template <int dim>
  void FieldOutput<dim>::load(std::istream &in)
  {
    std::string tag;
    std::size_t n = 0;
    in >> tag >> counter >> n;
    records.resize(n);
    for (auto &[time, name] : records)
      in >> time >> name;
    AssertThrow(tag == "FieldOutput" && !in.fail(),
                ExcMessage("checkpoint: cannot read the field output's records"));
  }

  template class FieldOutput<2>;
  template class FieldOutput<3>;
} // namespace Suspension::Postprocess
