#pragma once

#include <deal.II/distributed/tria.h>

#include <suspension/core/parameters.h>
#include <suspension/fluid/fluid_space.h>
#include <suspension/fluid/fluid_operators.h>
#include <suspension/solid/solid_phase.h>

#include <iosfwd>
#include <memory>
#include <vector>

namespace Suspension
{
  /// Levels and counts of the current mesh.
  struct MeshLevels
  {
    unsigned int            min_level = 0, max_level = 0;
    types::global_cell_index cells_on_finest = 0;
    /// interface cells (see SolidPhase::classify_cells) below the finest
    /// level: 0 if the adaptation kept up with the interface
    types::global_cell_index coarse_interface_cells = 0;
    /// whether an interface cell is within the band's margin (see
    /// MeshAdaptor::due()) of a cell below the finest level: the band
    /// must move now
    bool interface_near_coarse_cells = false;
  };

  /**
   * Decides where the mesh is fine: each criterion of the 'Mesh
   * refinement' subsection asks for a level per cell, the largest wins,
   * clamped to [minimum, maximum] level:
   *
   *  - the phi interface band, widened by 'Buffer cells' face neighbours
   *    (across processor and periodic boundaries): the maximum level;
   *  - the solid interior: 'Solid level';
   *  - the 'Region' expression: 'Region level';
   *  - Kelly's estimator on the velocity: one level up for the largest
   *    'Velocity refine fraction' of the error, keep the level unless in
   *    the smallest 'Velocity coarsen fraction'.
   *
   * Cells below their level are flagged for refinement, cells above it for
   * coarsening; one adaptation moves a cell by at most one level.
   */
  template <int dim>
  class MeshAdaptor
  {
  public:
    MeshAdaptor(const Parameters::All &parameters,
                parallel::distributed::Triangulation<dim> &triangulation);

    bool enabled() const { return settings.enabled; }

    /// Size of the smallest cell the mesh will have: on a uniform mesh the
    /// smallest cell now, on an adaptive one that of the maximum level.
    double finest_cell_size() const;

    /// Whether the interface's speed, not the fastest fluid's, says when
    /// the band must move ('Adaptation speed = interface', no Kelly
    /// refinement of the velocity).
    bool follows_interface_only() const
    {
      return settings.interface_speed && settings.refine_fraction == 0.;
    }

    /// epsilon of the interface band: cells with epsilon < phi < 1 - epsilon.
    double interface_threshold() const { return settings.interface_threshold; }

    /// Called once per step with the distance the interface moved (max |u|
    /// dt over the cells it crosses; the fastest material point's with
    /// Kelly refinement) and the mesh's levels: true when the mesh should be
    /// adapted now. With a fixed 'Interval' every that many steps;
    /// otherwise once the distance moved since the last adaptation reaches
    /// 'Buffer fraction' of the buffer (buffer cells x finest cell size),
    /// or, with follows_interface_only(), once an interface cell comes
    /// within the margin, max(1,
    /// floor((1 - fraction) x buffer cells)) face neighbours, of a cell
    /// below the finest level: the band of phi between epsilon and
    /// 1 - epsilon also widens by the transport's numerical diffusion,
    /// which no material speed bounds.
    bool due(double distance_moved, const MeshLevels &levels);

    /// Sets refine and coarsen flags (locally owned cells) for the state
    /// at `time` (the 'Region' expression may depend on t). True if any
    /// cell on any rank is flagged.
    bool flag(const Solid::SolidPhase<dim> *solid,
              const Fluid::FluidSpace<dim>  &space,
              const Fluid::VectorType       *velocity,
              double                         time);

    MeshLevels levels(const Solid::SolidPhase<dim> *solid) const;

    /// Flags for refinement every locally owned cell whose periodic
    /// neighbour is finer; true if any rank flagged one. Called after each
    /// refinement until it returns false, so that no face across a periodic
    /// boundary has a hanging node: deal.II 9.4's MatrixFree gets the DG
    /// face pairs wrong there (dealii/dealii#8905), which corrupted B in a
    /// particle straddling the periodic boundary.
    bool flag_periodic_hanging_faces();

    /// The counters due() keeps (text, full precision; checkpoints).
    void save(std::ostream &out) const;
    void load(std::istream &in);

  private:
    /// Makes the flags of cells facing each other across periodic faces
    /// agree (see flag_periodic_hanging_faces()).
    void keep_periodic_faces_conforming();
    /// Widens `band` (per active cell) by one face neighbour, `layers` times.
    void dilate(std::vector<unsigned char> &band, unsigned int layers) const;

    const Parameters::MeshRefinement           &settings;
    parallel::distributed::Triangulation<dim> &triangulation;
    std::unique_ptr<Function<dim>>             region;
    unsigned int                               steps_since = 0;
    double                                     distance_since = 0.;
  };
} // namespace Suspension
