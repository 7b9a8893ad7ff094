#pragma once
/// @file analyze.hpp
/// The safety analysis an assessor asks for, derived from the specification the robot runs
/// (`safecass analyze`, docs/analyze.md):
///
///   failure modes → their local and system effects, by the engine's own propagation (a system
///   built as `run` builds it; each mode raised alone, every address read, the system reset) →
///   detection → the reaction the hazards require → hazards → test evidence → gaps;
///   fault trees: per top event (a hazard's reaction address at its level, or `--top`), the gates
///   that propagation (OR) and escalation (AND: an onset that takes Error only on a machine
///   already at Warning, DESIGN §2.3) make of the failure modes, in the Open-PSA Model Exchange
///   Format, whose minimal cut sets (and, with rates, probabilities and importances) SCRAM
///   computes;
///   a GSN safety case over hazards, detection, reaction and evidence.
///
/// Split in pure steps: build_analysis() (files → Analysis, SCRAM included), then the formats.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/core/expected.hpp"
#include "safecass/core/state.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/spec/diagnostics.hpp"
#include "safecass/trace/trace.hpp"

namespace safecass::analyze {

/// What fails (docs/analyze.md, "Failure modes").
enum class ModeKind : std::uint8_t {
  Onset,            ///< an onset event at the machine it is raised at
  MachineError,     ///< a component's framework or application machine at Error, named by no event or not
  StaleSignal,      ///< a signal stops, where a filter watches its freshness
  MonitoringFault,  ///< a detecting filter cannot evaluate its input (EVT_INVALID_SAMPLE)
  CoordinatorLost,  ///< a coordinator (process) stops: EVT_COORDINATOR_LOST
  SupervisorLost,   ///< the supervisor stops: EVT_SUPERVISOR_LOST
};
std::string_view to_string(ModeKind kind) noexcept;

/// An address and the level a failure mode puts it at.
struct Reached {
  std::string address;
  State level = State::Normal;
};

/// A hazard a failure mode leads to.
struct HazardLink {
  std::string id;
  std::string description;
  /// "detected": the mode is an onset linked to the hazard; "blinds": the mode stops a filter
  /// that detects the hazard (its signal stale, its evaluation failing, its process lost).
  std::string role;
  /// Detected: the reaction addresses the mode alone leaves below their required level, as
  /// "SERVO at Normal, Error required". Empty: the engine meets the reaction for this mode.
  std::vector<std::string> missed;
  trace::Verdict verified = trace::Verdict::NotRun;  ///< `safecass verify`'s verdict for the reaction
};

/// A scenario that exercises a failure mode, and its verdict.
struct Evidence {
  std::string scenario;
  bool passed = false;
};

/// Missing or contrary evidence on one row. Kinds (docs/analyze.md, "Gaps"): no-detection,
/// reaction-missed, no-reaction, no-test, test-failed, reaction-not-proved.
struct Gap {
  trace::Severity severity = trace::Severity::Warning;
  std::string kind;
  std::string message;
};

/// One row of the FMEA.
struct FailureMode {
  std::string id;    ///< the basic event's name in the fault trees: "FM7"
  std::string name;  ///< how a user names it (`"reliability"`): "EVT_X@C.s_A", "C.s_F", "stale:C.sig", "fault:filter",
                     ///< "lost:coordinator", "lost:supervisor"
  ModeKind kind = ModeKind::Onset;
  std::string description;
  std::string event;                 ///< the onset it raises
  int severity = 0;                  ///< that onset's severity
  std::vector<std::string> origins;  ///< the machines it is raised at
  State level = State::Error;        ///< its level at its origins, arriving in Normal
  bool escalates = false;            ///< it takes Error on a machine already at Warning or worse
  std::string local_effect;          ///< "JR3.s_A at Error"
  std::vector<Reached> effects;      ///< every address it reaches alone, in the system's order
  std::vector<Reached> escalated;    ///< the same when it takes Error (only when it escalates)
  std::string detection;             ///< how it is detected, or "none"
  std::vector<trace::FilterLink> filters;
  std::vector<HazardLink> hazards;
  std::vector<Evidence> tests;
  std::vector<Gap> gaps;
  std::optional<double> rate;         ///< failures per hour, from the system's "reliability"
  std::optional<double> probability;  ///< within the mission, from the system's "reliability"
  spec::Position where;
};

/// A basic event in a cut set, with SCRAM's importance factors when probabilities were given.
struct Importance {
  std::string mode;  ///< FailureMode::id
  double probability = 0.0, mif = 0.0, cif = 0.0, dif = 0.0, raw = 0.0, rrw = 0.0;
};

struct CutSet {
  std::vector<std::string> modes;  ///< FailureMode ids, in SCRAM's order
  std::optional<double> probability;
};

/// A gate of the fault trees: OR or AND of failure modes and other gates.
struct Gate {
  std::string name;  ///< its MEF name
  bool all = false;  ///< AND (else OR)
  std::vector<std::string> modes;
  std::vector<std::string> gates;
  std::string label;
};

/// A top event: an address at or above a level.
struct TopEvent {
  std::string gate;  ///< its gate's MEF name
  std::string address;
  State level = State::Error;
  std::string why;  ///< "H-3's reaction", "--top"
  std::vector<CutSet> cut_sets;
  std::optional<double> probability;  ///< with rates or probabilities for every mode
  std::vector<Importance> importance;
};

struct FaultTrees {
  std::vector<TopEvent> tops;
  std::vector<Gate> gates;       ///< every gate, tops first
  int order = 3;                 ///< the largest cut set computed (SCRAM's --limit-order)
  double mission_time = 8760.0;  ///< hours (the "reliability" section's, or SCRAM's default)
  /// Empty when SCRAM computed probabilities and importances; else why not ("no \"reliability\"
  /// section", "3 modes have no rate or probability: FM2, …").
  std::string unquantified;
  std::string mef;    ///< the MEF document given to SCRAM
  std::string scram;  ///< "SCRAM 0.16.2"
};

/// One node of the GSN goal structure (GSN Community Standard v3 element types).
struct GsnNode {
  std::string id;    ///< "G1", "S1.2", "Sn3", …
  std::string type;  ///< "goal", "strategy", "solution", "context", "assumption"
  std::string text;
  bool undeveloped = false;          ///< a goal no evidence supports yet (a gap)
  std::vector<std::string> parts;    ///< SupportedBy children
  std::vector<std::string> context;  ///< InContextOf children
};

struct SafetyCase {
  std::vector<GsnNode> nodes;  ///< the top goal first
};

struct Analysis {
  trace::Trace trace;  ///< the hazards, events, filters, scenarios and verify verdicts it stands on
  std::vector<FailureMode> modes;
  FaultTrees trees;
  SafetyCase safety_case;
  std::vector<spec::Diagnostic> notes;

