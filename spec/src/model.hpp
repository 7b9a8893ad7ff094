#pragma once
// The loader's internal model: what the files say, with the position of every value that a
// check may need to point at. Built by the reader (reader.cpp), checked by the validator
// (validate.cpp), then turned into the public SystemSpec.

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "safecass/core/coordinator.hpp"
#include "safecass/core/event.hpp"
#include "safecass/filters/filter.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/json/read.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/spec/system.hpp"

namespace safecass::spec {

/// Where a value is: index of its file, position, JSON pointer in that file.
struct Site {
  int file = -1;
  json::TextPosition position;
  std::string pointer;
};

/// A loaded file: its path as opened, its bytes and its parsed document (kept alive while
/// loading: the model points into it).
struct Document {
  std::string path;
  std::string canonical;
  std::string text;
  std::optional<json::JsonValue> root;
};

/// Collects diagnostics and turns sites into positions.
class Sink {
public:
  std::deque<Document> documents;
  std::vector<Diagnostic> diagnostics;
  std::vector<int> files;         ///< file index of each diagnostic, for sorting
  std::vector<Diagnostic> notes;  ///< what was accepted and ignored (validate --verbose)
  std::vector<int> note_files;

  void error(const Site& site, std::string message) { add(Diagnostic::Severity::Error, site, std::move(message)); }
  void warning(const Site& site, std::string message) { add(Diagnostic::Severity::Warning, site, std::move(message)); }
  void note(const Site& site, std::string message) { add(Diagnostic::Severity::Note, site, std::move(message)); }
  /// "file:line:col", for "first defined at ...".
  std::string at(const Site& site) const;
  Position position(const Site& site) const;
  std::size_t error_count() const;

private:
  void add(Diagnostic::Severity severity, const Site& site, std::string message);
};

struct Name {
  std::string text;
  Site site;
};

struct SignalItem {
  std::string name;  ///< full: Component.signal
  std::size_t size = 1;
  Site site;
  bool implicit = false;  ///< implied by a 2016 file that declares no signals
};

struct EventItem {
  EventDef def;
  std::string component;
  Site site;  ///< the object
  Site name_site;
  Site severity_site;
  Site transitions_site;
  Site completes_site;
  Site latched_site;
  Site hazard_site;
  bool has_name = false;
  bool has_severity = false;
  bool has_transitions = false;
  bool transitions_valid = true;        ///< every listed transition was understood
  bool framework_redefinition = false;  ///< repeats a framework event's definition: the built-in is used
};

struct ParamItem {
  std::string name;
  Site key_site;
  Site value_site;
  const json::JsonValue* value = nullptr;  ///< null: synthesized by a pipeline (see `synthetic`)
  std::string synthetic;                   ///< a signal name filled in by a pipeline
};

struct FilterItem {
  FilterConfig config;
  std::string owner;  ///< the component whose file declares the filter
  bool named = false;
  std::string pipeline;  ///< the pipeline it is a stage of, if any
  std::size_t stage = 0;
  Site site;
  Site name_site;
  Site class_site;
  Site target_site;  ///< the target object, or the filter when there is none
  Site target_type_site;
  Site target_component_site;
  Site target_interface_site;
  Site argument_site;  ///< the argument object, or the filter when there is none
  bool has_class = false;
  bool has_target_interface = false;
  bool target_component_given = false;
  bool argument_misspelled = false;  ///< an unknown key of the filter is a typo of 'argument' (reported)
  const json::JsonValue* misspelled_argument = nullptr;  ///< its value: the events it names count as generated
  bool from_template = false;                            ///< instantiated from a framework filter template for `owner`
  std::vector<ParamItem> params;
};

struct FilterEntryItem {
  std::string pipeline;  ///< empty for a single filter
  Site site;
  Site name_site;
  std::vector<FilterItem> stages;
};

struct ServiceItem {
  std::string provided;
  ServiceDependency dependency;
  Site site;
  Site name_site;
  std::vector<Name> required;  ///< the s_R list
  bool has_name = false;
};

struct ComponentItem {
  std::string name;
  Site site;
  Site name_site;
  bool has_name = false;
  bool has_interfaces = false;
  bool has_signals = false;
  std::vector<Name> provided;
  std::vector<Name> required;
  std::vector<SignalItem> signals;
  std::vector<EventItem> events;
  std::vector<FilterEntryItem> filters;
  std::vector<ServiceItem> services;
  std::optional<double> period;
  /// A framework filter template (`"component": ""`, as the 2016 framework filter file): its
  /// filters are instantiated for every component of the system, its events are system events.
  bool is_template() const noexcept { return has_name && name.empty(); }
  bool stand_in = false;  ///< the component a template loaded alone is checked against (not in the system)
};

struct ConnectionItem {
  std::string required;
  std::string provided;
  Site site;
  Site required_site;
  Site provided_site;
  bool complete = false;  ///< both ends given as strings
};

struct CoordinatorItem {
  Name name;
  std::vector<Name> components;
};

struct HazardItem {
  std::string id;
  std::string description;
  Site site;
  Site id_site;
  bool has_id = false;
  struct Reaction {
    std::string address;
    std::string level;  ///< as written; checked by the validator
    Site key_site;
    Site value_site;
  };
  std::vector<Reaction> reaction;
};

struct InvariantItem {
  std::string name;
  std::string formula;
  std::string description;
  Site site;
  Site name_site;
  Site formula_site;
  bool has_name = false;
  bool has_formula = false;
};

/// The system file's "reliability" section, as written; checked by the validator.
struct ReliabilityItem {
  struct Mode {
    std::string name;
    std::optional<double> rate, probability;  ///< when given and valid
    int given = 0;                            ///< how many of "rate" and "probability" are written
    Site key_site;
    Site value_site;
  };
  std::optional<double> mission_time;
  std::vector<Mode> modes;
  Site site;
};

struct Model {
  std::string name;
  std::string path;
  bool system_file = false;           ///< the loaded file is a system file (not a single component)
  std::size_t component_entries = 0;  ///< entries of the top-level "components" list
  bool has_components_key = false;    ///< the top-level file has a (well-typed) "components" list
  std::vector<ComponentItem> components;
  std::vector<ConnectionItem> connections;
  std::vector<CoordinatorItem> coordinators;
  bool has_coordinators = false;
  std::vector<HazardItem> hazards;
  bool has_hazards = false;  ///< a "hazards" section exists: events' hazard ids are checked against it
  std::vector<InvariantItem> invariants;
  std::optional<ReliabilityItem> reliability;
};

/// Reads the top-level file (from disk when `text` is null) and everything it includes into
/// `model`, reporting file, syntax and schema problems to `sink`.
void read_files(const std::string& path, const std::string* text, Sink& sink, Model& model);

/// Cross-reference checks of DESIGN §5. Fills the names of unnamed filters, implied interfaces
/// and signals of 2016 files, and pipeline wiring into `model`.
void validate(Model& model, const FilterRegistry& registry, Sink& sink);

/// The public form of a model that passed validation.
SystemSpec to_system(const Model& model, const Sink& sink);

/// Names and kinds of the framework events every coordinator defines.
struct FrameworkEvent {
  std::string name;
  bool onset = true;
  std::string counterpart;
  int severity = 0;
  TransitionSet transitions;
};
const std::vector<FrameworkEvent>& framework_events();

}  // namespace safecass::spec
