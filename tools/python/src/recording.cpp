// Recordings as numpy arrays (docs/python.md, "Recordings as arrays"): an inputs recording
// (record/input_log.hpp, read by the one streaming reader) and a history file (JSON lines, read by
// the one history reader, timeline's parse_history). The arrays are built column by column; the
// Python classes around them (safecass.Recording, safecass.History) are in safecass/__init__.py.
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "safecass/introspect/action.hpp"
#include "safecass/record/input_log.hpp"
#include "safecass/timeline/timeline.hpp"

namespace safecass::python {

namespace in = safecass::introspect;

namespace {

py::object numpy() { return py::module_::import("numpy"); }

/// A column of doubles (or integers) as a numpy array, copied once.
template <class T>
py::array_t<T> column(const std::vector<T>& values) {
  py::array_t<T> out(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), out.mutable_data());
  return out;
}

/// A column of text as a fixed-width unicode numpy array ("U1" at least).
py::object text_column(const std::vector<std::string>& values) {
  return numpy().attr("array")(py::cast(values), py::arg("dtype") = "U");
}

/// The columns as one numpy structured array, in the order given.
py::object structured(const std::vector<std::pair<const char*, py::object>>& columns, std::size_t n) {
  py::list dtype;
  for (const auto& [name, values] : columns) {
    dtype.append(py::make_tuple(name, values.attr("dtype")));
  }
  py::object out = numpy().attr("empty")(n, py::arg("dtype") = dtype);
  for (const auto& [name, values] : columns) out[py::str(name)] = values;
  return out;
}

py::dict action_dict(const in::Action& action, double time) {
  py::dict d;
  d["time"] = time;
  d["action"] = std::string(in::action_name(action));
  std::visit(
      [&d](const auto& a) {
        using A = std::decay_t<decltype(a)>;
        if constexpr (std::is_same_v<A, in::PushSample>) {
          d["signal"] = a.signal;
          d["values"] = a.values;
        } else if constexpr (std::is_same_v<A, in::GenerateEvent>) {
          d["event"] = a.event;
          d["target"] = a.target;
        } else if constexpr (std::is_same_v<A, in::BroadcastEvent>) {
          d["event"] = a.event;
        } else if constexpr (std::is_same_v<A, in::ResetState>) {
          d["target"] = a.target;
          d["who"] = a.who;
          d["why"] = a.why;
        } else if constexpr (std::is_same_v<A, in::InjectShallow>) {
          d["filter"] = a.filter;
          d["samples"] = a.samples;
        } else {
          d["signal"] = a.signal;
          d["samples"] = a.samples;
        }
      },
      action);
  return d;
}

/// Everything an inputs recording holds: {"header", "inputs" (time, signal, index, value), "actions",
/// "losses", "end", "truncated"}. A malformed recording raises SpecError naming the record and byte.
py::dict read_inputs(const std::string& path) {
  auto reader = value_or_raise(InputLogReader::open(path));
  std::vector<double> times, values;
  std::vector<std::uint16_t> ids, index;
  py::list actions, losses;
  py::object end = py::none();
  for (InputLogReader::Item item = reader->next(); item != InputLogReader::Item::Eof; item = reader->next()) {
    if (item == InputLogReader::Item::Error) raise(Error{ErrorCode::Parse, reader->error()});
    if (item == InputLogReader::Item::Sample) {
      const double t = to_seconds(reader->time());
      for (std::size_t k = 0; k < reader->width(); ++k) {
        times.push_back(t);
        ids.push_back(reader->signal());
        index.push_back(static_cast<std::uint16_t>(k));
        values.push_back(reader->values()[k]);
      }
    } else if (item == InputLogReader::Item::Action) {
      actions.append(action_dict(reader->action(), to_seconds(reader->mark_time())));
    } else if (item == InputLogReader::Item::Loss) {
      const std::uint16_t id = reader->loss_signal();
      losses.append(py::dict(py::arg("time") = to_seconds(reader->mark_time()),
                             py::arg("signal") = id == 0xffff ? std::string() : reader->signal_name(id),
                             py::arg("lost") = reader->lost()));
    } else if (item == InputLogReader::Item::End) {
      end = py::float_(to_seconds(reader->mark_time()));
    }
  }
  std::vector<std::string> names(ids.size());
  for (std::size_t i = 0; i < ids.size(); ++i) names[i] = reader->signal_name(ids[i]);
  const InputLogHeader& h = reader->header();
  py::dict out;
  out["header"] = py::dict(py::arg("period") = to_seconds(h.period), py::arg("start") = to_seconds(h.start),
                           py::arg("clock") = h.clock, py::arg("system") = h.system);
  out["inputs"] = structured(
      {{"time", column(times)}, {"signal", text_column(names)}, {"index", column(index)}, {"value", column(values)}},
      times.size());
  out["actions"] = actions;
  out["losses"] = losses;
  out["end"] = end;
  out["truncated"] = reader->truncated();
  // What a killed recorder left after its last whole record: the bytes the reader did not take.
  std::error_code size_error;
  const auto size = std::filesystem::file_size(path, size_error);
  out["cut_bytes"] = reader->truncated() && !size_error && size > reader->offset() ? size - reader->offset() : 0;
  return out;
}

std::string level_of(const in::HistoryEntry& e) {
  return std::string(to_string(e.kind == RecordKind::Event ? e.level : e.to));
}

/// A history file: {"records" (time, seq, kind, address, event, level, root), "dropped", "torn"}.
/// Every malformed line raises SpecError with its line.
py::dict read_history(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  if (!file) raise(Error{ErrorCode::Io, path + ": cannot be read"});
  std::stringstream text;
  text << file.rdbuf();
  const std::string all = text.str();
  const timeline::HistoryParse parsed = timeline::parse_history(all);
  if (!parsed.errors.empty()) {
    spec::Diagnostics problems;
    for (const timeline::HistoryError& e : parsed.errors) {
      problems.push_back(spec::Diagnostic{spec::Diagnostic::Severity::Error, {path, e.line, 1}, e.message, ""});
    }
    raise(problems);
  }
  std::vector<double> times;
  std::vector<std::uint64_t> seqs, dropped;
  std::vector<std::string> kinds, addresses, events, levels, roots;
  for (const timeline::HistoryRecord& r : parsed.records) {
    if (r.overflow) {
      dropped.push_back(r.dropped);
      continue;
    }
    const in::HistoryEntry& e = r.entry;
    times.push_back(to_seconds(e.time));
    seqs.push_back(e.seq);
    kinds.emplace_back(to_string(e.kind));
    addresses.emplace_back(e.where());
    events.push_back(e.event);
    levels.push_back(level_of(e));
    roots.push_back(e.root ? e.root->name() : std::string());
  }
  py::dict out;
  out["records"] = structured({{"time", column(times)},
                               {"seq", column(seqs)},
                               {"kind", text_column(kinds)},
                               {"address", text_column(addresses)},
                               {"event", text_column(events)},
                               {"level", text_column(levels)},
                               {"root", text_column(roots)}},
                              times.size());
  std::uint64_t lost = 0;
  for (const std::uint64_t d : dropped) lost += d;
  out["dropped"] = lost;
  out["torn"] = parsed.torn ? py::object(py::int_(parsed.torn->line)) : py::object(py::none());
  const std::size_t last_newline = all.rfind('\n');
  out["cut_bytes"] = parsed.torn ? all.size() - (last_newline == std::string::npos ? 0 : last_newline + 1) : 0;
  return out;
}

}  // namespace

void bind_recording(py::module_& m) {
  m.def("_read_inputs", &read_inputs, py::arg("path"));
  m.def("_read_history", &read_history, py::arg("path"));
}

}  // namespace safecass::python
