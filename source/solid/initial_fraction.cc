#include <deal.II/base/quadrature_lib.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/lac/full_matrix.h>

#include <suspension/core/scene.h>
#include <suspension/solid/initial_fraction.h>

#include <algorithm>
#include <cmath>
#include <functional>

namespace Suspension::Solid
{
  namespace
  {
    /// int sqrt(r^2 - x^2) dx. asin(x / r) would lose half the digits
    /// where |x| is close to r (a grid line tangent to the disc: 1.7e-9 of
    /// its area with 5 subdivisions of [-1, 1] and r = 0.2); the angle is
    /// taken from the chord instead.
    double half_chord_primitive(double x, const double r)
    {
      x              = std::clamp(x, -r, r);
      const double s = std::sqrt(std::max(0., (r - x) * (r + x)));
      return 0.5 * (x * s + r * r * std::atan2(x, s));
    }

    /// int_p^q |{y : |y| <= s(x), y <= Y}| dx with s(x) = sqrt(r^2 - x^2),
    /// -r <= p <= q <= r (the disc centred at the origin)
    double strip_below(const double p, const double q, const double Y, const double r)
    {
      if (q <= p || Y <= -r)
        return 0.;
      const auto S = [r](const double x) { return half_chord_primitive(x, r); };
      if (Y >= r)
        return 2. * (S(q) - S(p));
      // |x| < a: the chord is cut at Y (length Y + s); |x| > a: the whole
      // chord lies below Y (Y > 0) or above it (Y < 0)
      const double a     = std::sqrt(std::max(0., (r - Y) * (r + Y)));
      double       total = 0.;
      const double l = std::max(p, -a), u = std::min(q, a);
      if (u > l)
        total += Y * (u - l) + S(u) - S(l);
      if (Y > 0.)
        for (const auto &[lo, hi] : {std::pair{-r, -a}, std::pair{a, r}})
          {
            const double l2 = std::max(p, lo), u2 = std::min(q, hi);
            if (u2 > l2)
              total += 2. * (S(u2) - S(l2));
          }
      return total;
    }

    /// area of the disc (centre 0, radius r) in x <= X, y <= Y
    double quadrant_area(const double X, const double Y, const double r)
    {
      return strip_below(-r, std::clamp(X, -r, r), Y, r);
    }

    /// area of the disc (centre 0, radius r) in [x0, x1] x [y0, y1]
    double disc_rectangle(const double x0, const double x1, const double y0, const double y1,
                          const double r)
    {
      if (r <= 0. || x1 <= -r || x0 >= r || y1 <= -r || y0 >= r)
        return 0.;
      const double area = quadrant_area(x1, y1, r) - quadrant_area(x0, y1, r) -
                          quadrant_area(x1, y0, r) + quadrant_area(x0, y0, r);
      return std::clamp(area, 0., (x1 - x0) * (y1 - y0));
    }
  } // namespace

  template <int dim>
  double ball_box_intersection(const Point<dim> &c, const double r, const BoundingBox<dim> &box)
  {
    const auto  &lo = box.get_boundary_points().first;
    const auto  &hi = box.get_boundary_points().second;
    if constexpr (dim == 2)
      return disc_rectangle(lo[0] - c[0], hi[0] - c[0], lo[1] - c[1], hi[1] - c[1], r);
    else
      {
        const double x0 = lo[0] - c[0], x1 = hi[0] - c[0], y0 = lo[1] - c[1], y1 = hi[1] - c[1];
        const double z0 = std::max(lo[2] - c[2], -r), z1 = std::min(hi[2] - c[2], r);
        if (z1 <= z0)
          return 0.;
        // z = r sin(theta): the slice radius r cos(theta) is smooth in theta;
        // the slice area changes its form where that radius equals the
        // distance to a side or a corner of the box
        const double        ta = std::asin(z0 / r), tb = std::asin(z1 / r);
        std::vector<double> breaks = {ta, tb};
        const auto add_break = [&](const double theta) {
          if (theta > ta && theta < tb)
            breaks.push_back(theta);
        };
        add_break(0.); // the slice radius is largest there
        for (const double d : {x0, x1, y0, y1, std::hypot(x0, y0), std::hypot(x0, y1),
                               std::hypot(x1, y0), std::hypot(x1, y1)})
          if (std::abs(d) < r)
            {
              add_break(std::acos(std::abs(d) / r));
              add_break(-std::acos(std::abs(d) / r));
            }
        std::sort(breaks.begin(), breaks.end());
        static const QGauss<1> gauss(12);
        double                 volume = 0.;
        for (unsigned int s = 0; s + 1 < breaks.size(); ++s)
          {
            const double a = breaks[s], b = breaks[s + 1];
            for (unsigned int q = 0; q < gauss.size(); ++q)
              {
                const double theta = a + (b - a) * gauss.point(q)[0];
                const double rho   = r * std::cos(theta);
                // dz = r cos(theta) dtheta = rho dtheta
                volume += gauss.weight(q) * (b - a) * disc_rectangle(x0, x1, y0, y1, rho) * rho;
              }
          }
        return std::clamp(volume, 0., box.volume());
      }
  }

