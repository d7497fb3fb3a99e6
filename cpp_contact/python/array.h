// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// Small helpers shared by the binding files: numpy <-> std::span without copies.
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace contact::python {
namespace py = pybind11;
using carray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// @brief View of a C-contiguous float64 array with a check on its trailing dimension.
inline std::span<const double> as_span(const carray& a, const char* name, py::ssize_t cols = 0) {
  if (cols > 0 and (a.ndim() != 2 or a.shape(1) != cols))
    throw std::invalid_argument(std::string(name) + ": expected an array of shape (n, " +
                                std::to_string(cols) + ")");
  return std::span<const double>(a.data(), std::size_t(a.size()));
}

/// @brief Move a std::vector into a numpy array of the given shape (no copy).
template <typename T> py::array_t<T> to_numpy(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* p = new std::vector<T>(std::move(v));
  py::capsule owner(p, [](void* q) { delete static_cast<std::vector<T>*>(q); });
  return py::array_t<T>(shape, p->data(), owner);
}
} // namespace contact::python
