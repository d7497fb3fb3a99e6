// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// The checked numpy <-> std::span layer shared by every binding file (issue 28, item 5). An
// array a binding reads or writes is checked for its dtype (exactly, no cast), C-contiguity (no
// copy), shape and, for indices, range; a bad one raises ValueError "function: argument: what".
#pragma once
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace contact::python {
namespace py = pybind11;

/// @brief A checked argument as error messages name it: "function: argument".
struct Arg {
  const char* function; ///< the binding, e.g. "assemble_contact"
  const char* name;     ///< the argument, e.g. "u"
};

/// @brief Raise ValueError "function: argument: what".
[[noreturn]] inline void fail(const Arg& arg, const std::string& what) {
  throw py::value_error(std::string(arg.function) + ": " + arg.name + ": " + what);
}

/// @brief A checked C-contiguous array of dtype T (what `input` returns).
template <typename T> using Array = py::array_t<T, py::array::c_style>;

/// @brief Shape pattern entry matching any extent.
inline constexpr py::ssize_t any = -1;

/// @brief A shape as Python prints it: "(3, 2)", "(3,)", "()".
inline std::string shape_str(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t d = 0; d < a.ndim(); ++d)
    s += (d ? ", " : "") + std::to_string(a.shape(d));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// @brief A shape pattern as text: "(n, 2)" for {any, 2}.
inline std::string pattern_str(std::initializer_list<py::ssize_t> pattern) {
  std::string s = "(";
  const char* names[] = {"n", "m", "k", "l"};
  std::size_t d = 0;
  for (const py::ssize_t e : pattern) {
    s += d ? ", " : "";
    s += e == any ? std::string(names[d % 4]) : std::to_string(e);
    ++d;
  }
  return s + (pattern.size() == 1 ? ",)" : ")");
}

/// @brief Whether the shape of `a` matches `pattern` (any: any extent).
inline bool has_shape(const py::array& a, std::initializer_list<py::ssize_t> pattern) {
  if (a.ndim() != py::ssize_t(pattern.size()))
    return false;
  py::ssize_t d = 0;
  for (const py::ssize_t e : pattern) {
    if (e != any and a.shape(d) != e)
      return false;
    ++d;
  }
  return true;
}

/// @brief Check the shape of `a` against `pattern` (any: any extent), e.g. {any, 2} for (n, 2).
/// @param[in] text The expected shape as the message shows it, or null for pattern_str(pattern)
/// @throws ValueError "expected an array of shape (n, 2), got (5, 3)"
inline void check_shape(const Arg& arg, const py::array& a,
                        std::initializer_list<py::ssize_t> pattern, const char* text = nullptr) {
  if (!has_shape(a, pattern))
    fail(arg, "expected an array of shape " + (text ? std::string(text) : pattern_str(pattern)) +
                  ", got " + shape_str(a));
}

/// @brief The numpy array behind an argument: an ndarray as it is, any other sequence through
/// numpy.asarray (its natural dtype, which the caller's dtype check then sees).
inline py::array as_array(const Arg& arg, const py::handle& h) {
  if (py::isinstance<py::array>(h))
    return py::reinterpret_borrow<py::array>(h);
  py::array a = py::array::ensure(h);
  if (!a)
    fail(arg, std::string("expected an array, got ") + Py_TYPE(h.ptr())->tp_name);
  return a;
}

/// @brief Whether `a` has exactly the dtype T (native byte order).
template <typename T> bool has_dtype(const py::array& a) {
  return py::detail::npy_api::get().PyArray_EquivTypes_(a.dtype().ptr(), py::dtype::of<T>().ptr());
}

/// @brief Numpy's name of the dtype T, e.g. "float64".
template <typename T> std::string dtype_name() {
  return py::str(py::dtype::of<T>()).cast<std::string>();
}

/// @brief Check that `a` is C-contiguous and aligned (so that a pointer to it is valid).
/// @throws ValueError naming numpy.ascontiguousarray
inline void check_contiguous(const Arg& arg, const py::array& a) {
  const int need =
      py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_ | py::detail::npy_api::NPY_ARRAY_ALIGNED_;
  if ((a.flags() & need) != need)
    fail(arg, "expected a C-contiguous array (a strided view is not copied: pass "
              "numpy.ascontiguousarray(...))");
}

/// @brief An input array of exactly dtype T, C-contiguous: a view, no cast and no copy.
/// @param[in] arg Its name in error messages
/// @param[in] h The Python argument (an ndarray; lists go through numpy.asarray)
/// @param[in] pattern Expected shape (any: any extent), or empty for any shape
/// @param[in] text The expected shape as messages show it, or null for pattern_str(pattern)
/// @throws ValueError on the dtype ("expected float64, got float32"), then the shape, then the
/// layout ("expected a C-contiguous array")
template <typename T>
Array<T> input(const Arg& arg, const py::handle& h, std::initializer_list<py::ssize_t> pattern = {},
               const char* text = nullptr) {
  py::array a = as_array(arg, h);
  // a Python list of numbers has no dtype of its own: numpy's float64 of it is no narrowing
  if (!py::isinstance<py::array>(h) and std::is_floating_point_v<T> and a.dtype().kind() == 'i')
    a = py::array_t<T>::ensure(a);
  if (!has_dtype<T>(a))
    fail(arg, "expected " + dtype_name<T>() + ", got " + py::str(a.dtype()).cast<std::string>());
  if (pattern.size() > 0)
    check_shape(arg, a, pattern, text);
  check_contiguous(arg, a);
  return py::reinterpret_borrow<Array<T>>(a);
}

/// @brief Flat read-only view of a checked input.
template <typename T> std::span<const T> flat(const Array<T>& a) {
  return std::span<const T>(a.data(), std::size_t(a.size()));
}

/// @brief An output (or in-out) array the binding writes into: an ndarray of exactly dtype T,
/// C-contiguous and writeable with `size` entries. Never a cast or a copy: the caller would
/// not see the result.
/// @throws ValueError on any other array
template <typename T> std::span<T> output(const Arg& arg, const py::handle& h, std::size_t size) {
  if (!py::isinstance<py::array>(h))
    fail(arg,
         std::string("expected a numpy array to write into, got ") + Py_TYPE(h.ptr())->tp_name);
  py::array a = py::reinterpret_borrow<py::array>(h);
  if (!has_dtype<T>(a))
    fail(arg, "expected " + dtype_name<T>() + ", got " + py::str(a.dtype()).cast<std::string>());
  check_contiguous(arg, a);
  if (!a.writeable())
    fail(arg, "expected a writeable array");
  if (std::size_t(a.size()) != size)
    fail(arg, "expected " + std::to_string(size) + " entries, got " + std::to_string(a.size()) +
                  " (shape " + shape_str(a) + ")");
  return std::span<T>(static_cast<T*>(a.mutable_data()), size);
}

/// @brief Check lo <= i < hi for every index i of `v`, once per call (not in an inner loop).
/// @throws ValueError "index 1234 out of range [0, 800) (entry 7)"
inline void check_range(const Arg& arg, std::span<const std::int32_t> v, std::int64_t lo,
                        std::int64_t hi) {
  for (std::size_t k = 0; k < v.size(); ++k)
    if (v[k] < lo or v[k] >= hi)
      fail(arg, "index " + std::to_string(v[k]) + " out of range [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + ") (entry " + std::to_string(k) + ")");
}

/// @brief int32 indices from an int32 array (a view) or an int64 one (converted, each value
/// checked to fit int32); C-contiguous, of the expected shape. Any other dtype is refused.
class Indices {
public:
  /// @brief Check and (int64 only) convert the argument.
  /// @param[in] arg Its name in error messages
  /// @param[in] h The Python argument (an ndarray; lists go through numpy.asarray)
  /// @param[in] pattern Expected shape (any: any extent), or empty for any shape
  Indices(const Arg& arg, const py::handle& h, std::initializer_list<py::ssize_t> pattern = {})
      : arg_(arg), array_(as_array(arg, h)) {
    if (!has_dtype<std::int32_t>(array_) and !has_dtype<std::int64_t>(array_))
      fail(arg,
           "expected int32 or int64 indices, got " + py::str(array_.dtype()).cast<std::string>());
    if (pattern.size() > 0)
      check_shape(arg, array_, pattern);
    check_contiguous(arg, array_);
    const auto n = std::size_t(array_.size());
    if (has_dtype<std::int32_t>(array_)) {
      flat_ = std::span<const std::int32_t>(static_cast<const std::int32_t*>(array_.data()), n);
      return;
    }
    const auto* p = static_cast<const std::int64_t*>(array_.data());
    owned_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      if (p[k] < std::numeric_limits<std::int32_t>::min() or
          p[k] > std::numeric_limits<std::int32_t>::max())
        fail(arg, "index " + std::to_string(p[k]) + " does not fit int32 (entry " +
                      std::to_string(k) + ")");
      owned_[k] = std::int32_t(p[k]);
    }
    flat_ = owned_;
  }
  Indices(const Indices&) = delete;
  Indices& operator=(const Indices&) = delete;

  /// @brief The indices, flat (row-major).
  std::span<const std::int32_t> flat() const { return flat_; }
  /// @brief The indices as a vector (a copy).
  std::vector<std::int32_t> vector() const { return {flat_.begin(), flat_.end()}; }
  /// @brief The checked array (int32 or int64).
  const py::array& array() const { return array_; }
  /// @brief Number of dimensions of the array.
  py::ssize_t ndim() const { return array_.ndim(); }
  /// @brief Extent along dimension d.
  py::ssize_t shape(py::ssize_t d) const { return array_.shape(d); }
  /// @brief Number of indices.
  std::size_t size() const { return flat_.size(); }
  /// @brief Check lo <= i < hi for every index (see check_range).
  void check_range(std::int64_t lo, std::int64_t hi) const {
    contact::python::check_range(arg_, flat_, lo, hi);
  }

private:
  Arg arg_;
  py::array array_;
  std::vector<std::int32_t> owned_;
  std::span<const std::int32_t> flat_;
};

