#pragma once

#include <suspension/core/parameters.h>

#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

namespace Suspension
{
  /**
   * One case of a study: the paper's dimensionless numbers and the entries
   * of the base scene that realise them. With the base scene's h, V_b, rho
   * and particle radius r (h = `Geometry/Half height`, V_b = `Flow
   * driving/Bulk velocity`):
   *   gdot = 3 V_b / (2 h)                (the unladen profile-averaged shear rate)
   *   mu   = rho gdot r^2 / Re            (`Material/Viscosity`)
   *   G    = mu gdot / Ca                 (`Solid/Shear modulus`)
   *   Phi                                 (`Solid/Seeding/Volume fraction`)
   * and the case's own `Output/Directory` under `Study/Directory`.
   */
  struct StudyCase
  {
    std::string                                      name; // Re3.75_Ca0.3_Phi0.1
    double                                           reynolds = 0., capillary = 0., volume_fraction = 0.;
    std::vector<std::pair<std::string, std::string>> entries; // --set Section/Entry=value
  };

  /// The cases of `parameters.study` on the base scene `parameters`;
  /// InputError (naming the entry) if the base is not a suspension in a
  /// channel at constant flow rate or the lists are empty.
  std::vector<StudyCase> study_cases(const Parameters::All &parameters);

  /// The cases as JSON (what scripts/study reads).
  void write_study_cases(std::ostream &out, const Parameters::All &parameters,
                         const std::vector<StudyCase> &cases);
} // namespace Suspension
