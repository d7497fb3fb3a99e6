// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
// The compiled part of dolfinx_forms: numpy in, numpy out, vectorised over points.
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_geometry(py::module_& m);
void bind_contact(py::module_& m);
void bind_assembly(py::module_& m);
void bind_location(py::module_& m);
void bind_cut(py::module_& m);
void bind_mls(py::module_& m);
void bind_evolution(py::module_& m);
void bind_broad_phase(py::module_& m);
void bind_schur(py::module_& m);

PYBIND11_MODULE(_cpp, m) {
  m.doc() = "ILS contact core: level sets, closest points, contact surface, return mapping";
  bind_geometry(m);
  bind_contact(m);
  bind_assembly(m);
  bind_location(m);
  bind_cut(m);
  bind_mls(m);
  bind_evolution(m);
  bind_broad_phase(m);
  bind_schur(m);
}