/// @brief Per-entry flags (nonzero: set) read from a bool or int8 array.
struct Flags {
  py::array array;                   ///< the checked array (keeps the view valid)
  std::span<const std::int8_t> flat; ///< its entries
};

/// @brief Flags of exactly dtype bool or int8, C-contiguous, with `size` entries: a view.
/// @throws ValueError on any other array
inline Flags flags(const Arg& arg, const py::handle& h, std::size_t size) {
  py::array a = as_array(arg, h);
  if (!has_dtype<bool>(a) and !has_dtype<std::int8_t>(a))
    fail(arg, "expected bool or int8 flags, got " + py::str(a.dtype()).cast<std::string>());
  check_contiguous(arg, a);
  if (std::size_t(a.size()) != size)
    fail(arg, "expected " + std::to_string(size) + " entries, got " + std::to_string(a.size()) +
                  " (shape " + shape_str(a) + ")");
  const auto* p = static_cast<const std::int8_t*>(a.data());
  return {a, std::span<const std::int8_t>(p, size)};
}

/// @brief Move a std::vector into a numpy array of the given shape (no copy).
template <typename T> py::array_t<T> to_numpy(std::vector<T>&& v, std::vector<py::ssize_t> shape) {
  auto* p = new std::vector<T>(std::move(v));
  py::capsule owner(p, [](void* q) { delete static_cast<std::vector<T>*>(q); });
  return py::array_t<T>(shape, p->data(), owner);
}
} // namespace contact::python
