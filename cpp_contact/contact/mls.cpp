// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "mls.h"

#include <nanoflann.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>

namespace contact {

namespace {

/// nanoflann dataset adaptor over the projector's own copy of the sources.
struct Cloud {
  std::vector<double> x;
  std::size_t dim;
  std::size_t kdtree_get_point_count() const { return x.size() / dim; }
  double kdtree_get_pt(std::uint32_t i, std::size_t k) const { return x[i * dim + k]; }
  template <class BBox> bool kdtree_get_bbox(BBox&) const { return false; }
};

// Fixed-dimension trees: the distance loops unroll (the dimension is known per projector).
template <int D>
using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud,
                                                 D, std::uint32_t>;

/// Reciprocal 1-norm condition number of the SPD moment matrix M (N x N) and its first inverse
/// column c = M^{-1} e_0 (the only one eq 44 needs, since P(x_t) = e_0 on the centred basis).
/// Exact 1-norm of M^{-1} (N <= 4 solves are cheaper than an estimator); 0 if the Cholesky
/// factorisation breaks down (M singular or indefinite by round-off).
template <int N> double invert_first_column(std::array<double, N * N> M, std::array<double, N>& c) {
  double norm = 0;
  for (int j = 0; j < N; ++j) {
    double s = 0;
    for (int i = 0; i < N; ++i)
      s += std::abs(M[i * N + j]);
    norm = std::max(norm, s);
  }
  // In-place Cholesky M = L L^T (lower triangle).
  for (int j = 0; j < N; ++j) {
    double d = M[j * N + j];
    for (int k = 0; k < j; ++k)
      d -= M[j * N + k] * M[j * N + k];
    if (!(d > 0))
      return 0.0;
    d = std::sqrt(d);
    M[j * N + j] = d;
    for (int i = j + 1; i < N; ++i) {
      double s = M[i * N + j];
      for (int k = 0; k < j; ++k)
        s -= M[i * N + k] * M[j * N + k];
      M[i * N + j] = s / d;
    }
  }
  double inv_norm = 0;
  for (int col = 0; col < N; ++col) {
    std::array<double, N> y{};
    for (int i = 0; i < N; ++i) { // L y = e_col
      double s = (i == col) ? 1.0 : 0.0;
      for (int k = 0; k < i; ++k)
        s -= M[i * N + k] * y[k];
      y[i] = s / M[i * N + i];
    }
    for (int i = N - 1; i >= 0; --i) { // L^T x = y
      double s = y[i];
      for (int k = i + 1; k < N; ++k)
        s -= M[k * N + i] * y[k];
      y[i] = s / M[i * N + i];
    }
    double s = 0;
    for (int i = 0; i < N; ++i)
      s += std::abs(y[i]);
    inv_norm = std::max(inv_norm, s);
    if (col == 0)
      c = y;
  }
  const double rc = 1.0 / (norm * inv_norm);
  return std::isfinite(rc) ? rc : 0.0;
}

/// Runs of consecutive close targets (within h of a run's first, at most 64: the Gauss points
/// of one cell) as their first indices, k appended. A rule of the targets alone: the runs, and
/// so the results bit for bit, do not depend on the number of threads.
std::vector<std::size_t> run_starts(std::span<const double> targets, int dim, double h) {
  const std::size_t k = targets.size() / std::size_t(dim), max_run = 64;
  std::vector<std::size_t> starts;
  for (std::size_t t0 = 0; t0 < k;) {
    starts.push_back(t0);
    std::size_t t1 = t0 + 1;
    for (; t1 < k and t1 - t0 < max_run; ++t1) {
      double d2 = 0;
      for (int a = 0; a < dim; ++a) {
        const double d = targets[dim * t1 + a] - targets[dim * t0 + a];
        d2 += d * d;
      }
      if (d2 > h * h)
        break;
    }
    t0 = t1;
  }
  starts.push_back(k);
  return starts;
}

/// sum_q x_q y_q (y null: sum_q x_q) with four partial sums.
double sum_product(const double* x, const double* y, std::size_t n) {
  std::array<double, 4> s{};
  std::size_t q = 0;
  for (; q + 4 <= n; q += 4)
    for (int l = 0; l < 4; ++l)
      s[l] += y ? x[q + l] * y[q + l] : x[q + l];
  for (; q < n; ++q)
    s[0] += y ? x[q] * y[q] : x[q];
  return (s[0] + s[1]) + (s[2] + s[3]);
}

bool all_finite(std::span<const double> a) {
  for (double v : a)
    if (!std::isfinite(v))
      return false;
  return true;
}

} // namespace

struct MLSProjector::Impl {
  Cloud cloud;
  std::unique_ptr<Tree<2>> tree2;
  std::unique_ptr<Tree<3>> tree3;

