// Whole runs from Python: a scenario and its verdicts, `verify` and `trace` (docs/python.md,
// "Scenarios, verify and trace"). Each runs with the GIL released, through the library the
// `safecass` command calls.
#include <memory>
#include <string>
#include <vector>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "safecass/filters/registry.hpp"
#include "safecass/introspect/format.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/runner/scenario_runner.hpp"
#include "safecass/spec/instance.hpp"
#include "safecass/trace/trace.hpp"
#include "safecass/verify/verify.hpp"

namespace safecass::python {

namespace in = safecass::introspect;

namespace {

/// One expectation that failed, and why the address was where it was at that tick.
struct Failure {
  runner::ExpectationFailure failure;
  std::string explain;  ///< `explain ADDRESS` at the failing tick, as the console prints it
};

struct ScenarioVerdict {
  std::string scenario;
  std::string system;
  int checks = 0;
  std::vector<Failure> failures;
  std::vector<std::string> problems;  ///< every failure line, and a recorder's that was incomplete
  runner::Coverage coverage;
  bool history_complete = true;
  bool passed() const { return problems.empty(); }
};

ScenarioVerdict run_scenario(const std::string& path, const std::string& system, const std::string& record) {
  Expected<ScenarioVerdict> ran = fail(ErrorCode::InvalidState, "not run");
  spec::Diagnostics problems;
  {
    py::gil_scoped_release unlocked;
    auto opened = runner::ScenarioRunner::open(runner::ScenarioSource{path, system}, builtin_filters());
    if (!opened) {
      problems = std::move(opened.error());
    } else {
      runner::ScenarioRunner& r = **opened;
      in::LocalQuery query(r.coordinator(), r.monitor(), builtin_filters());
      ScenarioVerdict verdict;
      verdict.scenario = path;
      verdict.system = r.scenario().system;
      r.set_on_failure([&](const runner::ExpectationFailure& f) {
        auto why = query.explain(f.address);
        verdict.failures.push_back(Failure{f, why ? in::explain_text(*why, in::TimeFormat()) : why.error().message});
      });
      runner::RunOptions options;
      options.quiet = true;
      options.record_path = record;
      const runner::RunResult result = r.run(options);
      verdict.checks = result.checks;
      verdict.problems = result.failures;
      verdict.coverage = result.coverage;
      verdict.history_complete = result.history_complete();
      ran = std::move(verdict);
    }
  }
  if (!problems.empty()) raise(problems);
  return value_or_raise(std::move(ran));
}

void bind_scenario(py::module_& m) {
  py::class_<Failure>(m, "Failure", "An expectation that did not hold: where it is written, when, and why.")
      .def_property_readonly("file", [](const Failure& f) { return f.failure.where.file; })
      .def_property_readonly("line", [](const Failure& f) { return f.failure.where.line; })
      .def_property_readonly("column", [](const Failure& f) { return f.failure.where.column; })
      .def_property_readonly("pointer", [](const Failure& f) { return f.failure.pointer; })
      .def_property_readonly("time", [](const Failure& f) { return to_seconds(f.failure.at); })
      .def_property_readonly("address", [](const Failure& f) { return f.failure.address; })
      .def_property_readonly("problem", [](const Failure& f) { return f.failure.problem; })
      .def_readonly("explain", &Failure::explain, "`explain ADDRESS` at the failing tick")
      .def("__str__", [](const Failure& f) { return f.failure.text(); })
      .def("__repr__", [](const Failure& f) { return "<Failure " + f.failure.text() + ">"; });
  py::class_<runner::Coverage>(m, "Coverage", "What a run exercised.")
      .def_readonly("events_fired", &runner::Coverage::events_fired)
      .def_readonly("transitions_taken", &runner::Coverage::taken, "(event, transition) pairs that happened")
      .def_readonly("transitions_defined", &runner::Coverage::defined);
  py::class_<ScenarioVerdict>(m, "ScenarioResult", "The verdicts of one scenario run.")
      .def_readonly("scenario", &ScenarioVerdict::scenario)
      .def_readonly("system", &ScenarioVerdict::system)
      .def_property_readonly("passed", &ScenarioVerdict::passed)
      .def_readonly("checks", &ScenarioVerdict::checks, "expectations checked")
      .def_readonly("failures", &ScenarioVerdict::failures, "each failed expectation, in run order")
      .def_readonly("problems", &ScenarioVerdict::problems,
                    "every line `safecass run` reports as a failure (expectations, an incomplete recording)")
      .def_readonly("coverage", &ScenarioVerdict::coverage)
      .def_readonly("history_complete", &ScenarioVerdict::history_complete)
      .def("__bool__", &ScenarioVerdict::passed)
      .def("__repr__", [](const ScenarioVerdict& v) {
        return "<ScenarioResult " + v.scenario + ": " + (v.passed() ? "passed" : "failed") + ", " +
               std::to_string(v.checks) + " checks>";
      });
  m.def("run_scenario", &run_scenario, py::arg("path"), py::arg("system") = "", py::arg("record") = "",
        "Runs a scenario file (SpecError with every problem when it cannot run) and returns its verdicts; "
        "system replaces the scenario's, record writes the history. The GIL is released while it runs.");
}

spec::SystemSpec load_or_raise(const std::string& path) {
  auto loaded = spec::load_valid_system(path, builtin_filters());
  if (!loaded) raise(loaded.error());
  return std::move(*loaded);
}

void bind_verify(py::module_& m) {
  using P = verify::PropertyResult;
  py::class_<P>(m, "Property", "One property `safecass verify` checked, and its verdict.")
      .def_property_readonly("kind", [](const P& p) { return std::string(verify::to_string(p.kind)); })
      .def_property_readonly("verdict", [](const P& p) { return std::string(verify::to_string(p.verdict)); })
      .def_readonly("name", &P::name)
      .def_readonly("text", &P::text, "what is checked")
      .def_readonly("message", &P::message, "a violation's or a finding's what and why")
      .def_property_readonly("file", [](const P& p) { return p.where.file; })
      .def_property_readonly("line", [](const P& p) { return p.where.line; })
      .def_property_readonly("column", [](const P& p) { return p.where.column; })
      .def_readonly("structural", &P::structural)
      .def_readonly("states", &P::states)
      .def_readonly("memory_mb", &P::memory_mb)
      .def_readonly("seconds", &P::seconds)
      .def_readonly("scenario", &P::scenario, "the counterexample scenario written, with out_dir")
      .def_readonly("advice", &P::advice)
      .def("__repr__", [](const P& p) {
        return "<Property " + std::string(verify::to_string(p.kind)) + " " + p.name + ": " +
               std::string(verify::to_string(p.verdict)) + ">";
      });
  py::class_<verify::Report>(m, "VerifyReport", "What `safecass verify` proved of a system.")
      .def_readonly("system", &verify::Report::system)
      .def_readonly("properties", &verify::Report::properties)
      .def_readonly("seconds", &verify::Report::seconds)
      .def_property_readonly("exit_code", &verify::Report::exit_code,
                             "0 all hold, 1 one is violated, 3 one is undecided (the command's exit status)")
      .def("__bool__", [](const verify::Report& r) { return r.exit_code() == 0; });
  m.def(
      "verify",
      [](const std::string& path, const std::string& property, const std::string& out_dir, std::size_t memory_mb) {
        const spec::SystemSpec system = load_or_raise(path);
        verify::Options options;
        options.property = property;
        options.out_dir = out_dir;
        options.memory_mb = memory_mb;
        Expected<verify::Report> report = fail(ErrorCode::InvalidState, "not run");
        {
          py::gil_scoped_release unlocked;
          report = verify::verify(system, builtin_filters(), options);
        }
        return value_or_raise(std::move(report));
      },
      py::arg("system"), py::arg("property") = "", py::arg("out_dir") = "", py::arg("memory_mb") = 4096,
      "Model-checks a system's hazard reactions and invariants with SPIN (docs/verify.md). The GIL is released.");
}

void bind_trace(py::module_& m) {
  m.def(
      "trace",
      [](const std::string& system, const std::vector<std::string>& scenarios, const std::string& verify_json) {
        trace::TraceOptions options;
        options.system = system;
        options.scenarios = scenarios;
        options.verify_json = verify_json;
        tl::expected<trace::Trace, spec::Diagnostics> traced = tl::unexpected(spec::Diagnostics{});
        {
          py::gil_scoped_release unlocked;
          traced = trace::build_trace(options, builtin_filters());
        }
        if (!traced) raise(traced.error());
        return result_from_json(trace::trace_json(*traced));
      },
      py::arg("system"), py::arg("scenarios") = std::vector<std::string>{}, py::arg("verify") = "",
      "The hazard trace of a system (docs/trace.md) as a Result with the fields of `safecass trace --json`; "
      "verify: a `safecass verify --json` output to read. The GIL is released while the scenarios run.");
}

}  // namespace

void bind_runs(py::module_& m) {
  bind_scenario(m);
  bind_verify(m);
  bind_trace(m);
}

}  // namespace safecass::python
