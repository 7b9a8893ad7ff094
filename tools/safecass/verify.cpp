// `safecass verify SYSTEM [--property NAME] [--out DIR] [--json]` (docs/verify.md).

#include "verify_command.hpp"

#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include "safecass/filters/registry.hpp"
#include "safecass/json/write.hpp"
#include "safecass/spec/load.hpp"
#include "safecass/verify/verify.hpp"

namespace safecass::tools {

/// Three decimals: the figures' precision in --json (megabytes, seconds).
std::string fixed3(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.3f", v);
  return buf;
}

namespace {

std::string where_text(const spec::Position& p) {
  if (p.file.empty()) return {};
  return p.file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

bool checked(const verify::PropertyResult& p) {
  return p.kind == verify::PropertyResult::Kind::Reaction || p.kind == verify::PropertyResult::Kind::Invariant;
}

std::string figures(const verify::PropertyResult& p) {
  char buf[160];
  std::snprintf(buf, sizeof buf, "%llu states, %.1f MB, %.2f s, %zu of %zu onsets",
                static_cast<unsigned long long>(p.states), p.memory_mb, p.seconds, p.onsets, p.onsets_total);
  return buf;
}

}  // namespace

void add_verify_command(CLI::App& app, int& code) {
  struct Args {
    std::string system;
    verify::Options options;
    bool json = false;
    bool bus = false;
    bool mutants = false;
    verify::BusOptions bus_options;
    long period_ms = 100, lost_after_ms = 0, supervisor_lost_after_ms = 600;
  };
  auto args = std::make_shared<Args>();
  auto* cmd = app.add_subcommand("verify",
                                 "Model-check hazard reactions and invariants with SPIN; counterexamples as scenarios");
  cmd->add_option("SYSTEM", args->system, "system file")->required();
  cmd->add_option("--property", args->options.property, "check only this property (a hazard id or an invariant name)");
  cmd->add_option("--out", args->options.out_dir,
                  "write each violated property's counterexample as DIR/<property>.scenario.json");
  cmd->add_flag("--json", args->json, "one JSON object per property, then a summary object");
  cmd->add_option("--memory", args->options.memory_mb, "SPIN's memory bound per property, in MB (default 4096)");
  cmd->add_flag(
      "--no-slice", [args](std::int64_t) { args->options.slice = false; },
      "keep every onset in every property's model (no cone of influence)");
  cmd->add_flag(
      "--no-merge", [args](std::int64_t) { args->options.merge = false; },
      "track every onset on its own (no counting of interchangeable onsets)");
  cmd->add_flag("--bus", args->bus,
                "model-check the bus protocol for this deployment instead (P1-P5, docs/verify.md \"The bus\")");
  cmd->add_option("--period", args->period_ms, "--bus: the heartbeat period in ms (default 100)");
  cmd->add_option("--lost-after", args->lost_after_ms, "--bus: the coordinators' loss bound in ms (default 3 periods)");
  cmd->add_option("--supervisor-lost-after", args->supervisor_lost_after_ms,
                  "--bus: the supervisor's loss bound in ms (default 600)");
  cmd->add_flag(
      "--no-supervisor", [args](std::int64_t) { args->bus_options.supervisor = false; },
      "--bus: the deployment runs no supervisor");
  cmd->add_option("--fault-class", args->bus_options.fault_class, "--bus: search only this fault class");
  cmd->add_option("--mutant", args->bus_options.mutant, "--bus: remove this rule from the model (see --mutants)");
  cmd->add_flag("--mutants", args->mutants, "--bus: check that each mutant of the protocol is caught by a property");
  cmd->callback([args, &code] {
    if (!args->bus) {
      code = run_verify(args->system, args->options, args->json);
      return;
    }
    args->bus_options.period = std::chrono::milliseconds(args->period_ms);
    args->bus_options.lost_after = std::chrono::milliseconds(args->lost_after_ms);
    args->bus_options.supervisor_lost_after = std::chrono::milliseconds(args->supervisor_lost_after_ms);
    if (args->options.memory_mb != verify::Options{}.memory_mb) args->bus_options.memory_mb = args->options.memory_mb;
    code = run_verify_bus(args->system, args->bus_options, args->json, args->mutants);
  });
}

const spec::SystemSpec* load_to_verify(const std::string& path, std::string_view command, spec::LoadResult& loaded) {
  loaded = spec::load_system(path, builtin_filters());
  for (const spec::Diagnostic& d : loaded.diagnostics) {
    if (d.severity == spec::Diagnostic::Severity::Error) std::fprintf(stderr, "%s\n", spec::format(d).c_str());
  }
  if (!loaded.ok()) {
    std::fprintf(stderr, "%.*s: %s has %zu error(s); `safecass validate` lists every problem\n",
                 static_cast<int>(command.size()), command.data(), path.c_str(), loaded.errors());
    return nullptr;
  }
  return &*loaded.system;
}

int run_verify(const std::string& system_path, const verify::Options& options, bool json) {
  const FilterRegistry& registry = builtin_filters();
  spec::LoadResult loaded;
  const spec::SystemSpec* system = load_to_verify(system_path, "verify", loaded);
  if (system == nullptr) return 2;
  auto report = verify::verify(*system, registry, options);
  if (!report) {
    std::fprintf(stderr, "verify: %s\n", report.error().message.c_str());
    return 2;
  }
  std::size_t holds = 0, violated = 0, undecided = 0, findings = 0;
  for (const verify::PropertyResult& p : report->properties) {
    if (!checked(p)) {
      ++findings;
    } else if (p.verdict == verify::PropertyResult::Verdict::Holds) {
      ++holds;
    } else if (p.verdict == verify::PropertyResult::Verdict::Violated) {
      ++violated;
    } else {
      ++undecided;
    }
    if (json) {
      json::JsonObject line;
      line.str("kind", verify::to_string(p.kind))
          .str("name", p.name)
          .str("result", checked(p) ? verify::to_string(p.verdict) : "warning")
          .str("checks", p.text);
      if (!p.where.file.empty()) {
        line.str("file", p.where.file).integer("line", p.where.line).integer("column", p.where.column);
      }
      if (!p.structural) {
        line.integer("states", static_cast<long long>(p.states))
            .raw("memory_mb", fixed3(p.memory_mb))
            .raw("seconds", fixed3(p.seconds))
            .integer("onsets", static_cast<long long>(p.onsets))
            .integer("onsets_total", static_cast<long long>(p.onsets_total));
      }
      if (!p.message.empty()) line.str("message", p.message);
      if (!p.scenario.empty()) line.str("scenario", p.scenario);
      if (!p.advice.empty()) line.str("advice", p.advice);
      std::printf("%s\n", line.text().c_str());
      continue;
    }
    if (!checked(p)) {
      const std::string at = where_text(p.where);
      std::printf("%s%swarning: %s [%s]\n", at.c_str(), at.empty() ? "" : ": ", p.message.c_str(),
                  std::string(verify::to_string(p.kind)).c_str());
      continue;
    }
    const std::string label = std::string(verify::to_string(p.kind)) + " " + p.name;
    if (p.structural) {
      std::printf("%-32s %-9s (%s)\n", label.c_str(), std::string(verify::to_string(p.verdict)).c_str(),
                  p.message.c_str());
      continue;
    }
    std::printf("%-32s %-9s %s\n", label.c_str(), std::string(verify::to_string(p.verdict)).c_str(),
                figures(p).c_str());
    if (p.verdict != verify::PropertyResult::Verdict::Holds) {
      const std::string at = where_text(p.where);
      std::printf("  %s%s%s\n", at.c_str(), at.empty() ? "" : ": ", p.text.c_str());
      std::printf("  %s\n", p.message.c_str());
      if (!p.scenario.empty())
        std::printf("  counterexample: %s (safecass run --scenario %s)\n", p.scenario.c_str(), p.scenario.c_str());
      if (!p.advice.empty()) std::printf("  %s\n", p.advice.c_str());
    }
  }
  const int exit = report->exit_code();
  if (json) {
    const std::string line = json::JsonObject()
                                 .str("kind", "summary")
                                 .str("system", report->system)
                                 .integer("holds", static_cast<long long>(holds))
                                 .integer("violated", static_cast<long long>(violated))
                                 .integer("undecided", static_cast<long long>(undecided))
                                 .integer("warnings", static_cast<long long>(findings))
                                 .raw("seconds", fixed3(report->seconds))
                                 .integer("exit", exit)
                                 .text();
    std::printf("%s\n", line.c_str());
  } else {
    std::printf(
        "%s: %zu propert%s hold%s, %zu violated, %zu undecided, %zu warning%s about the specification (%.2f s)\n",
        report->system.c_str(), holds, holds == 1 ? "y" : "ies", holds == 1 ? "s" : "", violated, undecided, findings,
        findings == 1 ? "" : "s", report->seconds);
  }
  return exit;
}

}  // namespace safecass::tools
