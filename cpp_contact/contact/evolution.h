// Copyright (C) 2026 The ILS contact developers. SPDX-License-Identifier: MIT
#pragma once
namespace contact {} // namespace contact
