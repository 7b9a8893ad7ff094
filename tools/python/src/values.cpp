// The read model's values as Python classes (introspect/model.hpp: one value type per fact), and
// the errors. Each value's to_dict() is its JSON as the console's --json prints it: the one JSON
// formatter of introspect/format.hpp, read back with json.loads.
#include <string>
#include <utility>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "safecass/core/clock.hpp"
#include "safecass/core/condition.hpp"
#include "safecass/core/coordinator.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/model.hpp"

namespace safecass::python {

namespace in = safecass::introspect;

namespace {

py::object values_module() { return py::module_::import("safecass._values"); }

const char* error_class(ErrorCode code) {
  switch (code) {
    case ErrorCode::NotFound: return "NotFound";
    case ErrorCode::InvalidArgument:
    case ErrorCode::Duplicate: return "InvalidArgument";
    case ErrorCode::InvalidState: return "InvalidState";
    case ErrorCode::Denied: return "Denied";
    case ErrorCode::Io: return "BusError";
    case ErrorCode::Parse: return "SpecError";
  }
  return "Error";
}

[[noreturn]] void raise_object(const py::object& cls, const py::object& exception) {
  PyErr_SetObject(cls.ptr(), exception.ptr());
  throw py::error_already_set();
}

std::string level(State s) { return std::string(to_string(s)); }

void bind_diagnostic(py::module_& m) {
  py::class_<spec::Diagnostic>(m, "Diagnostic", "One problem of a file: where it is, how bad, and what.")
      .def_property_readonly("file", [](const spec::Diagnostic& d) { return d.where.file; })
      .def_property_readonly("line", [](const spec::Diagnostic& d) { return d.where.line; })
      .def_property_readonly("column", [](const spec::Diagnostic& d) { return d.where.column; })
      .def_property_readonly("severity",
                             [](const spec::Diagnostic& d) {
                               switch (d.severity) {
                                 case spec::Diagnostic::Severity::Error: return "error";
                                 case spec::Diagnostic::Severity::Warning: return "warning";
                                 case spec::Diagnostic::Severity::Note: return "note";
                               }
                               return "error";
                             })
      .def_readonly("message", &spec::Diagnostic::message)
      .def_readonly("pointer", &spec::Diagnostic::pointer, "the JSON pointer of the value, /filter/1/argument")
      .def("to_dict", [](const spec::Diagnostic& d) { return from_json(spec::to_json(d)); })
      .def("__str__", [](const spec::Diagnostic& d) { return spec::format(d); })
      .def("__repr__", [](const spec::Diagnostic& d) { return "<Diagnostic " + spec::format(d) + ">"; });
}

void bind_root(py::module_& m) {
  py::class_<ResolvedRoot>(m, "Root", "The root cause of a condition: the onset that started it, where and when.")
      .def_readonly("event", &ResolvedRoot::event)
      .def_readonly("origin", &ResolvedRoot::origin, "the machine it was processed on, JR3.s_A")
      .def_property_readonly("time", [](const ResolvedRoot& r) { return to_seconds(r.time); })
      .def_readonly("filter", &ResolvedRoot::filter, "the filter that fired it, or ''")
      .def_readonly("signal", &ResolvedRoot::signal, "the signal of its sample, or ''")
      .def_readonly("value", &ResolvedRoot::value)
      .def_property_readonly("sample_time", [](const ResolvedRoot& r) { return to_seconds(r.sample_time); })
      .def_readonly("injected", &ResolvedRoot::injected)
      .def_property_readonly("name", &ResolvedRoot::name, "JR3.s_A:EVT_FORCE_ERROR, as expect_cause writes it")
      .def("__repr__", [](const ResolvedRoot& r) { return "<Root " + r.name() + ">"; });
}

void bind_record(py::module_& m) {
  py::class_<in::HistoryEntry>(m, "Record",
                               "One record of the observer stream: an event, a transition, a reset or an injection.")
      .def_readonly("seq", &in::HistoryEntry::seq)
      .def_property_readonly(
          "time", [](const in::HistoryEntry& e) { return to_seconds(e.time); }, "seconds")
      .def_property_readonly("kind", [](const in::HistoryEntry& e) { return std::string(to_string(e.kind)); })
      .def_property_readonly("outcome",
                             [](const in::HistoryEntry& e) {
                               return e.outcome == Outcome::None ? std::string() : std::string(to_string(e.outcome));
                             })
      .def_readonly("component", &in::HistoryEntry::component)
      .def_readonly("machine", &in::HistoryEntry::machine)
      .def_readonly("event", &in::HistoryEntry::event)
      .def_property_readonly("from_level", [](const in::HistoryEntry& e) { return level(e.from); })
      .def_property_readonly("to_level", [](const in::HistoryEntry& e) { return level(e.to); })
      .def_property_readonly("level", [](const in::HistoryEntry& e) { return level(e.level); })
      .def_readonly("severity", &in::HistoryEntry::severity)
      .def_readonly("mirror", &in::HistoryEntry::mirror)
      .def_readonly("root", &in::HistoryEntry::root)
      .def_readonly("text", &in::HistoryEntry::text, "why an event was ignored; who and why of a reset")
      .def_property_readonly("where", [](const in::HistoryEntry& e) { return std::string(e.where()); })
      .def(
          "to_dict", [](const in::HistoryEntry& e) { return from_json(in::history_json(e)); },
          "the record as the history file writes it (docs/record-format.md)")
      .def("__str__", [](const in::HistoryEntry& e) { return in::live_line(e); })
      .def("__repr__", [](const in::HistoryEntry& e) { return "<Record " + in::history_json(e) + ">"; });
}

void bind_state_row(py::module_& m) {
  py::class_<in::StateRow>(m, "StateRow", "One row of `state list`: SYSTEM, a component, a machine or a service.")
      .def_readonly("address", &in::StateRow::address)
      .def_property_readonly("kind", [](const in::StateRow& r) { return std::string(to_string(r.kind)); })
      .def_property_readonly("state", [](const in::StateRow& r) { return level(r.state); })
      .def_readonly("outstanding", &in::StateRow::outstanding)
      .def("to_dict", [](const in::StateRow& r) { return from_json(in::state_list_json({r})); })
      .def("__repr__", [](const in::StateRow& r) { return "<StateRow " + r.address + " " + level(r.state) + ">"; });
}

void bind_explain(py::module_& m) {
  py::class_<Explanation>(m, "Explanation", "One active condition at an address, with its root cause and path.")
      .def_readonly("machine", &Explanation::machine)
      .def_readonly("event", &Explanation::event)
      .def_property_readonly("level", [](const Explanation& e) { return level(e.level); })
      .def_readonly("severity", &Explanation::severity)
      .def_readonly("mirror", &Explanation::mirror)
      .def_readonly("outstanding", &Explanation::outstanding)
      .def_readonly("count", &Explanation::count)
      .def_property_readonly("first", [](const Explanation& e) { return to_seconds(e.first); })
      .def_property_readonly("last", [](const Explanation& e) { return to_seconds(e.last); })
      .def_readonly("root", &Explanation::root)
      .def_readonly("hazard", &Explanation::hazard)
      .def_readonly("path", &Explanation::path, "origin machine, then each service or interface, then this machine");
  py::class_<in::ExplainAnswer>(m, "Explain", "Why an address is at its level: every active condition.")
      .def_readonly("address", &in::ExplainAnswer::address)
      .def_property_readonly("state", [](const in::ExplainAnswer& a) { return level(a.state); })
      .def_readonly("conditions", &in::ExplainAnswer::conditions)
      .def("to_dict", [](const in::ExplainAnswer& a) { return from_json(in::explain_json(a)); })
      .def("__str__", [](const in::ExplainAnswer& a) { return in::explain_text(a, in::TimeFormat()); })
      .def("__repr__", [](const in::ExplainAnswer& a) {
        return "<Explain " + a.address + " " + level(a.state) + ", " + std::to_string(a.conditions.size()) +
               " condition(s)>";
      });
}

}  // namespace

void raise(const Error& error) {
  const py::object cls = values_module().attr(error_class(error.code));
  if (error.code == ErrorCode::Parse) raise_object(cls, cls(error.message, py::list()));
  raise_object(cls, cls(error.message));
}

void raise(const spec::Diagnostics& diagnostics) {
  const py::object cls = values_module().attr("SpecError");
  std::string text = spec::to_text(diagnostics);
  while (!text.empty() && text.back() == '\n') text.pop_back();
  raise_object(cls, cls(text, py::cast(diagnostics)));
}

py::object from_json(std::string_view text) {
  return py::module_::import("json").attr("loads")(py::str(text.data(), text.size()));
}

py::object result_from_json(std::string_view text) { return values_module().attr("Result")(from_json(text)); }

py::list result_list(std::string_view lines) {
  const py::object result = values_module().attr("Result");
  py::list out;
  while (!lines.empty()) {
    const std::size_t end = lines.find('\n');
    const std::string_view line = lines.substr(0, end);
    if (!line.empty()) out.append(result(from_json(line)));
    lines = end == std::string_view::npos ? std::string_view() : lines.substr(end + 1);
  }
  return out;
}

void bind_values(py::module_& m) {
  bind_diagnostic(m);
  bind_root(m);
  bind_record(m);
  bind_state_row(m);
  bind_explain(m);
}

}  // namespace safecass::python
