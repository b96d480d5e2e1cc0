#pragma once

#include <deal.II/lac/la_parallel_vector.h>

#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/fluid_operators.h>

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /**
   * Writes the fields of one output step as .pvtu + .vtu pieces
   * (velocity, pressure, vorticity, MPI rank, refinement level) and keeps
   * a .pvd index of all steps for ParaView, rewritten each time.
   */
  /// A further field on its own DoFHandler (e.g. phi and B of the solid).
  template <int dim>
  struct ExtraField
  {
    const DoFHandler<dim>                            *dof_handler;
    const LinearAlgebra::distributed::Vector<double> *vector;
    std::vector<std::string>                          names;
  };

  template <int dim>
  class FieldOutput
  {
  public:
    /// `subdivisions`: of each cell's patch (0: the velocity degree)
    FieldOutput(const std::string &directory, unsigned int subdivisions = 0);

    void write(const Fluid::FluidSpace<dim> &space,
               const Fluid::VectorType      &velocity,
               const Fluid::VectorType      &kinematic_pressure,
               double                        density,
               double                        time,
               const std::vector<ExtraField<dim>> &extra_fields = {});

    /// The counter and the .pvd records (checkpoints).
    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    std::string                                  directory;
    unsigned int                                 subdivisions = 0;
    unsigned int                                 counter = 0;
    std::vector<std::pair<double, std::string>> records;
  };
} // namespace Suspension::Postprocess
