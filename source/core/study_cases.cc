#include <deal.II/base/utilities.h>

#include <suspension/core/study_cases.h>

#include <iomanip>
#include <ostream>
#include <sstream>

namespace Suspension
{
  using namespace dealii;

  namespace
  {
    /// The paper's table of cases (Rosti & Brandt): (Re, Ca) pairs, each
    /// at every volume fraction; Re = 3.75 first, which most of its
    /// figures show, so that a study cut short has them.
    const std::pair<double, double> paper_pairs[] = {
      {3.75, 0.3}, {3.75, 0.009}, {3.75, 0.075}, {0.45, 0.3}, {0.45, 0.009}, {7.5, 0.3}, {7.5, 0.15}};

    std::string shortest(const double x)
    {
      std::ostringstream s;
      s << std::setprecision(12) << x;
      return s.str();
    }

    std::vector<double> numbers(ParameterHandler &prm, const std::string &entry)
    {
      std::vector<double> out;
      for (const auto &piece : Utilities::split_string_list(prm.get(entry), ','))
        out.push_back(Utilities::string_to_double(piece));
      return out;
    }

    std::string json_string(const std::string &s)
    {
      std::string out = "\"";
      for (const char c : s)
        {
          if (c == '"' || c == '\\')
            out += '\\';
          out += c;
        }
      return out + "\"";
    }
  } // namespace

  namespace Parameters
  {
    void Study::declare(ParameterHandler &prm)
    {
      const Study d;
      prm.enter_subsection("Study");
      prm.declare_entry("Cases", "grid", Patterns::Selection("grid|paper"),
                        "Which cases scripts/study runs on this scene (the "
                        "base case): grid = every combination of 'Reynolds "
                        "numbers', 'Capillary numbers' and 'Volume fractions'; "
                        "paper = the paper's seven (Re, Ca) pairs (Re = 7.5: "
                        "Ca = 0.15, 0.3; Re = 3.75: Ca = 0.009, 0.075, 0.3; "
                        "Re = 0.45: Ca = 0.009, 0.3), each at every volume "
                        "fraction. Re = rho gdot r^2/mu and Ca = mu gdot/G with "
                        "gdot = 3 V_b/(2h) set 'Material/Viscosity' and "
                        "'Solid/Shear modulus'; Phi sets 'Solid/Seeding/Volume "
                        "fraction'. A single run of the scene ignores this "
                        "subsection.");
      prm.declare_entry("Reynolds numbers", "", Patterns::List(Patterns::Double(0.), 0),
                        "Particle Reynolds numbers rho gdot r^2 / mu (grid).");
      prm.declare_entry("Capillary numbers", "", Patterns::List(Patterns::Double(0.), 0),
                        "Capillary numbers mu gdot / G (grid).");
      prm.declare_entry("Volume fractions", "", Patterns::List(Patterns::Double(0., 1.), 0),
                        "Solid volume fractions Phi of the seeded particles.");
      prm.declare_entry("Directory", d.directory, Patterns::Anything(),
                        "Each case writes to Directory/Re<Re>_Ca<Ca>_Phi<Phi>/ "
                        "(relative to where scripts/study runs); the study's "
                        "table and figures go to Directory itself.");
      prm.declare_entry("Ranks per case", std::to_string(d.ranks_per_case),
                        Patterns::Integer(1),
                        "MPI ranks of one case; scripts/study runs as many "
                        "cases at once as the cores allow (cores / ranks).");
      prm.leave_subsection();
    }

    void Study::parse(ParameterHandler &prm)
    {
      prm.enter_subsection("Study");
      cases             = prm.get("Cases") == "paper" ? StudyCases::paper : StudyCases::grid;
      reynolds_numbers  = numbers(prm, "Reynolds numbers");
      capillary_numbers = numbers(prm, "Capillary numbers");
      volume_fractions  = numbers(prm, "Volume fractions");
      directory         = prm.get("Directory");
      ranks_per_case    = prm.get_integer("Ranks per case");
      prm.leave_subsection();
    }
  } // namespace Parameters

  std::vector<StudyCase> study_cases(const Parameters::All &p)
  {
    using Parameters::InputError;
    const auto &s = p.study;
    if (p.geometry.type != Parameters::GeometryType::channel)
      throw InputError("Geometry/Type", "a study runs channel scenes ('channel')");
    if (p.flow_driving.type != Parameters::FlowDrivingType::constant_flow_rate)
      throw InputError("Flow driving/Type",
                       "a study defines Re by the bulk velocity: 'constant flow rate'");
    if (!p.solid.seeded) // read() turned the random particles into explicit ones
      throw InputError("Solid/Initial fraction",
                       "a study seeds its particles: 'random particles'");
    if (s.volume_fractions.empty())
      throw InputError("Study/Volume fractions", "no volume fraction given");
    std::vector<std::pair<double, double>> pairs;
    if (s.cases == Parameters::StudyCases::paper)
      pairs.assign(std::begin(paper_pairs), std::end(paper_pairs));
    else
      {
        if (s.reynolds_numbers.empty())
          throw InputError("Study/Reynolds numbers", "no Reynolds number given (Cases = grid)");
        if (s.capillary_numbers.empty())
          throw InputError("Study/Capillary numbers", "no capillary number given (Cases = grid)");
        for (const double re : s.reynolds_numbers)
          for (const double ca : s.capillary_numbers)
            pairs.emplace_back(re, ca);
      }
    for (const auto &[re, ca] : pairs)
      if (!(re > 0) || !(ca > 0))
        throw InputError(re > 0 ? "Study/Capillary numbers" : "Study/Reynolds numbers",
                         "must be positive");

    const double rho   = p.material.density;
    const double r     = p.solid.seeding.radius;
    const double gdot  = 3. * p.flow_driving.bulk_velocity / (2. * p.geometry.half_height);
    std::vector<StudyCase> cases;
    for (const auto &[re, ca] : pairs)
      for (const double phi : s.volume_fractions)
        {
          StudyCase c;
          c.reynolds        = re;
          c.capillary       = ca;
          c.volume_fraction = phi;
          c.name = "Re" + shortest(re) + "_Ca" + shortest(ca) + "_Phi" + shortest(phi);
          const double mu   = rho * gdot * r * r / re;
          const double G    = mu * gdot / ca;
          c.entries         = {{"Material/Viscosity", shortest(mu)},
                               {"Solid/Shear modulus", shortest(G)},
                               {"Solid/Seeding/Volume fraction", shortest(phi)},
                               {"Output/Directory", s.directory + "/" + c.name}};
          cases.push_back(c);
        }
    return cases;
  }

  void write_study_cases(std::ostream &out, const Parameters::All &p,
                         const std::vector<StudyCase> &cases)
  {
    out << "{\"directory\": " << json_string(p.study.directory)
        << ", \"ranks_per_case\": " << p.study.ranks_per_case
        << ", \"end_time\": " << shortest(p.time_stepping.end_time) << ", \"cases\": [";
    for (unsigned int i = 0; i < cases.size(); ++i)
      {
        const auto &c = cases[i];
        out << (i > 0 ? "," : "") << "\n  {\"name\": " << json_string(c.name)
            << ", \"Re\": " << shortest(c.reynolds) << ", \"Ca\": " << shortest(c.capillary)
            << ", \"Phi\": " << shortest(c.volume_fraction) << ", \"set\": {";
        for (unsigned int e = 0; e < c.entries.size(); ++e)
          out << (e > 0 ? ", " : "") << json_string(c.entries[e].first) << ": "
              << json_string(c.entries[e].second);
        out << "}}";
      }
    out << "\n]}\n";
  }
} // namespace Suspension
