#pragma once
/// @file spec.hpp
/// The specification module: load, validate, instantiate, schema.

#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/spec/schema.hpp"
#include "safecass/spec/system.hpp"
