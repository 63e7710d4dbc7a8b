#include <immersed_grains/mesh/size_estimate.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace ImmersedGrains
{
  namespace
  {
    template <int dim>
    SizeEstimate
    size_of(const double      cells,
            const double      dofs,
            const bool        with_fluid,
            const std::size_t n_grains)
    {
      // Measured peak resident memory (one rank, Release, doc/performance.md):
      // 2D cloud, 18,915 and 296,835 DoFs: 229 and 736 MB; 3D cloud with
      // 10,000 grains, 15,468 and 112,724 DoFs: 243 and 730 MB. Hence about
      // 200 MB of libraries and set-up, 1.9 kB per DoF in 2D and 5.2 kB in 3D
      // (the velocity block's rows hold 25 and 81 entries of the same
      // component, plus its AMG hierarchy and ILU), with a margin of 15 %.
      // A grain with its copies in the step arrays, the contact list and
      // the ghost layer: about 2 kB.
      const double base            = 200e6;
      const double bytes_per_dof   = (dim == 2 ? 1.9e3 : 5.2e3) * 1.15;
      const double bytes_per_grain = 2e3;
      const double bytes_per_cell  = 1e3; // p4est, Triangulation, grain sorting
      // With a fluid, the positions of each cell matrix's entries in the
      // matrix rows (CellScatter: 2 bytes per coupled pair of the Q2-Q1
      // cell's DoFs, 4 per DoF): 0.7 kB in 2D, 7.5 kB in 3D. In 2D on one
      // rank, the Helmholtz filter's sparse LU besides (one Q1 unknown per
      // cell): 380 MB at 131,072 cells, 2.9 kB per cell, growing like
      // log n; counted on any number of ranks, an estimate errs high.
      const double bytes_per_fluid_cell = dim == 2 ? 0.75e3 + 3e3 : 7.5e3;

      SizeEstimate e;
      e.cells = cells;
      e.dofs  = dofs;
      e.peak_bytes =
        base + bytes_per_dof * e.dofs +
        (bytes_per_cell + (with_fluid ? bytes_per_fluid_cell : 0)) * e.cells +
        bytes_per_grain * n_grains;
      return e;
    }
  } // namespace


  template <int dim>
  SizeEstimate
  estimate_size(const Geometry<dim> &geometry,
                const bool           with_fluid,
                const std::size_t    n_grains)
  {
    double velocity_nodes = 1, pressure_nodes = 1, cells = 1;
    for (unsigned int d = 0; d < dim; ++d)
    {
      const double n = geometry.equivalent_subdivisions()[d] *
                       std::pow(2.0, geometry.initial_refinement);
      cells *= n;
      velocity_nodes *= 2 * n + 1;
      pressure_nodes *= n + 1;
    }
    return size_of<dim>(cells,
                        with_fluid ? dim * velocity_nodes + pressure_nodes : 0.,
                        with_fluid,
                        n_grains);
  }


  template <int dim>
  SizeEstimate
  estimate_adapted_size(const Geometry<dim>                   &geometry,
                        const GrainBand                       &band,
                        const bool                             with_fluid,
                        const std::vector<dealii::Point<dim>> &positions)
  {
    const SizeEstimate initial =
      estimate_size(geometry, with_fluid, positions.size());

    // The levels the band reaches: the cell-size floor (Adaptivity) stops
    // refinement where a cell's shortest edge is below twice the floor.
    unsigned int finest = 0;
    while (finest < band.max_level &&
           geometry.shortest_cell_edge(finest) >= 2 * band.smallest_cell)
      ++finest;

    // Cells of level l by integer coordinates, packed into one key (21
    // bits per axis: up to two million cells along an edge).
    const auto key = [](const std::array<std::int64_t, dim> &c)
    {
      std::uint64_t k = 0;
      for (unsigned int d = 0; d < dim; ++d)
        k = (k << 21) | static_cast<std::uint64_t>(c[d]);
      return k;
    };
    const auto coordinates = [](std::uint64_t k)
    {
      std::array<std::int64_t, dim> c;
      for (int d = dim - 1; d >= 0; --d)
      {
        c[d] = static_cast<std::int64_t>(k & ((1u << 21) - 1));
        k >>= 21;
      }
      return c;
    };

    // Each refined cell adds 2^dim - 1 active cells.
    double                     cells = 1;
    bool                       all   = true; // every cell of the level
    std::vector<std::uint64_t> refined;      // else: these
    for (unsigned int d = 0; d < dim; ++d)
      cells *= geometry.equivalent_subdivisions()[d];
    // Below Min level every cell is refined, whatever the floor.
    const unsigned int top =
      std::max(finest, std::min(band.min_level, band.max_level));
    for (unsigned int level = 0; level < top; ++level)
    {
      std::array<std::int64_t, dim> n;
      double                        level_cells = 1;
      for (unsigned int d = 0; d < dim; ++d)
      {
        n[d] = static_cast<std::int64_t>(geometry.equivalent_subdivisions()[d])
               << level;
        level_cells *= n[d];
      }
      // Beyond the keys' range the band alone is far beyond any memory:
      // say so through the estimate, which the caller turns into an error
      // naming Max level.
      if (*std::max_element(n.begin(), n.end()) >= (1 << 21))
      {
        SizeEstimate huge =
          size_of<dim>(level_cells,
                       level_cells * initial.dofs / initial.cells,
                       with_fluid,
                       positions.size());
        huge.adapted = true;
        return huge;
      }
      if (level < band.min_level)
      {
        cells += ((1 << dim) - 1) * level_cells;
        continue;
      }

      // The cells that hold grains, then the band around them, one axis
      // at a time.
      std::vector<std::uint64_t> marked;
      marked.reserve(positions.size());
      for (const auto &x : positions)
      {
        std::array<std::int64_t, dim> c;
        for (unsigned int d = 0; d < dim; ++d)
        {
          const double s =
            (x[d] - geometry.lower_corner[d]) /
            (geometry.upper_corner[d] - geometry.lower_corner[d]) * n[d];
          c[d] = static_cast<std::int64_t>(
            std::min(std::max(std::floor(s), 0.), n[d] - 1.));
        }
        marked.push_back(key(c));
      }
      std::sort(marked.begin(), marked.end());
      marked.erase(std::unique(marked.begin(), marked.end()), marked.end());
      // Every marked cell and those within @p layers of it along axis d.
      const auto grow = [&](const unsigned int d, const std::int64_t layers)
      {
        std::vector<std::uint64_t> grown;
        grown.reserve(marked.size() * (2 * layers + 1));
        for (const auto k : marked)
        {
          auto c = coordinates(k);
          for (std::int64_t o = -layers; o <= layers; ++o)
          {
            auto shifted = c;
            shifted[d] += o;
            if (geometry.is_periodic(d)) // the band crosses the face
              shifted[d] = (shifted[d] + n[d]) % n[d];
            if (shifted[d] >= 0 && shifted[d] < n[d])
              grown.push_back(key(shifted));
          }
        }
        std::sort(grown.begin(), grown.end());
        grown.erase(std::unique(grown.begin(), grown.end()), grown.end());
        marked.swap(grown);
      };
      // The paths, in cells of this level: a cell refined here holds
      // 2^(finest - level) finest cells along an edge.
      if (const auto path =
            std::lround(band.lookahead /
                        std::pow(2.0, static_cast<double>(finest) - level));
          path > 0 && level < finest)
        grow(band.path_axis, path);
      for (unsigned int d = 0; d < dim; ++d)
        grow(d, band.band_width);
      // Only cells that exist: their parents were refined.
      if (!all)
        marked.erase(std::remove_if(marked.begin(),
                                    marked.end(),
                                    [&](const std::uint64_t k)
                                    {
                                      auto c = coordinates(k);
                                      for (auto &x : c)
                                        x /= 2;
                                      return !std::binary_search(
                                        refined.begin(), refined.end(), key(c));
                                    }),
                     marked.end());
      cells += ((1 << dim) - 1) * static_cast<double>(marked.size());
      refined.swap(marked);
      all = false;
    }

    // Q2-Q1 DoFs per cell as on the uniform initial mesh (hanging nodes
    // make the adapted mesh's ratio a little lower).
    const double dofs_per_cell = initial.dofs / initial.cells;
    SizeEstimate adapted =
      size_of<dim>(cells, cells * dofs_per_cell, with_fluid, positions.size());
    adapted.adapted = true;
    return adapted.peak_bytes > initial.peak_bytes ? adapted : initial;
  }


  double
  machine_memory(MPI_Comm comm)
  {
    // One rank per machine (the lowest of those that share memory) counts
    // its machine's memory.
    MPI_Comm shared;
    MPI_Comm_split_type(comm, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &shared);
    int rank_on_machine = 0;
    MPI_Comm_rank(shared, &rank_on_machine);
    MPI_Comm_free(&shared);
    const double own = rank_on_machine == 0 ?
                         static_cast<double>(sysconf(_SC_PHYS_PAGES)) *
                           static_cast<double>(sysconf(_SC_PAGESIZE)) :
                         0.0;
    return dealii::Utilities::MPI::sum(own, comm);
  }


  template SizeEstimate
  estimate_size(const Geometry<2> &, bool, std::size_t);
  template SizeEstimate
  estimate_size(const Geometry<3> &, bool, std::size_t);
  template SizeEstimate
  estimate_adapted_size(const Geometry<2> &,
                        const GrainBand &,
                        bool,
                        const std::vector<dealii::Point<2>> &);
  template SizeEstimate
  estimate_adapted_size(const Geometry<3> &,
                        const GrainBand &,
                        bool,
                        const std::vector<dealii::Point<3>> &);
} // namespace ImmersedGrains
