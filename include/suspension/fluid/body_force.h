#pragma once

#include <deal.II/base/function.h>

#include <suspension/fluid/momentum_source.h>

#include <memory>

namespace Suspension::Fluid
{
  /// A body force per unit volume given as a function of (x, t): the
  /// simplest MomentumSource (used by manufactured solutions).
  template <int dim>
  class BodyForce : public MomentumSource<dim>
  {
  public:
    explicit BodyForce(std::unique_ptr<Function<dim>> function)
      : function(std::move(function))
    {}

    void add(const typename Triangulation<dim>::active_cell_iterator &,
             const std::vector<Point<dim>> &points,
             const std::vector<Point<dim>> &,
             const double                          time,
             std::vector<Tensor<1, dim>>          &force,
             std::vector<SymmetricTensor<2, dim>> &) const override
    {
      function->set_time(time);
      for (unsigned int q = 0; q < points.size(); ++q)
        for (unsigned int d = 0; d < dim; ++d)
          force[q][d] += function->value(points[q], d);
    }

    bool has_stress() const override
    {
      return false;
    }

  private:
    std::unique_ptr<Function<dim>> function;
  };
} // namespace Suspension::Fluid
