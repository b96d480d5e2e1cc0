#pragma once

/// The layout of ChannelStatistics' per-bin sums and bulk budget, shared by
/// its sampling (channel_statistics.cc) and its output
/// (channel_statistics_output.cc); not for use elsewhere.
namespace Suspension::Postprocess::ChannelLayout
{
  /// What a sample integrates per bin; the first n_stored are summed over
  /// samples as the sample's bin means (uu..uv then hold the covariances
  /// of the fluctuations, see fluctuations()). t = (y - y_bin) / (width/2).
  enum Quantity : unsigned int
  {
    volume, // integral (not a mean): |bin|
    y,
    u,
    v,
    w,
    uu,
    vv,
    ww,
    uv,
    phi,
    viscous, // mu du/dy
    elastic, // G phi B_xy
    force_x, // contact force density
    n_stored,
    t1 = n_stored, // moments of t for the fit of the mean profile
    t2,
    t3,
    t4,
    ut1,
    ut2,
    vt1,
    vt2,
    wt1,
    wt2,
    n_integrated
  };

  enum Budget : unsigned int
  {
    b_viscous,
    b_reynolds,
    b_elastic,
    b_collision,
    b_total,
    n_budget
  };

  inline constexpr const char *budget_names[n_budget] = {"viscous", "Reynolds", "elastic",
                                                         "collision", "total"};
} // namespace Suspension::Postprocess::ChannelLayout