  template <int D> const Tree<D>& tree() const {
    if constexpr (D == 2)
      return *tree2;
    else
      return *tree3;
  }

  template <int D>
  void project(double h, const MLSOptions& opt, std::span<const double> values, std::size_t m,
               std::span<const double> targets, std::span<const std::size_t> starts,
               MLSResult& out) const;
};

/// The sources of one target as contiguous arrays (the loops over them vectorise): index,
/// offset (x_p - x_t) / H per axis (or coordinates, for a run's candidates), squared offset
/// length, weight.
template <int D> struct Support {
  std::vector<std::uint32_t> id;
  std::array<std::vector<double>, D> dx, wdx;
  std::vector<double> r2, w;
  void clear() {
    id.clear();
    for (auto& a : dx)
      a.clear();
    r2.clear();
  }
};

template <int D>
void MLSProjector::Impl::project(double h, const MLSOptions& opt, std::span<const double> values,
                                 std::size_t m, std::span<const double> targets,
                                 std::span<const std::size_t> starts, MLSResult& out) const {
  constexpr int N = D + 1;
  const Tree<D>& index = tree<D>();
  const nanoflann::SearchParams unsorted(32, 0.0f, false);
  std::vector<std::pair<std::uint32_t, double>> hits; // radius-search result (index, d^2)
  hits.reserve(1024);
  Support<D> cand, sup, wide; // a run's candidates (coordinates), one target's support
  std::vector<double> r2;

  // The sources of target xt within 1.5 H among the candidates c: into sup.
  auto select = [&](const double* xt, double H, const Support<D>& c) {
    const std::size_t n = c.id.size();
    const double inv = 1.0 / H;
    r2.assign(n, 0.0);
    for (int a = 0; a < D; ++a) {
      const double* ca = c.dx[a].data();
      const double xa = xt[a];
      for (std::size_t j = 0; j < n; ++j)
        r2[j] += (ca[j] - xa) * (ca[j] - xa) * (inv * inv);
    }
    // branch-free compaction (about half the candidates are kept, unpredictably)
    sup.id.resize(n);
    sup.r2.resize(n);
    for (auto& a : sup.dx)
      a.resize(n);
    std::uint32_t* __restrict id = sup.id.data();
    double* __restrict rs = sup.r2.data();
    std::array<double*, D> dx;
    std::array<const double*, D> cx;
    for (int a = 0; a < D; ++a)
      dx[a] = sup.dx[a].data(), cx[a] = c.dx[a].data();
    const std::uint32_t* cid = c.id.data();
    const double* r2c = r2.data();
    std::size_t kept = 0;
    for (std::size_t j = 0; j < n; ++j) {
      id[kept] = cid[j];
      rs[kept] = r2c[j];
      for (int a = 0; a < D; ++a)
        dx[a][kept] = (cx[a][j] - xt[a]) * inv;
      kept += r2c[j] < 2.25;
    }
    sup.id.resize(kept);
    sup.r2.resize(kept);
    for (auto& a : sup.dx)
      a.resize(kept);
  };
  // The sources of a radius search as candidates (their coordinates).
  auto gather = [&](Support<D>& s, const std::vector<std::pair<std::uint32_t, double>>& found) {
    s.clear();
    for (const auto& hit : found) {
      s.id.push_back(hit.first);
      for (int a = 0; a < D; ++a)
        s.dx[a].push_back(cloud.x[D * std::size_t(hit.first) + a]);
    }
  };

  // The linear fit of eq 44 at target t on the support `sup`: writes the values and returns
  // true, or false (rcond, count set) if the fit is singular.
  auto fit = [&](std::size_t t, double& rc, std::int32_t& count) {
    const std::size_t n = sup.id.size();
    sup.w.resize(n);
    double* __restrict w = sup.w.data();
    const double* __restrict r2q = sup.r2.data();
    for (std::size_t q = 0; q < n; ++q)
      w[q] = quadratic_spline_weight(std::sqrt(r2q[q]));
    // Moment matrix (eq 42) on the basis P = [1, (x - x_t)/H] centred at the target, entry by
    // entry as sums over contiguous arrays (four partial sums each: no dependency chain)
    for (int a = 0; a < D; ++a) {
      sup.wdx[a].resize(n);
      for (std::size_t q = 0; q < n; ++q)
        sup.wdx[a][q] = w[q] * sup.dx[a][q];
    }
    std::array<double, N * N> M{};
    M[0] = sum_product(w, nullptr, n);
    for (int a = 0; a < D; ++a) {
      M[(a + 1) * N] = sum_product(sup.wdx[a].data(), nullptr, n);
      for (int b = 0; b <= a; ++b)
        M[(a + 1) * N + b + 1] = sum_product(sup.wdx[a].data(), sup.dx[b].data(), n);
    }
    count = 0;
    for (std::size_t q = 0; q < n; ++q)
      count += w[q] > 0;
    for (int i = 0; i < N; ++i)
      for (int j = i + 1; j < N; ++j)
        M[i * N + j] = M[j * N + i];
    std::array<double, N> c{};
    rc = count >= N ? invert_first_column<N>(M, c) : 0.0;
    if (!(rc >= opt.rcond_min))
      return false;
    // Eq 44 at x = x_t: u^h = e_0^T M^{-1} b = sum_p w_p (P_p . c) u_p, for all m fields.
    double* u = out.values.data() + m * t;
    for (std::size_t q = 0; q < n; ++q) {
      double phi = c[0];
      for (int a = 0; a < D; ++a)
        phi += c[a + 1] * sup.dx[a][q];
      phi *= sup.w[q];
      const double* up = values.data() + m * std::size_t(sup.id[q]);
      for (std::size_t f = 0; f < m; ++f)
        u[f] += phi * up[f];
    }
    return true;
  };

  // Targets come in runs of close points (the Gauss points of one cell): one radius search
  // of radius 1.5 h + the run's extent serves the whole run, each target then keeps the
  // candidates within its own support: the sources of a search of its own, found faster.
  for (std::size_t r = 0; r + 1 < starts.size(); ++r) {
    const std::size_t t0 = starts[r], t1 = starts[r + 1];
    // one search about the run's centre, radius 1.5 h + the run's radius about it
    std::array<double, D> centre{};
    for (std::size_t t = t0; t < t1; ++t)
      for (int a = 0; a < D; ++a)
        centre[a] += targets[D * t + a] / double(t1 - t0);
    double radius2 = 0;
    for (std::size_t t = t0; t < t1; ++t) {
      double d2 = 0;
      for (int a = 0; a < D; ++a)
        d2 += (targets[D * t + a] - centre[a]) * (targets[D * t + a] - centre[a]);
      radius2 = std::max(radius2, d2);
    }
    const double R = 1.5 * h * (1 + 1e-12) + std::sqrt(radius2);
    index.radiusSearch(centre.data(), R * R, hits, unsorted);
    gather(cand, hits);
    for (std::size_t t = t0; t < t1; ++t) {
      const double* xt = targets.data() + D * t;
      select(xt, h, cand);
      double rc;
      std::int32_t count;
      double widen = 1.0;
      // singular: widen the support (eq 45's h) and search again, up to the cap
      for (int level = 0; not fit(t, rc, count); ++level) {
        if (level == opt.max_widenings) {
          std::ostringstream msg;
          msg << "MLSProjector::project: target " << t << " at (";
          for (int a = 0; a < D; ++a)
            msg << (a ? ", " : "") << xt[a];
          msg << ") has a singular MLS fit (" << count << " neighbours, rcond " << rc
              << ") even with the support widened to " << widen
              << " h: the sources are too far or collinear there";
          throw std::runtime_error(msg.str());
        }
        widen *= opt.widen_factor;
        const double H = h * widen;
        index.radiusSearch(xt, 2.25 * H * H, hits, unsorted);
        gather(wide, hits);
        select(xt, H, wide);
      }
      out.widening[t] = widen;
      out.rcond[t] = rc;
      out.neighbours[t] = count;
    }
  }
}

MLSProjector::MLSProjector(std::span<const double> sources, int dim, double h, MLSOptions options)
    : _impl(std::make_unique<Impl>()), _dim(dim), _h(h), _options(options) {
  if (dim != 2 and dim != 3)
    throw std::invalid_argument("MLSProjector: dim must be 2 or 3, got " + std::to_string(dim));
  if (sources.size() % std::size_t(dim) != 0)
    throw std::invalid_argument("MLSProjector: sources must hold (n, dim) coordinates");
  const std::size_t n = sources.size() / std::size_t(dim);
  if (n < std::size_t(dim) + 1)
    throw std::invalid_argument("MLSProjector: sources must hold at least dim + 1 points");
  if (n > std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("MLSProjector: sources has too many points for 32-bit indices");
  if (!all_finite(sources))
    throw std::invalid_argument("MLSProjector: sources has non-finite coordinates");
  if (!(std::isfinite(h) and h > 0))
    throw std::invalid_argument("MLSProjector: h must be finite and > 0");
  if (!(options.rcond_min >= 0 and options.rcond_min < 1 and options.widen_factor > 1 and
        std::isfinite(options.widen_factor) and options.max_widenings >= 0))
    throw std::invalid_argument("MLSProjector: options need 0 <= rcond_min < 1, finite "
                                "widen_factor > 1 and max_widenings >= 0");
  _impl->cloud = Cloud{std::vector<double>(sources.begin(), sources.end()), std::size_t(dim)};
  // Leaves of ~16 points: a support holds ~30-70 sources, so few leaves are visited.
  const nanoflann::KDTreeSingleIndexAdaptorParams params(16);
  if (dim == 2)
    _impl->tree2 = std::make_unique<Tree<2>>(2, _impl->cloud, params);
  else
    _impl->tree3 = std::make_unique<Tree<3>>(3, _impl->cloud, params);
}

MLSProjector::~MLSProjector() = default;
MLSProjector::MLSProjector(MLSProjector&&) noexcept = default;
MLSProjector& MLSProjector::operator=(MLSProjector&&) noexcept = default;

std::size_t MLSProjector::num_points() const {
  return _impl->cloud.x.size() / std::size_t(_dim);
}

MLSResult MLSProjector::project(std::span<const double> values, std::size_t m,
                                std::span<const double> targets, int threads) const {
  const std::size_t n = num_points();
  if (m < 1)
    throw std::invalid_argument("MLSProjector::project: values must have m >= 1 fields (columns)");
  if (values.size() != n * m)
    throw std::invalid_argument("MLSProjector::project: values must hold (n, m) = (" +
                                std::to_string(n) + ", " + std::to_string(m) + ") entries, got " +
                                std::to_string(values.size()));
  if (targets.size() % std::size_t(_dim) != 0)
    throw std::invalid_argument("MLSProjector::project: targets must hold (k, dim) coordinates");
  if (!all_finite(values))
    throw std::invalid_argument("MLSProjector::project: values has non-finite entries");
  if (!all_finite(targets))
    throw std::invalid_argument("MLSProjector::project: targets has non-finite coordinates");

  const std::size_t k = targets.size() / std::size_t(_dim);
  MLSResult out{std::vector<double>(k * m, 0.0), std::vector<double>(k), std::vector<double>(k),
                std::vector<std::int32_t>(k)};
  // the runs split over the threads in contiguous blocks; each thread writes its own targets
  const std::vector<std::size_t> starts = run_starts(targets, _dim, _h);
  const std::size_t runs = starts.size() - 1;
  const std::size_t nt = std::clamp<std::size_t>(std::size_t(std::max(1, threads)), 1,
                                                 std::max<std::size_t>(1, runs / 256));
  std::vector<std::exception_ptr> errors(nt);
  auto work = [&](std::size_t i) {
    try {
      const std::span<const std::size_t> mine(starts.data() + runs * i / nt,
                                              runs * (i + 1) / nt - runs * i / nt + 1);
      if (_dim == 2)
        _impl->project<2>(_h, _options, values, m, targets, mine, out);
      else
        _impl->project<3>(_h, _options, values, m, targets, mine, out);
    } catch (...) {
      errors[i] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  for (std::size_t i = 1; i < nt; ++i)
    pool.emplace_back(work, i);
  work(0);
  for (auto& th : pool)
    th.join();
  for (auto& e : errors) // the first failing target's error, whatever the thread count
    if (e)
      std::rethrow_exception(e);
  return out;
}

} // namespace contact
