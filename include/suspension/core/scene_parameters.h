#pragma once

#include <deal.II/base/parameter_handler.h>

#include <suspension/core/parameter_basics.h>

#include <array>
#include <string>
#include <vector>

/// The box and its faces: 'Geometry' and 'Boundary conditions'
/// (core/scene_parameters.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  enum class GeometryType
  {
    channel,
    box
  };

  struct Geometry
  {
    GeometryType type = GeometryType::channel;
    // channel: x in [0, Lx], (3D) y in [0, Ly], wall-normal in [-h, h]
    double streamwise_length = 6.;
    double spanwise_length   = 3.;
    double half_height       = 1.;
    // box
    std::vector<double> box_lower{0., 0., 0.};
    std::vector<double> box_upper{1., 1., 1.};
    // base cells per direction; empty: cells of aspect ratio one
    std::vector<unsigned int> subdivisions;
    bool                      subdivisions_given = false;

    static void declare(ParameterHandler &prm, unsigned int dim);
    void        parse(ParameterHandler &prm, unsigned int dim);
  };

  enum class BoundaryType
  {
    no_slip,
    velocity,
    periodic
  };

  /// Faces are numbered as GridGenerator colours them:
  /// 0 = x-, 1 = x+, 2 = y-, 3 = y+, 4 = z-, 5 = z+.
  struct BoundaryConditions
  {
    std::array<BoundaryType, 6>       type;
    std::array<FunctionExpression, 6> velocity;

    BoundaryConditions();
    static std::string face_name(unsigned int face);
    static void        declare(ParameterHandler &prm, unsigned int dim);
    void               parse(ParameterHandler &prm, unsigned int dim);
  };
} // namespace Suspension::Parameters
