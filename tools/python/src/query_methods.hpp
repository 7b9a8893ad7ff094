#pragma once
/// @file query_methods.hpp
/// The reads and writes every Python system has, in-process (System) or live over the bus
/// (RemoteSystem): the console's commands through the one read model (introspect::SystemQuery) and
/// the one action path (SystemQuery::apply). `Owner` runs each through
/// `owner.ask([](introspect::SystemQuery&) { ... })`, which locks or releases the GIL as it must,
/// and `owner.apply(action)`.

#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/query.hpp"

namespace safecass::python {

/// The values of push(signal, *values): numbers, or one sequence of them.
inline std::vector<double> sample_values(const py::args& values) {
  if (values.size() == 1 && !py::isinstance<py::float_>(values[0]) && !py::isinstance<py::int_>(values[0]))
    return values[0].cast<std::vector<double>>();
  return values.cast<std::vector<double>>();
}

/// The samples of an injection: a sequence of numbers or of sequences of numbers.
inline std::vector<std::vector<double>> sample_rows(const py::object& samples) {
  std::vector<std::vector<double>> rows;
  for (const py::handle row : samples) {
    if (py::isinstance<py::float_>(row) || py::isinstance<py::int_>(row)) {
      rows.push_back({row.cast<double>()});
    } else {
      rows.push_back(row.cast<std::vector<double>>());
    }
  }
  return rows;
}

template <class Owner>
void bind_actions(py::class_<Owner>& c) {
  namespace in = safecass::introspect;
  c.def(
       "push",
       [](Owner& s, const std::string& signal, const py::args& values) {
         s.apply(in::PushSample{signal, sample_values(values)});
       },
       py::arg("signal"),
       "Writes one sample of a signal (Component.signal) now: push('JR3.force', 12.5), or a sequence for a vector.")
      .def(
          "generate",
          [](Owner& s, const std::string& event, const std::string& target) {
            s.apply(in::GenerateEvent{event, target});
          },
          py::arg("event"), py::arg("target"),
          "Processes an event on a machine (\"JR3.s_A\"), as the console's `generate`.")
      .def(
          "broadcast", [](Owner& s, const std::string& event) { s.apply(in::BroadcastEvent{event}); }, py::arg("event"),
          "Processes a broadcast event (severity 251-255) on every component's s_A.")
      .def(
          "reset",
          [](Owner& s, const std::string& target, const std::string& why) {
            s.apply(in::ResetState{target, "python", why});
          },
          py::arg("target"), py::arg("why") = "",
          "Clears the conditions originating in a machine, a component or SYSTEM, recording why.")
      .def(
          "inject",
          [](Owner& s, const std::string& filter, const py::object& samples) {
            s.apply(in::InjectShallow{filter, sample_rows(samples)});
          },
          py::arg("filter"), py::arg("samples"),
          "Shallow injection: samples queued into one filter's private input (the console's `filter inject`).")
      .def(
          "inject_deep",
          [](Owner& s, const std::string& signal, const py::object& samples) {
            s.apply(in::InjectDeep{signal, sample_rows(samples)});
          },
          py::arg("signal"), py::arg("samples"),
          "Deep injection: samples written into a signal's history now, seen by every consumer (`filter dinject`).");
}

template <class Owner>
void bind_reads(py::class_<Owner>& c) {
  namespace in = safecass::introspect;
  c.def(
       "states",
       [](Owner& s, const std::string& component) {
         return s.ask([&](in::SystemQuery& q) { return q.state_list(component); });
       },
       py::arg("component") = "",
       "Every row of `state list`: SYSTEM, then each component's extended state, machines and services.")
      .def(
          "levels",
          [](Owner& s) {
            py::dict levels;
            for (const in::StateRow& row : s.ask([](in::SystemQuery& q) { return q.state_list(); })) {
              levels[py::str(row.address)] = std::string(to_string(row.state));
            }
            return levels;
          },
          "Every address of `state list` -> its level: 'Normal', 'Warning' or 'Error'.")
      .def(
          "state",
          [](Owner& s, const std::string& address) {
            // explain resolves every address (SYSTEM, a coordinator, a component, a machine, a service).
            const in::ExplainAnswer a = s.ask([&](in::SystemQuery& q) { return q.explain(address); });
            return std::string(to_string(a.state));
          },
          py::arg("address"), "The level of one address: SYSTEM, a component, a machine or a service.")
      .def(
          "explain",
          [](Owner& s, const std::string& address) {
            return s.ask([&](in::SystemQuery& q) { return q.explain(address); });
          },
          py::arg("address"), "Why an address is at its level: every active condition, its root cause and path.")
      .def(
          "history",
          [](Owner& s, const std::string& scope, std::size_t last, bool events_only) {
            const auto filter = events_only ? in::HistoryFilter::Events : in::HistoryFilter::All;
            return s.ask([&](in::SystemQuery& q) { return q.history(scope, last, filter); });
          },
          py::arg("scope") = "SYSTEM", py::arg("last") = 0, py::arg("events_only") = false,
          "The records kept about a scope (SYSTEM, a component or a machine), oldest first; last=0: all kept.")
      .def(
          "filters",
          [](Owner& s) {
            return result_list(in::filter_list_json(s.ask([](in::SystemQuery& q) { return q.filter_list(); })));
          },
          "`filter list`: each filter, its type, target, inputs, and whether it is enabled.")
      .def(
          "events",
          [](Owner& s) {
            return result_list(in::event_list_json(s.ask([](in::SystemQuery& q) { return q.event_list(); })));
          },
          "`event list`: each event, its severity, transitions and hazard.")
      .def(
          "connections",
          [](Owner& s) {
            return result_list(in::connection_list_json(s.ask([](in::SystemQuery& q) { return q.connection_list(); })));
          },
          "`connection list`: each connection and its states.")
      .def(
          "read",
          [](Owner& s, const std::string& name, const std::vector<std::string>& args) {
            return from_json(s.ask([&](in::SystemQuery& q) { return q.read(name, args); }));
          },
          py::arg("name"), py::arg("args") = std::vector<std::string>{},
          "A named read of the console (`state summary`, ...) as its --json answer.");
}

}  // namespace safecass::python
