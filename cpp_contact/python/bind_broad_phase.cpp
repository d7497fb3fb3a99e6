// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Broad phase of the multi-body contact search: candidate pairs from bounding boxes.
#include "array.h"
#include <contact/broad_phase.h>
#include <string>

namespace py = pybind11;
using contact::python::Arg;
using contact::python::Array;
using contact::python::fail;
using contact::python::flat;
using contact::python::input;
using contact::python::to_numpy;

namespace {

/// @brief Dimension of a float64 box array of shape (n, 2, d) or (n, 2 d), d >= 1.
int box_dim(const Array<double>& boxes, const Arg& arg) {
  if (boxes.ndim() == 3 and boxes.shape(1) == 2 and boxes.shape(2) >= 1)
    return int(boxes.shape(2));
  if (boxes.ndim() == 2 and boxes.shape(1) >= 2 and boxes.shape(1) % 2 == 0)
    return int(boxes.shape(1) / 2);
  fail(arg, "expected an array of shape (n, 2, d) or (n, 2 d) with rows [lo_0, .., lo_{d-1}, "
            "hi_0, .., hi_{d-1}], got " +
                contact::python::shape_str(boxes));
}

py::array_t<std::int32_t> pairs_array(std::vector<std::int32_t>&& p) {
  const auto m = py::ssize_t(p.size() / 2);
  return to_numpy(std::move(p), {m, 2});
}

} // namespace

void bind_broad_phase(py::module_& m) {
  m.def(
      "candidate_pairs",
      [](const py::object& boxes_in, double inflate) {
        const Arg arg{"candidate_pairs", "boxes"};
        const auto boxes = input<double>(arg, boxes_in);
        const int dim = box_dim(boxes, arg);
        std::vector<std::int32_t> p;
        {
          py::gil_scoped_release release;
          p = contact::candidate_pairs(flat(boxes), dim, inflate);
        }
        return pairs_array(std::move(p));
      },
      py::arg("boxes"), py::arg("inflate") = 0.0,
      "Broad phase: pairs (i, j), i < j, of boxes that overlap once each grows by `inflate` on "
      "every side (touching counts). boxes: (n, 2, d) or (n, 2 d), rows [lo..., hi...]. "
      "Returns an (m, 2) int32 array sorted lexicographically. Sort-and-sweep along the axis of "
      "largest spread: O(n log n + pairs). ValueError names the argument for NaN/inf, lo > hi "
      "or inflate < 0.");
  m.def(
      "candidate_pairs_between",
      [](const py::object& a_in, const py::object& b_in, double inflate) {
        const Arg arg_a{"candidate_pairs_between", "boxes_a"},
            arg_b{"candidate_pairs_between", "boxes_b"};
        const auto a = input<double>(arg_a, a_in), b = input<double>(arg_b, b_in);
        const int da = box_dim(a, arg_a), db = box_dim(b, arg_b);
        if (da != db)
          fail(arg_b,
               "dimension " + std::to_string(db) + " differs from boxes_a's " + std::to_string(da));
        std::vector<std::int32_t> p;
        {
          py::gil_scoped_release release;
          p = contact::candidate_pairs_between(flat(a), flat(b), da, inflate);
        }
        return pairs_array(std::move(p));
      },
      py::arg("boxes_a"), py::arg("boxes_b"), py::arg("inflate") = 0.0,
      "Broad phase between two sets (bodies and rigid obstacles): pairs (index in a, index in "
      "b) of overlapping inflated boxes, (m, 2) int32 sorted lexicographically; same box layout "
      "and rules as candidate_pairs.");
}
