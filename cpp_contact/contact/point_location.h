// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace contact {

/// @brief Result of CellLocator::locate for n points.
struct LocatedPoints {
  std::vector<std::int32_t> cells; ///< (n,) cell index (into the mesh's cells), -1 if none
  std::vector<double> X;           ///< (n, 2) reference coordinates (NaN where cells == -1)
  std::vector<double> outside;     ///< (n,) 0 inside, else physical distance (inf if cells == -1)
};

/// @brief Cells of one body of an unstructured P1 mesh (triangles or quadrilaterals), binned on
/// a uniform grid for O(1) average point location.
///
/// Reference cells follow DOLFINx: the triangle (0,0), (1,0), (0,1) and the quadrilateral
/// [0,1]^2 with its vertices in tensor order (0,0), (1,0), (0,1), (1,1). The locator copies the
/// vertex coordinates of the indexed cells: it does not keep references to its inputs.
///
/// Bins of about the mean cell diameter cover the bounding box of the cells; each cell is
/// registered in every bin its bounding box overlaps. A query examines its own bin (which holds
/// every cell containing the point), then rings of bins around it until the ring is further
/// than the nearest cell found (or than max_distance). Cells must be convex (quadrilaterals are
/// checked). locate() is const and holds no scratch state: it may be called concurrently.
class CellLocator {
public:
  /// Relative tolerance of containment: in reference coordinates for the reported `outside`,
  /// times the cell diameter for the physical test of the search.
  static constexpr double tolerance = 1e-12;

  /// Iteration cap of the Newton pull-back on quadrilaterals.
  static constexpr int max_newton_iterations = 50;

  /// @brief Bin the cells `subset` of a mesh.
  /// @param[in] x Vertex coordinates (nv, gdim) row-major; only the first two components are
  /// used (DOLFINx geometry.x has gdim = 3)
  /// @param[in] gdim Row length of x: 2 or 3
  /// @param[in] cells Vertex indices (nc, nverts) row-major, in DOLFINx order
  /// @param[in] nverts 3 (triangles) or 4 (quadrilaterals)
  /// @param[in] subset Indices of the cells to index (e.g. one body's cells); duplicates are
  /// ignored; may be empty (every point is then unlocated)
  /// @throws std::invalid_argument naming the argument for malformed input, out-of-range
  /// indices, non-finite coordinates, degenerate cells or non-convex quadrilaterals
  CellLocator(std::span<const double> x, int gdim, std::span<const std::int32_t> cells, int nverts,
              std::span<const std::int32_t> subset);

  /// @brief Locate points in the indexed cells.
  ///
  /// A point inside (or on the boundary of) an indexed cell gets the lowest-index such cell,
  /// its reference coordinates X and outside = 0. A point outside every indexed cell but within
  /// max_distance of one gets the nearest cell (lowest index among equally near ones), the
  /// pull-back X of the point itself (extrapolated: X lies outside the reference cell) and
  /// outside = the physical distance from the point to that cell (> 0). This is what exact
  /// boundary points of a curved body need: they lie slightly outside its polygonal mesh.
  /// A point further than max_distance from every indexed cell gets cell -1, X = NaN and
  /// outside = +inf.
  /// @param[in] points Flattened (n, 2) points
  /// @param[in] max_distance Search radius for points outside the cells (>= 0, may be +inf)
  /// @throws std::invalid_argument naming the argument for a malformed array, a non-finite point
  /// or a negative/NaN max_distance
  /// @throws std::runtime_error if the Newton pull-back into a quadrilateral does not converge:
  /// the bilinear map of a non-parallelogram folds at O(h^2/|v0 - v1 - v2 + v3|) from the cell
  /// and points beyond the fold have no pull-back, so keep max_distance below ~ the cell size
  LocatedPoints locate(std::span<const double> points, double max_distance) const;

  /// @brief Number of indexed cells (the subset without duplicates).
  std::size_t num_cells() const { return _cells.size(); }

  /// @brief Vertices per cell (3 or 4).
  int num_vertices() const { return _nverts; }

  /// @brief Number of bins along each axis.
  std::array<std::int32_t, 2> num_bins() const { return _nb; }

  /// @brief Bin size along each axis.
  std::array<double, 2> bin_size() const { return _h; }

private:
  /// One indexed cell
  struct Cell {
    double box[4];   ///< xmin, ymin, xmax, ymax, inflated by twice the tolerance
    double v[8];     ///< vertices in DOLFINx order (the last pair unused for triangles)
    double sign;     ///< orientation of the boundary polygon (+1 counter-clockwise)
    double tol;      ///< physical containment tolerance (tolerance * diameter)
    std::int32_t id; ///< mesh cell index
  };

  /// Bin index along axis d of coordinate t, clamped to the grid
  std::int32_t bin(int d, double t) const;

  /// Physical distance from p to the closed cell (0 inside)
  double distance(const Cell& c, std::array<double, 2> p) const;

  /// Reference coordinates of p (exact for triangles, Newton from (0.5, 0.5) for quads;
  /// extrapolated outside the cell)
  std::array<double, 2> pull_back(const Cell& c, std::array<double, 2> p) const;

  /// Entry of a bin: a cell with its box rounded outwards to float, so that the cells a query
  /// rejects by their box are never loaded
  struct Entry {
    float box[4];   ///< xmin, ymin, xmax, ymax
    std::int32_t k; ///< index into _cells
  };

  int _nverts;
  std::vector<Cell> _cells; ///< sorted by the bin of their centre (memory locality)
  std::array<double, 2> _lo{0, 0}, _h{1, 1};
  std::array<std::int32_t, 2> _nb{0, 0};
  std::vector<std::int32_t> _offsets; ///< CSR of bins (x-fastest) -> _bins
  std::vector<Entry> _bins;           ///< by increasing mesh index within a bin
};

} // namespace contact
