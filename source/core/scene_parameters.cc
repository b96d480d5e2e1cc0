// The parameters of the scene: geometry and boundary conditions.
#include <deal.II/base/utilities.h>

#include <suspension/core/parameter_parsing.h>
#include <suspension/core/scene_parameters.h>

namespace Suspension::Parameters
{
  using namespace dealii;
  using namespace Parsing;

  // ---------------------------------------------------------------- Geometry
  void Geometry::declare(ParameterHandler &prm, const unsigned int dim)
  {
    const Geometry d;
    prm.enter_subsection("Geometry");
    prm.declare_entry("Type",
                      "channel",
                      Patterns::Selection("channel|box"),
                      "channel: walls at (wall-normal coordinate) = +-h, "
                      "periodic in x (and y in 3D); the wall-normal "
                      "coordinate is the last one (y in 2D, z in 3D). "
                      "box: a rectangle/box whose faces each take a "
                      "condition from 'Boundary conditions'.");
    prm.declare_entry("Streamwise length",
                      std::to_string(d.streamwise_length),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel length in x (the flow direction).");
    prm.declare_entry("Spanwise length",
                      std::to_string(d.spanwise_length),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel width in y (3D only).");
    prm.declare_entry("Half height",
                      std::to_string(d.half_height),
                      Patterns::Double(0., Patterns::Double::max_double_value),
                      "Channel half-height h: walls at -h and +h.");
    prm.declare_entry("Box lower corner",
                      dim == 2 ? "0, 0" : "0, 0, 0",
                      Patterns::List(Patterns::Double(), dim, dim),
                      "Lower corner of the box.");
    prm.declare_entry("Box upper corner",
                      dim == 2 ? "1, 1" : "1, 1, 1",
                      Patterns::List(Patterns::Double(), dim, dim),
                      "Upper corner of the box.");
    prm.declare_entry("Subdivisions",
                      "",
                      Patterns::List(Patterns::Integer(1), 0, dim),
                      "Base (coarse) cells per direction, before refinement. "
                      "Empty: as many as give cells of aspect ratio one.");
    prm.leave_subsection();
  }

  void Geometry::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Geometry");
    type = prm.get("Type") == "channel" ? GeometryType::channel :
                                          GeometryType::box;
    streamwise_length = prm.get_double("Streamwise length");
    spanwise_length   = prm.get_double("Spanwise length");
    half_height       = prm.get_double("Half height");
    box_lower = to_doubles("Geometry/Box lower corner", prm.get("Box lower corner"));
    box_upper = to_doubles("Geometry/Box upper corner", prm.get("Box upper corner"));
    subdivisions.clear();
    for (const auto &s : split(prm.get("Subdivisions"), ','))
      subdivisions.push_back(Utilities::string_to_int(s));
    prm.leave_subsection();

    if (type == GeometryType::channel)
      {
        box_lower = {0., -half_height};
        box_upper = {streamwise_length, half_height};
        if (dim == 3)
          {
            box_lower = {0., 0., -half_height};
            box_upper = {streamwise_length, spanwise_length, half_height};
          }
      }
    for (unsigned int d = 0; d < dim; ++d)
      if (!(box_upper[d] > box_lower[d]))
        throw InputError("Geometry/Box upper corner",
                         "must exceed the lower corner in every direction");
    if (!subdivisions.empty() && subdivisions.size() != dim)
      throw InputError("Geometry/Subdivisions",
                       "give one count per direction (" + std::to_string(dim) +
                         ") or leave empty");
    subdivisions_given = !subdivisions.empty();
    if (subdivisions.empty())
      {
        double shortest = box_upper[0] - box_lower[0];
        for (unsigned int d = 1; d < dim; ++d)
          shortest = std::min(shortest, box_upper[d] - box_lower[d]);
        for (unsigned int d = 0; d < dim; ++d)
          subdivisions.push_back(static_cast<unsigned int>(
            std::max(1.0, std::round((box_upper[d] - box_lower[d]) / shortest))));
      }
  }

  // ------------------------------------------------------ BoundaryConditions
  BoundaryConditions::BoundaryConditions()
  {
    type.fill(BoundaryType::no_slip);
  }

  std::string BoundaryConditions::face_name(const unsigned int face)
  {
    static const char *names[] = {"x-", "x+", "y-", "y+", "z-", "z+"};
    return names[face];
  }

  void BoundaryConditions::declare(ParameterHandler &prm,
                                   const unsigned int dim)
  {
    prm.enter_subsection("Boundary conditions");
    prm.declare_entry("Function constants",
                      "",
                      Patterns::Anything(),
                      "Constants for the velocity expressions below, as "
                      "name=value pairs separated by commas.");
    for (unsigned int f = 0; f < 2 * dim; ++f)
      {
        prm.enter_subsection("Face " + face_name(f));
        prm.declare_entry("Type",
                          "no-slip",
                          Patterns::Selection("no-slip|velocity|periodic"),
                          "no-slip: u = 0; velocity: u given by 'Velocity'; "
                          "periodic: identified with the opposite face (both "
                          "must say so). Ignored for the channel's periodic "
                          "directions, which are always periodic.");
        prm.declare_entry("Velocity",
                          zero_vector(dim),
                          Patterns::Anything(),
                          "Velocity on this face when Type = velocity: one "
                          "expression of x, y[, z], t per component, "
                          "separated by ';'.");
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }

  void BoundaryConditions::parse(ParameterHandler &prm, const unsigned int dim)
  {
    prm.enter_subsection("Boundary conditions");
    const std::string constants = prm.get("Function constants");
    for (unsigned int f = 0; f < 2 * dim; ++f)
      {
        prm.enter_subsection("Face " + face_name(f));
        const std::string t = prm.get("Type");
        type[f] = t == "no-slip"  ? BoundaryType::no_slip :
                  t == "velocity" ? BoundaryType::velocity :
                                    BoundaryType::periodic;
        velocity[f] = {prm.get("Velocity"), constants};
        prm.leave_subsection();
        if (type[f] == BoundaryType::velocity)
          check_expression("Boundary conditions/Face " + face_name(f) +
                             "/Velocity",
                           velocity[f],
                           dim,
                           dim);
      }
    prm.leave_subsection();
    for (unsigned int d = 0; d < dim; ++d)
      if ((type[2 * d] == BoundaryType::periodic) !=
          (type[2 * d + 1] == BoundaryType::periodic))
        throw InputError("Boundary conditions/Face " + face_name(2 * d) +
                           "/Type",
                         "periodic faces come in pairs: set both " +
                           face_name(2 * d) + " and " + face_name(2 * d + 1) +
                           " to periodic");
  }
} // namespace Suspension::Parameters
