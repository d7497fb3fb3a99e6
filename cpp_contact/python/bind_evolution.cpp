// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "array.h"
#include <contact/evolution.h>

namespace py = pybind11;

void bind_evolution(py::module_& /*m*/) {}
