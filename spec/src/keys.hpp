#pragma once
// The keys of every object of the specification format: one table, read by the loader (unknown,
// missing and mistyped keys) and by the schema generator, so that the two cannot disagree.

#include <limits>
#include <string_view>
#include <utility>
#include <vector>

namespace safecass::spec {

enum class Shape : unsigned char {
  String,  ///< a string
  Bool,
  Integer,     ///< a whole number within [min, max]
  Number,      ///< a number within [min, max] (above min when exclusive_min)
  Choice,      ///< one of `choices`
  StringList,  ///< an array of strings
  ChoiceList,  ///< an array of `choices`
  Object,      ///< an object described by `ref` (or free-form when ref is empty)
  ObjectList,  ///< an array of objects described by `ref`
};

struct Key {
  std::string_view name;
  Shape shape = Shape::String;
  bool required = false;
  std::string_view doc;
  std::string_view ref;                   ///< $defs name (Object/ObjectList)
  std::vector<std::string_view> choices;  ///< Choice/ChoiceList
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool exclusive_min = false;
  std::string_view default_json;  ///< the default as JSON text, for the schema
  /// Choice: other spellings accepted, as in the 2016 loader: any letter case, and
  /// {synonym, choice} pairs ("INTERNAL" is "ACTIVE").
  bool any_case = false;
  std::vector<std::pair<std::string_view, std::string_view>> synonyms;
  /// Accepted only for the 2016 files and ignored: a note (validate --verbose) says so.
  bool ignored = false;
};

/// A key of an older format that has a new name or place: the error says what to write.
struct RenamedKey {
  std::string_view old_name;
  std::string_view advice;  ///< e.g. "write \"target\": {\"component\": ...}"
};

struct ObjectKind {
  std::string_view name;  ///< used in messages ("event") and as the schema's $defs name
  std::string_view doc;
  std::vector<Key> keys;
  const Key* find(std::string_view key) const noexcept;
};

/// The older key `key` of an object of `kind` that has a new name or place, or nullptr.
const RenamedKey* find_renamed(const ObjectKind& kind, std::string_view key) noexcept;

/// The choice `value` stands for under `key`'s spellings, or "" when it is none of them.
std::string_view canonical_choice(const Key& key, std::string_view value) noexcept;

const ObjectKind& system_kind();
const ObjectKind& include_kind();
const ObjectKind& component_kind();
const ObjectKind& interfaces_kind();
const ObjectKind& signal_kind();
const ObjectKind& event_kind();
const ObjectKind& filter_kind();
const ObjectKind& pipeline_kind();
const ObjectKind& target_kind();
const ObjectKind& service_kind();
const ObjectKind& dependency_kind();
const ObjectKind& connection_kind();
const ObjectKind& hazard_kind();
const ObjectKind& invariant_kind();
const ObjectKind& reliability_kind();
const ObjectKind& mode_rate_kind();

/// Every kind, in schema order.
std::vector<const ObjectKind*> all_kinds();

inline constexpr int kFormatVersion = 1;
inline constexpr double kMaxSignalSize = 4096;

}  // namespace safecass::spec
