#pragma once
/// @file schema.hpp
/// The JSON Schema of specification files, for editors and external validators.

#include <string>

#include "safecass/filters/registry.hpp"

namespace safecass::spec {

/// The JSON Schema (draft 2020-12) of system and component files, generated from the format's
/// key tables (the same ones load_system() checks against) and the filter manifests of
/// `registry` (one `argument` schema per filter type). Deterministic: the same registry gives
/// the same text, byte for byte. The schema checks shapes; cross-references (unknown events,
/// signals, interfaces...) are load_system()'s job.
std::string json_schema(const FilterRegistry& registry);

}  // namespace safecass::spec
