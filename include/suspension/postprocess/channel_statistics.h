#pragma once

#include <suspension/solid/stress_weight.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/la_parallel_vector.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/momentum_source.h>
#include <suspension/postprocess/stationarity.h>

#include <array>
#include <iosfwd>
#include <string>
#include <vector>

namespace Suspension::Postprocess
{
  using namespace dealii;

  /// The solid fields a sample reads: phi, then (if G > 0) B in
  /// SymmetricTensor unrolled order, one DG FESystem on the fluid's mesh.
  template <int dim>
  struct SolidFields
  {
    const DoFHandler<dim>                            &dof_handler;
    const LinearAlgebra::distributed::Vector<double> &solution;
    double                                            shear_modulus;
    Solid::StressWeight                               weight; // stress G H(phi) (B - I)
  };

  /// Mean over samples (Welford's update, stable where the samples hardly
  /// differ); the error of the mean is BlockedError's, from the series.
  struct RunningMean
  {
    unsigned long n    = 0;
    double        mean = 0., m2 = 0.;

    void add(double x);
  };

  /**
   * Statistics of a channel flow -h < y < h (y the wall-normal, last
   * coordinate; x streamwise; z spanwise in 3D, the second coordinate),
   * sampled every few steps and averaged over the samples s = 1..S.
   *
   * Planes are approximated by bins: the channel is cut into 'Number of
   * bins' slabs of equal width, and each Gauss point of a sample's
   * quadrature (velocity degree + 1 points per direction) adds its weight
   * to the slab that holds its y. The plane mean of a sample is
   *   [f]_s(y_k) = int_{bin k} f dV / |bin k|,
   * and <.> the mean over samples of [.]_s. Velocity fluctuations are
   * taken about the sample's plane mean as a function of y, the
   * least-squares fit U_s(y) = a + b t + c t^2 over each bin (t the
   * position in the bin): u' = u - U_s(y), so that the mean shear across
   * a bin is not counted as a fluctuation (exact for a parabolic profile;
   * lower degrees where a bin holds fewer than three rows of points).
   * Profiles are folded onto the lower half: even
   * quantities as (f(y) + f(-y)) / 2, odd ones (v and the shear stresses)
   * as (f(y) - f(-y)) / 2, reported at the mean y of the bin's points.
   *
   * Shear-stress budget (the momentum balance averaged over time and
   * planes, Pi = <-dp/dx> the mean driving force):
   *   tau_visc  = <mu du/dy>              (at the Gauss points)
   *   tau_Re    = -rho <u'v'>
   *   tau_el    = <G phi B_xy>
   *   tau_coll  = int_{-h}^{y} <f_x> dy'  (f the contact force density)
   *   tau_total = sum of the four, which must equal -Pi y:
   *               Pi h at the lower wall, 0 at the centre line.
   * The bulk budget is the volume average of each over the folded half
   * channel, also as a fraction of the average of tau_total.
   *
   * Bulk rheology per sample, then mean and standard error over samples
   * (samples are correlated in time: the error is the blocking estimate,
   * BlockedError, from the series of samples kept for it):
   *   mu_eff / mu = Pi_s / (3 mu V_s / h^2), V_s the sample's bulk velocity,
   *   N1 = <sigma_xx - sigma_yy>_V = <G phi (B_xx - B_yy) + 2 mu (du/dx - dv/dy)>_V,
   *   N2 = <sigma_yy - sigma_zz>_V = <G phi (B_yy - B_zz) + 2 mu (dv/dy - dw/dz)>_V,
   * in 2D with B_zz = 1 and dw/dz = 0 (plane strain).
   *
   * Stationarity ('Steady state window' > 0): every sample also feeds a
   * SteadyStateDetector with mu_eff and the solid's mean distance from
   * the walls, int phi (h - |y|) / int phi (the migration); when both stop
   * drifting all sums start again, so that the result covers the steady
   * state only, and complete() tells the run when 'Sampling time' of it
   * has been collected.
   *
   * The sums are MPI-reduced at every sample, so every rank holds them;
   * write() writes on rank 0 only.
   */
  template <int dim>
  class ChannelStatistics
  {
  public:
    ChannelStatistics(const Parameters::All &parameters, MPI_Comm communicator);

    /// From 'Start time' on, every 'Sample interval' steps.
    bool due(double time, unsigned int step) const;

    /// One sample of the current state. `solid` and `collision` may be
    /// nullptr (no solid phase, no contact force); `collision` must add
    /// forces only (has_stress() false).
    void sample(const Fluid::FluidSpace<dim>        &space,
                const Fluid::VectorType             &velocity,
                double                               time,
                double                               driving_force,
                const SolidFields<dim>              *solid,
                const Fluid::MomentumSource<dim>    *collision);

    unsigned int n_samples() const { return n_sampled; }

    /// Steady, and 'Sampling time' (if set) covered since.
    bool complete() const;

    /// profiles.txt, rheology.txt, stationarity.txt and samples.txt (the
    /// per-sample bulk values of the steady part) in `directory` (rank 0
    /// only).
    void write(const std::string &directory) const;

    /// A few rounded lines for the screen; with tolerance > 0 and an
    /// unladen channel, the deviations from laminar flow and verdicts.
    void print_summary(std::ostream &out, double tolerance, bool unladen) const;

    /// The accumulated sums, as text with full precision (checkpoints).
    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    /// Folded profiles on the lower half (bins 0..n/2-1, from the wall).
    struct Profiles
    {
      std::vector<double> volume, y, u, v, phi, u_rms, v_rms, w_rms, linear;
      /// viscous, Reynolds, elastic, collision, total
      std::array<std::vector<double>, 5> stress;
    };

    /// Folds per-bin means (one sample's, or the mean over samples).
    Profiles fold(const std::vector<std::vector<double>> &means, double driving_force) const;
    double   half_channel_mean(const Profiles &p, unsigned int stress) const;
    /// max |tau_total - tau_linear| / (Pi h)
    double   linear_deviation(const Profiles &p) const;
    /// the mean over samples
    Profiles profiles() const;
    /// every sum and mean back to no samples (the flow became steady)
    void     restart_sums();
    /// the standard error of one bulk quantity's mean (see `series`)
    double   error(unsigned int quantity) const;
    /// one line: steady from when, by what criterion, or why not
    std::string stationarity() const;

    const Parameters::All &parameters;
    MPI_Comm               communicator;
    const double           h;
    const unsigned int     n_bins;

    /// Per bin, sums over samples of the sample's plane means and
    /// fluctuation covariances (see the enum in the .cc file).
    std::vector<std::vector<double>> sums;
    unsigned int                     n_sampled  = 0;
    double                           first_time = 0., last_time = 0.;
    /// most cells cut by a bin boundary in any sample (0: bins fit the mesh)
    unsigned long long               straddling_cells = 0;
    RunningMean                      driving, viscosity_ratio, n1, n2;
    /// per-sample folded half-channel budget: viscous, Reynolds, elastic,
    /// collision, total
    std::vector<RunningMean> budget;
    /// per sample: driving force, mu_eff/mu, N1, N2, the five budget terms
    /// (for the correlated error)
    std::vector<std::vector<double>> series;
    std::vector<double>              sample_times;
    SteadyStateDetector              steadiness;
  };
} // namespace Suspension::Postprocess
