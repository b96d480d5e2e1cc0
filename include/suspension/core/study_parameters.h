#pragma once

#include <deal.II/base/parameter_handler.h>

#include <string>
#include <vector>

/// 'Study' (core/study_cases.cc).
namespace Suspension::Parameters
{
  using dealii::ParameterHandler;

  enum class StudyCases
  {
    grid,  // every Re x Ca x Phi
    paper  // the paper's seven (Re, Ca) pairs x Phi
  };

  /// A study of cases that differ in Re, Ca and Phi (scripts/study); the
  /// scene itself is the base case. Declared and parsed in
  /// core/study_cases.cc, next to the code that turns it into cases.
  struct Study
  {
    StudyCases          cases = StudyCases::grid;
    std::vector<double> reynolds_numbers, capillary_numbers, volume_fractions;
    std::string         directory = "output/study";
    unsigned int        ranks_per_case = 1;

    static void declare(ParameterHandler &prm);
    void        parse(ParameterHandler &prm);
  };
} // namespace Suspension::Parameters