  namespace
  {
    /// The sharp shape: membership of a point, and of a box where it can be
    /// decided (1 inside, 0 outside, -1 cut or unknown).
    template <int dim>
    struct SharpShape
    {
      std::function<double(const Point<dim> &)>        value;
      std::function<int(const BoundingBox<dim> &)>     classify;
      std::function<double(const BoundingBox<dim> &)> exact_measure; // null: none
      unsigned int                                     max_depth = 0;
    };

    /// the particles of the scene and those of their periodic images that
    /// reach into the box
    template <int dim>
    std::vector<std::pair<Point<dim>, double>> particle_images(const Parameters::All &p)
    {
      std::vector<std::pair<Point<dim>, double>> images;
      const auto &g = p.geometry;
      for (const auto &particle : p.solid.particles)
        {
          Point<dim> c;
          for (unsigned int d = 0; d < dim; ++d)
            c[d] = particle[d];
          const double r = particle[dim];
          for (unsigned int shift = 0; shift < Utilities::pow(3u, dim); ++shift)
            {
              Point<dim> image = c;
              bool       keep  = true;
              unsigned int code = shift;
              for (unsigned int d = 0; d < dim; ++d, code /= 3)
                {
                  const int k = int(code % 3) - 1;
                  if (k == 0)
                    continue;
                  if (p.boundary_conditions.type[2 * d] != Parameters::BoundaryType::periodic)
                    keep = false;
                  image[d] += k * (g.box_upper[d] - g.box_lower[d]);
                  keep = keep && image[d] + r > g.box_lower[d] && image[d] - r < g.box_upper[d];
                }
              if (keep)
                images.emplace_back(image, r);
            }
        }
      return images;
    }

    template <int dim>
    double distance_to_box(const Point<dim> &x, const BoundingBox<dim> &box, const bool farthest)
    {
      double d2 = 0.;
      for (unsigned int d = 0; d < dim; ++d)
        {
          const double lo = box.get_boundary_points().first[d] - x[d];
          const double hi = box.get_boundary_points().second[d] - x[d];
          const double e  = farthest ? std::max(std::abs(lo), std::abs(hi)) :
                                       (lo > 0 ? lo : (hi < 0 ? -hi : 0.));
          d2 += e * e;
        }
      return std::sqrt(d2);
    }
  } // namespace

