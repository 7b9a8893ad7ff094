#pragma once
/// @file bindings.hpp
/// The pieces of the `_safecass` Python module (docs/python.md), one file per part: values.cpp
/// (the read model's values, errors), system.cpp (an in-process system and a replay), runs.cpp
/// (scenarios, verify, trace), recording.cpp (recordings as numpy arrays) and remote.cpp (a live
/// system over the bus). Every call goes through the libraries the `safecass` command uses.

#include <string>
#include <string_view>

#include <pybind11/pybind11.h>

#include "safecass/core/expected.hpp"
#include "safecass/spec/diagnostics.hpp"

namespace safecass::python {

namespace py = pybind11;

void bind_values(py::module_& m);
void bind_system(py::module_& m);
void bind_runs(py::module_& m);
void bind_recording(py::module_& m);
void bind_remote(py::module_& m);

/// Raises the Python exception of `error` (safecass._values: NotFound, InvalidArgument, Denied,
/// BusError, SpecError for Parse, Error otherwise).
[[noreturn]] void raise(const Error& error);
/// Raises SpecError with every diagnostic (as safecass.Diagnostic objects) and their lines.
[[noreturn]] void raise(const spec::Diagnostics& diagnostics);

/// The value of `e`, or its error raised.
template <class T>
T value_or_raise(Expected<T> e) {
  if (!e) raise(e.error());
  return std::move(*e);
}
inline void value_or_raise(Expected<void> e) {
  if (!e) raise(e.error());
}

/// A JSON text as Python objects (json.loads): how every answer that a tool also prints with
/// --json reaches Python, with the same keys.
py::object from_json(std::string_view text);
/// JSON lines, one object per line (the read model's *_json lists), as a list of
/// safecass._values.Result objects.
py::list result_list(std::string_view lines);
/// A tool's JSON answer as a safecass._values.Result object.
py::object result_from_json(std::string_view text);

}  // namespace safecass::python