  bool has_error_gap() const noexcept;
  std::size_t gap_count(trace::Severity severity) const noexcept;
};

struct TopRequest {
  std::string address;
  State level = State::Error;
};

struct AnalyzeOptions {
  std::string system;
  std::vector<std::string> scenarios;  ///< test evidence, run as `trace` runs them
  std::string verify_json;             ///< `safecass verify --json` output, or empty
  std::vector<TopRequest> tops;        ///< top events beyond the hazards' reactions
  int order = 3;                       ///< the largest cut set: 1 to 6
  bool fault_trees = true;             ///< build the trees and run SCRAM
  std::string scram = "scram";         ///< SCRAM's executable
  std::string work_dir;                ///< keep SCRAM's files here (empty: a private directory, removed)
};

/// Parses "ADDR=LEVEL" (LEVEL Warning or Error). Errors: InvalidArgument, saying what is wrong.
[[nodiscard]] Expected<TopRequest> parse_top(std::string_view text);

/// Loads the system, runs the scenarios, derives the FMEA, the fault trees (SCRAM run) and the
/// safety case. Errors (nothing analysed): the system, a scenario or the verify file does not
/// load, a top names no address, SCRAM is missing or fails; each with file:line:col.
[[nodiscard]] tl::expected<Analysis, std::vector<spec::Diagnostic>> build_analysis(const AnalyzeOptions& options,
                                                                                   const FilterRegistry& registry);

/// Writes the fault trees (every mode a basic event) as one MEF document.
std::string mef_document(const std::string& system, const std::vector<FailureMode>& modes, const FaultTrees& trees);

std::string fmea_text(const Analysis& a);
std::string fault_trees_text(const Analysis& a);
std::string safety_case_text(const Analysis& a);
/// One row per failure mode (RFC 4180), with a header row.
std::string fmea_csv(const Analysis& a);
/// The whole analysis as one JSON document (docs/analyze.md, "JSON").
std::string analysis_json(const Analysis& a);
/// The goal structure alone, as analysis_json() has it: {"notation": ..., "nodes": [...]}.
std::string safety_case_json(const SafetyCase& c);

/// The report: one self-contained HTML page (no network) with a header (system, SHA-256 of every
/// spec file, tool version, `date`), the FMEA with its gaps marked, the fault trees with their cut
/// sets, and the safety case drawn as a GSN diagram; printable to PDF.
std::string render_analysis_page(const Analysis& a, const std::string& date);

/// Prints the report `html_path` to `pdf_path` with headless Chromium (`chromium`). Errors: Io.
[[nodiscard]] Expected<void> print_pdf(const std::string& html_path, const std::string& pdf_path,
                                       const std::string& chromium);

}  // namespace safecass::analyze