  namespace
  {
    /// fraction of the box [lower, upper] in which the indicator is 1: in 2D
    /// the polygon of the corners inside and of the points where the
    /// indicator changes along the edges (found by bisection), exact for a
    /// straight interface and O(size^3 curvature) otherwise; in 3D the same
    /// on the slices at Gauss points of the height
    /// `straight` (2D) is set to false where the interface is not one
    /// straight segment in the box: more than two edge crossings, or the points
    /// just either side of the middle of the chord between them on the same
    /// side (a corner of the shape inside the box, which the polygon cuts off).
    template <int dim>
    double indicator_fraction(const std::function<double(const Point<dim> &)> &value,
                              const Point<dim> &lower, const Point<dim> &upper,
                              bool &straight)
    {
      straight = true;
      const auto slice_fraction = [&](const auto &at) {
        // at(s, t): the point of the xy-slice at local coordinates s, t in [0, 1]
        const std::array<std::array<double, 2>, 4> corner = {{{0., 0.}, {1., 0.}, {1., 1.}, {0., 1.}}};
        std::array<bool, 4> in;
        for (unsigned int i = 0; i < 4; ++i)
          in[i] = value(at(corner[i][0], corner[i][1])) > 0.5;
        std::vector<std::array<double, 2>> polygon, crossings;
        for (unsigned int i = 0; i < 4; ++i)
          {
            const auto &a = corner[i], &b = corner[(i + 1) % 4];
            if (in[i])
              polygon.push_back(a);
            if (in[i] != in[(i + 1) % 4])
              {
                double lo = 0., hi = 1.;
                for (unsigned int k = 0; k < 40; ++k)
                  {
                    const double m = 0.5 * (lo + hi);
                    if ((value(at(a[0] + m * (b[0] - a[0]), a[1] + m * (b[1] - a[1]))) > 0.5) == in[i])
                      lo = m;
                    else
                      hi = m;
                  }
                const double m = 0.5 * (lo + hi);
                polygon.push_back({a[0] + m * (b[0] - a[0]), a[1] + m * (b[1] - a[1])});
                crossings.push_back(polygon.back());
              }
          }
        if (crossings.size() > 2)
          straight = false; // two pieces of interface
        else if (crossings.size() == 2)
          {
            constexpr double delta = 1e-3; // of the box
            const auto &a = crossings[0], &b = crossings[1];
            const double length = std::hypot(b[0] - a[0], b[1] - a[1]);
            const double nx = -(b[1] - a[1]) / length, ny = (b[0] - a[0]) / length;
            const double mx = 0.5 * (a[0] + b[0]), my = 0.5 * (a[1] + b[1]);
            if ((value(at(mx + delta * nx, my + delta * ny)) > 0.5) ==
                (value(at(mx - delta * nx, my - delta * ny)) > 0.5))
              straight = false;
          }
        double area = 0.;
        for (unsigned int i = 0; i < polygon.size(); ++i)
          {
            const auto &a = polygon[i], &b = polygon[(i + 1) % polygon.size()];
            area += a[0] * b[1] - b[0] * a[1];
          }
        return std::clamp(0.5 * area, 0., 1.);
      };
      const auto point = [&](const double s, const double t, const double z) {
        Point<dim> x;
        x[0] = lower[0] + s * (upper[0] - lower[0]);
        x[1] = lower[1] + t * (upper[1] - lower[1]);
        if constexpr (dim == 3)
          x[2] = lower[2] + z * (upper[2] - lower[2]);
        return x;
      };
      if constexpr (dim == 2)
        return slice_fraction([&](double s, double t) { return point(s, t, 0.); });
      else
        {
          // the corners within the slices are not looked for: straight
          static const QGauss<1> gauss(4);
          double                 fraction = 0.;
          for (unsigned int q = 0; q < gauss.size(); ++q)
            fraction += gauss.weight(q) * slice_fraction([&](double s, double t) {
                          return point(s, t, gauss.point(q)[0]);
                        });
          straight = true;
          return fraction;
        }
    }
  } // namespace

