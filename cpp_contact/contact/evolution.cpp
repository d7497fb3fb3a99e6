// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#include "evolution.h"
