#pragma once

#include <deal.II/base/point.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>
#include <deal.II/base/vectorization.h>

#include <algorithm>
#include <cmath>

/// Small kernels of the DG transport shared by its parts (operator,
/// THINC reconstruction, limiter): not for use elsewhere.
namespace Suspension::Solid::internal
{
  using namespace dealii;

  using VA = VectorizedArray<double>;

  template <int dim>
  SymmetricTensor<2, dim, VA> to_tensor(const Tensor<1, dim * (dim + 1) / 2, VA> &b)
  {
    SymmetricTensor<2, dim, VA> B;
    for (unsigned int c = 0; c < b.dimension; ++c)
      B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)] = b[c];
    return B;
  }

  template <int dim>
  Tensor<1, dim * (dim + 1) / 2, VA> to_vector(const Tensor<2, dim, VA> &B)
  {
    Tensor<1, dim * (dim + 1) / 2, VA> b;
    for (unsigned int c = 0; c < b.dimension; ++c)
      b[c] = B[SymmetricTensor<2, dim>::unrolled_to_component_indices(c)];
    return b;
  }

  // A face point seen from the cell [lower, upper] in one coordinate: on
  // a periodic face it is given on the other side of the domain, a period
  // away, and its image is the cell's far face (x below the box is the
  // upper face, x above it the lower one); otherwise it lies on the box up
  // to round-off, and clamping removes that.
  inline double on_cell_face(const double x, const double lower, const double upper)
  {
    const double half = 0.5 * (upper - lower);
    if (x < lower - half)
      return upper;
    if (x > upper + half)
      return lower;
    return std::clamp(x, lower, upper);
  }

  // The argument a of the THINC profile r at x (a point of the cell, or of
  // one of its faces given across a periodic boundary).
  template <int dim, typename Reconstruction>
  double profile_argument(const Reconstruction &r, const Point<dim> &x)
  {
    double argument = r.offset;
    // for the curved profile: s = (x - centre) / h, n from the slope
    double s2 = 0., sn = 0., nn = 0.;
    for (unsigned int d = 0; d < dim; ++d)
      {
        const double y = on_cell_face(x[d], r.lower[d], r.upper[d]);
        argument += r.slope[d] * y;
        if (r.curvature == 0.)
          continue;
        const double h = r.upper[d] - r.lower[d];
        const double s = (y - 0.5 * (r.lower[d] + r.upper[d])) / h;
        s2 += s * s;
        sn += r.slope[d] * h * s;
        nn += r.slope[d] * h * r.slope[d] * h;
      }
    if (r.curvature != 0.)
      argument += r.curvature * (s2 - sn * sn / nn);
    return argument;
  }

  // The THINC profile r at x: p + w (H - p), H = 1/2 (1 + tanh a) with a
  // = profile_argument(r, x), p the DG value, w how much of the profile the
  // transport sees.
  template <int dim, typename Reconstruction>
  double profile_phi(const Reconstruction &r, const Point<dim> &x, const double dg_value)
  {
    const double argument = profile_argument(r, x);
    // 1/2 (1 + tanh a) = 1 / (1 + exp(-2a)): one exp, cheaper than
    // glibc's tanh (which goes through expm1)
    return dg_value + r.weight * (1. / (1. + std::exp(-2. * argument)) - dg_value);
  }

  // phi where the transport sees it: the cell's THINC profile at x in
  // the lanes that have one, the DG value elsewhere
  template <int dim, typename Lanes>
  VA seen_phi(const Lanes &profile, const Point<dim, VA> &x, const VA &dg_value)
  {
    VA out = dg_value;
    for (unsigned int v = 0; v < VA::size(); ++v)
      if (profile[v].weight > 0.)
        {
          Point<dim> x_v;
          for (unsigned int d = 0; d < dim; ++d)
            x_v[d] = x[d][v];
          out[v] = profile_phi(profile[v], x_v, dg_value[v]);
        }
    return out;
  }

  // whether some lane of a batch is marked (B transported there)
  inline bool any_lane(const VA &active)
  {
    for (unsigned int v = 0; v < VA::size(); ++v)
      if (active[v] > 0.)
        return true;
    return false;
  }

  // upwind flux of a transported quantity: un > 0 takes the inside value
  template <typename T>
  T upwind(const VA &un, const T &inside, const T &outside)
  {
    return 0.5 * un * (inside + outside) + 0.5 * std::abs(un) * (inside - outside);
  }
} // namespace Suspension::Solid::internal