  template <int dim>
  InitialFractionReport project_initial_fraction(const Parameters::All &p,
                                                 const DoFHandler<dim> &dof_handler,
                                                 VectorType            &solution)
  {
    const FiniteElement<dim> &fe     = dof_handler.get_fe();
    const FiniteElement<dim> &scalar = fe.base_element(0);
    const unsigned int        n      = scalar.n_dofs_per_cell();

    SharpShape<dim> shape;
    std::unique_ptr<Function<dim>> expression;
    std::vector<std::pair<Point<dim>, double>> images;
    if (p.solid.initial_fraction == Parameters::InitialFraction::function)
      {
        expression      = make_function<dim>({p.solid.fraction_expression, p.solid.constants}, 1);
        shape.value     = [&](const Point<dim> &x) { return expression->value(x); };
        // A box is decided (0 or 1) only if the indicator agrees on a
        // lattice over the box widened by a quarter of its size on each
        // side, and cut (-1) if it takes both values there: a sliver of the
        // shape that crosses the box near its boundary, between the Gauss
        // points, is seen from the lattice or its halo (before: up to 9e-4
        // of the slotted disc's area was missed). Other values: a smooth
        // expression (-2), integrated by the Gauss rules.
        shape.classify = [&](const BoundingBox<dim> &box) {
          constexpr unsigned int m = dim == 2 ? 8 : 4;
          const Point<dim>       lower = box.get_boundary_points().first;
          const Tensor<1, dim>   size  = box.get_boundary_points().second - lower;
          bool zero = false, one = false, other = false;
          for (unsigned int k = 0; k < Utilities::fixed_power<dim>(m + 1); ++k)
            {
              Point<dim>   x;
              unsigned int index = k;
              for (unsigned int d = 0; d < dim; ++d, index /= (m + 1))
                x[d] = lower[d] + size[d] * (-0.25 + 1.5 * (index % (m + 1)) / m);
              const double v = expression->value(x);
              zero           = zero || v == 0.;
              one            = one || v == 1.;
              other          = other || (v != 0. && v != 1.);
            }
          return other ? -2 : (zero && one ? -1 : (one ? 1 : 0));
        };
        shape.max_depth = dim == 2 ? 8 : 3;
      }
    else
      {
        images      = particle_images<dim>(p);
        shape.value = [&](const Point<dim> &x) {
          for (const auto &[c, r] : images)
            if (x.distance_square(c) <= r * r)
              return 1.;
          return 0.;
        };
        shape.classify = [&](const BoundingBox<dim> &box) {
          for (const auto &[c, r] : images)
            {
              if (distance_to_box(c, box, true) <= r)
                return 1;
              if (distance_to_box(c, box, false) < r)
                return -1;
            }
          return 0;
        };
        shape.exact_measure = [&](const BoundingBox<dim> &box) {
          double measure = 0.;
          for (const auto &[c, r] : images)
            if (distance_to_box(c, box, false) < r)
              measure += ball_box_intersection(c, r, box);
          return std::min(measure, box.volume());
        };
        shape.max_depth = dim == 2 ? 4 : 2;
      }

    // reference mass matrix of the scalar element, its inverse, and the
    // integrals of the shape functions
    const QGauss<dim> leaf(scalar.degree + 2);
    FullMatrix<double> mass(n, n), inverse_mass(n, n);
    Vector<double>     shape_integral(n);
    {
      const QGauss<dim> q(scalar.degree + 1);
      for (unsigned int k = 0; k < q.size(); ++k)
        for (unsigned int i = 0; i < n; ++i)
          {
            shape_integral[i] += q.weight(k) * scalar.shape_value(i, q.point(k));
            for (unsigned int j = 0; j < n; ++j)
              mass(i, j) += q.weight(k) * scalar.shape_value(i, q.point(k)) *
                            scalar.shape_value(j, q.point(k));
          }
      inverse_mass.invert(mass);
    }

    InitialFractionReport report;
    std::vector<types::global_dof_index> dofs(fe.n_dofs_per_cell());
    Vector<double> load(n), coefficients(n);
    std::vector<double> samples(leaf.size());
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const BoundingBox<dim> box = cell->bounding_box();
          const Point<dim>       lower = box.get_boundary_points().first;
          Tensor<1, dim>         size  = box.get_boundary_points().second - lower;
          const int              kind  = shape.classify(box);
          cell->get_dof_indices(dofs);
          if (kind >= 0)
            {
              for (unsigned int i = 0; i < n; ++i)
                solution(dofs[fe.component_to_system_index(0, i)]) = kind;
              continue;
            }
          // load_i = int_cell chi phi_i / |cell| on the reference cell, by
          // Gauss rules on the sub-boxes that the shape cuts
          load = 0.;
          double quadrature_mean = 0.;
          const std::function<void(const Point<dim> &, double, unsigned int)> integrate =
            [&](const Point<dim> &unit_lower, const double unit_size, const unsigned int depth) {
              Point<dim> real_lower, real_upper;
              for (unsigned int d = 0; d < dim; ++d)
                {
                  real_lower[d] = lower[d] + size[d] * unit_lower[d];
                  real_upper[d] = real_lower[d] + size[d] * unit_size;
                }
              const int k = shape.classify(BoundingBox<dim>({real_lower, real_upper}));
              if (k == 0)
                return;
              double lo = 1e300, hi = -1e300;
              for (unsigned int q = 0; q < leaf.size(); ++q)
                {
                  Point<dim> x;
                  for (unsigned int d = 0; d < dim; ++d)
                    x[d] = real_lower[d] + (real_upper[d] - real_lower[d]) * leaf.point(q)[d];
                  samples[q] = k == 1 ? 1. : shape.value(x);
                  lo         = std::min(lo, samples[q]);
                  hi         = std::max(hi, samples[q]);
                }
              // the moments are good enough from the Gauss points; the mean
              // of an indicator that changes in the box is not
              const bool indicator = std::all_of(samples.begin(), samples.end(), [](const double v) {
                return v == 0. || v == 1.;
              });
              // an indicator changes in this sub-box: bisect; below the
              // last level, only where the shape has a corner in it (up to
              // 2^-8 of the last level's size: a corner cut off there is
              // ~1e-10 of the cell)
              const bool cut      = k == -1 || (k == -2 && hi - lo > 0.5);
              bool       straight = true;
              double     fraction = 0.;
              const bool polygon  = cut && !shape.exact_measure && indicator;
              if (polygon && depth >= shape.max_depth)
                fraction = indicator_fraction<dim>(shape.value, real_lower, real_upper, straight);
              if (cut && (depth < shape.max_depth || (!straight && depth < shape.max_depth + 8)))
                {
                  for (unsigned int child = 0; child < GeometryInfo<dim>::max_children_per_cell; ++child)
                    {
                      Point<dim> child_lower = unit_lower;
                      for (unsigned int d = 0; d < dim; ++d)
                        if (child & (1u << d))
                          child_lower[d] += 0.5 * unit_size;
                      integrate(child_lower, 0.5 * unit_size, depth + 1);
                    }
                  return;
                }
              const double measure = Utilities::fixed_power<dim>(unit_size);
              double       mean    = 0.;
              for (unsigned int q = 0; q < leaf.size(); ++q)
                {
                  if (samples[q] == 0.)
                    continue;
                  Point<dim> unit = unit_lower;
                  for (unsigned int d = 0; d < dim; ++d)
                    unit[d] += unit_size * leaf.point(q)[d];
                  const double w = leaf.weight(q) * measure * samples[q];
                  mean += w;
                  for (unsigned int i = 0; i < n; ++i)
                    load[i] += w * scalar.shape_value(i, unit);
                }
              if (polygon)
                mean = measure * fraction;
              quadrature_mean += mean;
            };
          integrate(Point<dim>(), 1., 0);
          inverse_mass.vmult(coefficients, load);
          const double exact = shape.exact_measure ? shape.exact_measure(box) / box.volume() :
                                                     quadrature_mean;
          if (exact > 0. && exact < 1.)
            ++report.cut_cells;
          // the Lagrange basis sums to one: a constant shift sets the mean
          const double shift = exact - (coefficients * shape_integral);
          for (unsigned int i = 0; i < n; ++i)
            solution(dofs[fe.component_to_system_index(0, i)]) = coefficients[i] + shift;
        }
    if (shape.exact_measure)
      {
        Point<dim> lo, hi;
        for (unsigned int d = 0; d < dim; ++d)
          {
            lo[d] = p.geometry.box_lower[d];
            hi[d] = p.geometry.box_upper[d];
          }
        for (const auto &[c, r] : images)
          report.exact_volume += ball_box_intersection(c, r, BoundingBox<dim>({lo, hi}));
      }
    const MPI_Comm comm      = dof_handler.get_communicator();
    report.cut_cells          = Utilities::MPI::sum(report.cut_cells, comm);
    return report;
  }

  template double ball_box_intersection(const Point<2> &, double, const BoundingBox<2> &);
  template double ball_box_intersection(const Point<3> &, double, const BoundingBox<3> &);
  template InitialFractionReport project_initial_fraction(const Parameters::All &,
                                                          const DoFHandler<2> &, VectorType &);
  template InitialFractionReport project_initial_fraction(const Parameters::All &,
                                                          const DoFHandler<3> &, VectorType &);
} // namespace Suspension::Solid
