// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "array.h"
#include <contact/mls.h>

namespace py = pybind11;

void bind_mls(py::module_& /*m*/) {}
