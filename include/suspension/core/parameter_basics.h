#pragma once

#include <map>
#include <stdexcept>
#include <string>

/// What every area's parameters share: the input error and function
/// expressions (see parameters.h for the conventions).
namespace Suspension::Parameters
{
  /// A parse error in the user's input: which entry, and what is wrong.
  struct InputError : std::runtime_error
  {
    InputError(const std::string &entry, const std::string &message)
      : std::runtime_error("entry '" + entry + "': " + message)
    {}
  };

  /// A function expression with its constants; the variables are
  /// x, y[, z], t. Components are separated by ';'.
  struct FunctionExpression
  {
    std::string expression;
    std::string constants;
    std::map<std::string, double> constant_map() const;
    bool        is_zero() const;
  };

  /// Variable names for function expressions: "x,y,t" or "x,y,z,t".
  std::string variable_names(unsigned int dim);
} // namespace Suspension::Parameters
