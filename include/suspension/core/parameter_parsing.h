#pragma once

#include <suspension/core/parameter_basics.h>

#include <string>
#include <vector>

/// Helpers shared by the areas' declare()/parse() functions (each area
/// parses its own subsections next to its code: scene, mesh, fluid, solid,
/// postprocess); not for use outside parameter parsing.
namespace Suspension::Parameters::Parsing
{
  /// The trimmed pieces of `s` between separators (none if `s` is blank).
  std::vector<std::string> split(const std::string &s, char sep);

  /// Comma-separated numbers; InputError naming `entry` if one is not.
  std::vector<double> to_doubles(const std::string &entry, const std::string &value);

  /// Throws InputError unless `f` parses as a function of x, y[, z], t with
  /// `n_components` components.
  void check_expression(const std::string        &entry,
                        const FunctionExpression &f,
                        unsigned int              n_components,
                        unsigned int              dim);

  /// "0; 0" or "0; 0; 0"
  std::string zero_vector(unsigned int dim);
} // namespace Suspension::Parameters::Parsing
